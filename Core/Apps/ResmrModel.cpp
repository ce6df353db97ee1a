// Grid files for the resmr subcommands: an EGRID or a GRDECL/DATA deck with its active flags.
#include "ResmrCommands.h"

#include "EclipseGrid.h"
#include "GrdeclParser.h"

void ReadGridFile(const std::string& path, resmr::GrdeclDeck& deck, std::vector<bool>& active)
{
  if (resmr::LooksLikeEclipseGridFile(path))
  {
    resmr::EclipseGrid grid = resmr::ReadEclipseGrid(path);
    active.resize(static_cast<std::size_t>(grid.deck.CellCount()));
    for (int64_t c = 0; c < grid.deck.CellCount(); ++c)
    {
      active[c] = grid.IsActive(c);
    }
    deck = std::move(grid.deck);
    return;
  }
  deck = resmr::ParseGrdeclFile(path);
  const resmr::CellArray* actnum = deck.FindArray("ACTNUM");
  active.resize(static_cast<std::size_t>(deck.CellCount()));
  for (int64_t c = 0; c < deck.CellCount(); ++c)
  {
    active[c] = !actnum || actnum->values[c] != 0;
  }
}
