// Corner-point models read layer by layer, top to bottom: what the hierarchy builder's first
// streaming pass (paper Sec. 4.2 and 7: partitioning) consumes, so no model is ever held whole.
//
// Contract:
// - Coord(): COORD as the grid defines it, 6 values a pillar (top x y depth, bottom x y depth),
//   MAPAXES not applied (grid coordinates); Placement() gives MAPAXES, MAPUNITS and GRIDUNIT.
// - Next() gives layers k = 0, 1, ... nk - 1 in order: ZCORN of the layer (8 nx ny values: the
//   2nx x 2ny top-face block then the bottom-face block, ECLIPSE order) and one active flag a
//   cell (i fastest); false after the last layer.
#pragma once

#include "CornerPointModel.h"

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace resmr
{

class CornerPointGeometry;
class SyntheticReservoir;
class SyntheticLayerStream;
struct SyntheticParameters;

class LayerSource
{
public:
  virtual ~LayerSource() = default;
  virtual std::array<int64_t, 3> Dims() const = 0;
  virtual const std::vector<double>& Coord() const = 0;
  virtual bool Next(std::vector<float>& zcorn, std::vector<uint8_t>& active) = 0;
  /// What the model is, for messages ("synth:100x100x10:1", a file name).
  virtual std::string Name() const = 0;
  /// The input's MAPAXES, MAPUNITS and GRIDUNIT (none for generated models).
  virtual MapPlacement Placement() const { return {}; }
  /// What the input left out (deck edits the viewer does not build, missing INCLUDEs ...),
  /// one message a line naming the file and place.
  virtual std::vector<std::string> Warnings() const { return {}; }
  /// The reader needs no more layers: the source may free what streaming them took. Dims(),
  /// Name(), Placement() and Warnings() still answer; Coord() and Next() no longer do.
  virtual void Finished() {}
};

/// Layers generated on the fly (SyntheticReservoir), never all in memory.
class SyntheticLayerSource : public LayerSource
{
public:
  SyntheticLayerSource(const SyntheticParameters& parameters, std::string name);
  ~SyntheticLayerSource() override;
  std::array<int64_t, 3> Dims() const override;
  const std::vector<double>& Coord() const override { return this->CoordValues; }
  bool Next(std::vector<float>& zcorn, std::vector<uint8_t>& active) override;
  std::string Name() const override { return this->Label; }
  /// Frees the generator (its per-pillar and per-column fields) and COORD.
  void Finished() override;

private:
  std::unique_ptr<SyntheticReservoir> Model;
  std::unique_ptr<SyntheticLayerStream> Stream;
  std::vector<double> CoordValues;
  std::array<int64_t, 3> Dimensions{};
  std::string Label;
};

/// Layers of a grid already in memory (a GRDECL deck or an EGRID).
class CornerPointLayerSource : public LayerSource
{
public:
  /// `geometry` and `active` (one flag a cell, ECLIPSE order) must outlive the source;
  /// `placement`: the deck's (CornerPointModel::Placement()).
  CornerPointLayerSource(const CornerPointGeometry& geometry, const std::vector<bool>& active, std::string name,
    MapPlacement placement = {});
  std::array<int64_t, 3> Dims() const override;
  const std::vector<double>& Coord() const override;
  bool Next(std::vector<float>& zcorn, std::vector<uint8_t>& active) override;
  std::string Name() const override { return this->Label; }
  MapPlacement Placement() const override { return this->Map; }

private:
  const CornerPointGeometry& Geometry;
  const std::vector<bool>& Active;
  std::string Label;
  MapPlacement Map;
  int64_t K = 0;
};

/// An EGRID or a GRDECL/DATA deck: its deck and one active flag a cell (ACTNUM; all active
/// if none). Throws InputError naming the file and place.
void ReadCornerPointModel(const std::string& path, CornerPointModel& deck, std::vector<bool>& active);

/// The layers of `input`, streamed whatever the model's size:
/// - "synth:NIxNJxNK[:SEED[:STEPS]]": from the generator (ParseSyntheticSpec);
/// - an EGRID/FEGRID: COORD read whole, then each layer's ZCORN and ACTNUM read from the file
///   as Next() asks for it (EclipseRecordCursor). Checked as ReadEclipseGrid checks; the
///   checks of ZCORN's values happen layer by layer;
/// - a GRDECL/DATA deck: parsed once with ParseGrdeclGrid, ZCORN and ACTNUM (DX, DY, DZ, TOPS
///   for Cartesian decks) spooled to unlinked temporary files in `spoolFolder` (created if
///   missing; the system temporary folder when empty), freed with the source.
/// Memory: COORD and O(nx ny) a layer. Layers, Coord(), Dims() and Placement() are exactly those of a
/// CornerPointLayerSource over ReadCornerPointModel and CornerPointGeometry::FromDeck(deck,
/// false). Throws InputError naming the file and place, std::invalid_argument for a
/// malformed synth: spec.
std::unique_ptr<LayerSource> OpenLayerSource(const std::string& input, const std::string& spoolFolder = "");

} // namespace resmr
