// Subcommands of the resmr tool, one file each.
#pragma once

#include "GrdeclDeck.h"

#include <stdexcept>
#include <string>
#include <vector>

/// The value after option argv[a] (advancing a); throws std::invalid_argument if missing.
inline const char* OptionValue(int& a, int argc, char** argv)
{
  if (a + 1 >= argc)
  {
    throw std::invalid_argument(std::string(argv[a]) + " needs a value");
  }
  return argv[++a];
}

/// resmr synth NX NY NZ -o FILE [options]; argv[1] is "synth".
int SynthCommand(int argc, char** argv);

/// resmr simplify MODEL [options]; argv[1] is "simplify".
int SimplifyCommand(int argc, char** argv);

/// resmr build INPUT -o OUT.resmr [options]; argv[1] is "build".
int BuildCommand(int argc, char** argv);

/// resmr info FILE.resmr: levels, regions, sizes and errors as JSON.
int MultiresolutionInfo(const char* path);

/// An EGRID or a GRDECL/DATA deck: its deck and one active flag a cell (ACTNUM, all if none).
void ReadGridFile(const std::string& path, resmr::GrdeclDeck& deck, std::vector<bool>& active);
