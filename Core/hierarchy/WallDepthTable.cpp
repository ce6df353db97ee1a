// Wall depths (ours): see WallDepthTable.h.
#include "WallDepthTable.h"

#include "ByteStream.h"
#include "Errors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace resmr
{

namespace
{
/// Nearest open cell of each cell of the face (the upper one on a tie); false if none is open.
bool NearestOpen(const std::vector<uint8_t>& open, std::vector<uint32_t>& nearest)
{
  const std::size_t n = open.size();
  constexpr uint32_t None = std::numeric_limits<uint32_t>::max();
  std::vector<uint32_t> above(n, None), below(n, None);
  for (std::size_t k = 0; k < n; ++k)
  {
    above[k] = open[k] ? static_cast<uint32_t>(k) : (k > 0 ? above[k - 1] : None);
  }
  for (std::size_t k = n; k-- > 0;)
  {
    below[k] = open[k] ? static_cast<uint32_t>(k) : (k + 1 < n ? below[k + 1] : None);
  }
  if (n == 0 || above[n - 1] == None)
  {
    return false;
  }
  nearest.resize(n);
  for (std::size_t k = 0; k < n; ++k)
  {
    const bool up = above[k] != None && (below[k] == None || k - above[k] <= below[k] - k);
    nearest[k] = up ? above[k] : below[k];
  }
  return true;
}
} // namespace

void CollectWallFaces(const RegionMesh& leaf, int64_t nx, std::vector<WallFace>& out)
{
  const std::size_t layers = static_cast<std::size_t>(leaf.layers);
  for (std::size_t c = 0; c < leaf.corners.size(); ++c)
  {
    const auto& q = leaf.corners[c];
    const auto [i, j] = leaf.ColumnCell(c);
    for (int e = 0; e < 4; ++e)
    {
      uint32_t a = q[e], b = q[(e + 1) % 4];
      const auto& ta = leaf.topology[a];
      const auto& tb = leaf.topology[b];
      const int axis = ta[0] == tb[0] ? 0 : ta[1] == tb[1] ? 1 : -1; // the face's constant axis
      if (axis < 0)
      {
        continue;
      }
      const int along = 1 - axis;
      if (ta[along] > tb[along])
      {
        std::swap(a, b);
      }
      std::vector<uint8_t> open(layers);
      std::size_t run = 0, longest = 0;
      for (std::size_t k = 0; k < layers; ++k)
      {
        open[k] = leaf.active[c * layers + k] && ((leaf.openSides[c * layers + k] >> e) & 1);
        run = open[k] ? run + 1 : 0;
        longest = std::max(longest, run);
      }
      WallFace face;
      if (longest < std::min<std::size_t>(MinWallRun, layers) || !NearestOpen(open, face.open))
      {
        continue;
      }
      const float plane = ta[axis];
      const uint32_t code = static_cast<uint32_t>(2 * axis + (plane == (axis == 0 ? i : j) ? 0 : 1));
      face.key = WallFaceKey(static_cast<uint32_t>(i), static_cast<uint32_t>(j), code, static_cast<uint32_t>(nx));
      face.depthA.resize(layers + 1);
      face.depthB.resize(layers + 1);
      for (std::size_t k = 0; k <= layers; ++k)
      {
        face.depthA[k] =
          static_cast<float>(leaf.positions[leaf.Vertex(a, static_cast<int32_t>(k)) * std::size_t(3) + 2]);
        face.depthB[k] =
          static_cast<float>(leaf.positions[leaf.Vertex(b, static_cast<int32_t>(k)) * std::size_t(3) + 2]);
      }
      out.push_back(std::move(face));
    }
  }
}

WallDepthTable BuildWallDepthTable(const std::vector<WallFace>& faces, int32_t layers, int64_t nx)
{
  WallDepthTable table;
  table.layers = layers;
  if (faces.empty() || layers <= 0)
  {
    return table;
  }
  table.faces = faces.size();
  std::vector<std::array<uint32_t, 3>> cells;
  cells.reserve(faces.size());
  const uint32_t columns = static_cast<uint32_t>(nx);
  for (const WallFace& f : faces)
  {
    const uint32_t column = (f.key - 1) / 4;
    cells.push_back({ column % columns, column / columns, (f.key - 1) % 4 });
  }
  table.hash = BuildPerfectSpatialHash(cells);
  const std::size_t stride = static_cast<std::size_t>(layers + 1) * 3;
  table.slots.assign(static_cast<std::size_t>(table.hash.TableSize()), { 0, 0 });
  table.texels.assign(faces.size() * stride, 0.f);
  for (std::size_t f = 0; f < faces.size(); ++f)
  {
    const std::size_t slot = static_cast<std::size_t>(table.hash.Slot(cells[f][0], cells[f][1], cells[f][2]));
    table.slots[slot] = { faces[f].key, static_cast<uint32_t>(f) };
    float* texel = &table.texels[f * stride];
    for (int32_t k = 0; k <= layers; ++k)
    {
      texel[3 * k] = faces[f].depthA[static_cast<std::size_t>(k)];
      texel[3 * k + 1] = faces[f].depthB[static_cast<std::size_t>(k)];
      texel[3 * k + 2] = static_cast<float>(faces[f].open[static_cast<std::size_t>(std::min(k, layers - 1))]);
    }
  }
  return table;
}

std::vector<uint8_t> EncodeWallDepthTable(const WallDepthTable& table)
{
  ByteWriter out;
  out.Put(table.layers);
  out.Put(table.faces);
  for (uint32_t side : table.hash.tableSides)
  {
    out.Put(side);
  }
  for (uint32_t side : table.hash.offsetSides)
  {
    out.Put(side);
  }
  for (const auto& o : table.hash.offsets)
  {
    out.PutBytes(o.data(), 6);
  }
  out.PutBytes(table.slots.data(), table.slots.size() * 8);
  out.PutBytes(table.texels.data(), table.texels.size() * 4);
  return std::move(out.Bytes);
}

WallDepthTable DecodeWallDepthTable(
  const std::vector<uint8_t>& bytes, const std::array<int64_t, 3>& dims, const std::string& place)
{
  ByteReader in(bytes.data(), bytes.size(), place);
  WallDepthTable table;
  table.layers = in.Get<int32_t>();
  table.faces = in.Get<uint64_t>();
  for (auto& side : table.hash.tableSides)
  {
    side = in.Get<uint32_t>();
  }
  for (auto& side : table.hash.offsetSides)
  {
    side = in.Get<uint32_t>();
  }
  const auto bad = [&](const std::string& what) { return FileFormatError(place + ": " + what + " (corrupt)"); };
  if (table.layers != dims[2])
  {
    throw bad(
      "wall depth table of " + std::to_string(table.layers) + " layers for a model of " + std::to_string(dims[2]));
  }
  for (int a = 0; a < 3; ++a)
  {
    if (table.hash.tableSides[a] == 0 || table.hash.tableSides[a] > PerfectSpatialHash::MaxSide ||
      table.hash.offsetSides[a] == 0 || table.hash.offsetSides[a] > PerfectSpatialHash::MaxSide)
    {
      throw bad("wall depth table sides out of range");
    }
  }
  const uint64_t slots = table.hash.TableSize();
  const uint64_t stride = static_cast<uint64_t>(table.layers + 1) * 3;
  const uint64_t expected = 36 + table.hash.OffsetTableSize() * 6 + slots * 8 + table.faces * stride * 4;
  if (table.faces > slots || bytes.size() != expected)
  {
    throw bad("wall depth table of " + std::to_string(bytes.size()) + " bytes, " + std::to_string(expected) +
      " expected from its sides");
  }
  table.hash.offsets.resize(static_cast<std::size_t>(table.hash.OffsetTableSize()));
  for (auto& o : table.hash.offsets)
  {
    in.GetBytes(o.data(), 6);
    for (int a = 0; a < 3; ++a)
    {
      if (o[a] >= table.hash.tableSides[a])
      {
        throw bad("a wall hash offset lies outside the table");
      }
    }
  }
  table.slots.resize(static_cast<std::size_t>(slots));
  in.GetBytes(table.slots.data(), table.slots.size() * 8);
  table.texels.resize(static_cast<std::size_t>(table.faces * stride));
  in.GetBytes(table.texels.data(), table.texels.size() * 4);
  const uint64_t keyLimit = static_cast<uint64_t>(dims[0] * dims[1]) * 4;
  for (std::size_t s = 0; s < table.slots.size(); ++s)
  {
    if (table.slots[s][0] > keyLimit || (table.slots[s][0] != 0 && table.slots[s][1] >= table.faces))
    {
      throw bad("wall slot " + std::to_string(s) + ": key " + std::to_string(table.slots[s][0]) + " or row " +
        std::to_string(table.slots[s][1]) + " beyond the model or the table");
    }
  }
  for (uint64_t v = 0; v < table.texels.size(); ++v)
  {
    const float value = table.texels[static_cast<std::size_t>(v)];
    if (!std::isfinite(value) || (v % 3 == 2 && (value < 0 || value >= float(table.layers))))
    {
      throw bad("wall depth or cell not finite or out of range in row " + std::to_string(v / stride));
    }
  }
  return table;
}

} // namespace resmr
