// Eclipse grid deck parser (paper Sec. 3: the corner-point model and its cell properties).
#include "GrdeclParser.h"

#include "MemoryBudget.h"

#include "EclipseKeywordFile.h"
#include "Errors.h"
#include "GrdeclEdits.h"
#include "GrdeclTokenizer.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <unistd.h>
#include <unordered_map>
#include <unordered_set>

namespace resmr
{

const CellArray* CornerPointModel::FindArray(const std::string& name) const
{
  for (const CellArray& array : this->arrays)
  {
    if (array.name == name)
    {
      return &array;
    }
  }
  return nullptr;
}

CellArray* CornerPointModel::FindArray(const std::string& name)
{
  return const_cast<CellArray*>(static_cast<const CornerPointModel*>(this)->FindArray(name));
}

bool IsGeometryArrayName(const std::string& name)
{
  return name == "DX" || name == "DY" || name == "DZ" || name == "TOPS" || name == "ACTNUM";
}

int64_t CheckedCellCount(const std::array<int64_t, 3>& dims, int64_t maxCells, const std::string& file, int64_t line,
  const std::string& keyword)
{
  for (int64_t d : dims)
  {
    if (d <= 0 || d > std::numeric_limits<int32_t>::max())
    {
      throw InputError(file, line, keyword,
        "grid dimensions " + std::to_string(dims[0]) + " x " + std::to_string(dims[1]) + " x " +
          std::to_string(dims[2]) + " must each be between 1 and 2147483647");
    }
  }
  int64_t count = 0;
  if (__builtin_mul_overflow(dims[0], dims[1], &count) || __builtin_mul_overflow(count, dims[2], &count) ||
    count > maxCells)
  {
    throw InputError(file, line, keyword,
      "grid of " + std::to_string(dims[0]) + " x " + std::to_string(dims[1]) + " x " + std::to_string(dims[2]) +
        " cells is larger than this machine can hold in memory at full "
        "resolution (limit " +
        std::to_string(maxCells) + " cells); " + MultiresolutionAdvice(file));
  }
  return count;
}

namespace
{
constexpr int MaxIncludeDepth = 32;

std::string Upper(std::string_view text)
{
  std::string value(text);
  for (char& c : value)
  {
    if (c >= 'a' && c <= 'z')
    {
      c = static_cast<char>(c - 'a' + 'A');
    }
  }
  return value;
}

bool LooksLikeKeyword(std::string_view word)
{
  if (word.empty() || word.size() > 8 || word[0] < 'A' || word[0] > 'Z')
  {
    return false;
  }
  for (char c : word)
  {
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '+' || c == '-';
    if (!ok)
    {
      return false;
    }
  }
  return true;
}

bool IsRegionArrayName(const std::string& name)
{
  return name.size() > 3 && name.compare(name.size() - 3, 3, "NUM") == 0;
}

/// The value of a cell the deck gives no value: region numbers and ACTNUM are 1 there, as
/// for ECLIPSE and OPM; any other array has none (NaN).
double NotGiven(const std::string& name)
{
  return IsRegionArrayName(name) ? 1.0 : std::numeric_limits<double>::quiet_NaN();
}

bool IsIntegerArrayName(const std::string& name)
{
  return name == "ACTNUM" || name == "FACIES" || (name.size() > 3 && name.compare(name.size() - 3, 3, "NUM") == 0);
}

/// Cell property keywords whose value count is checked strictly (a wrong count is an error,
/// not an unknown keyword to skip).
bool IsKnownCellArray(const std::string& name)
{
  static const std::unordered_set<std::string> names = { "ACTNUM", "PORO", "PERMX", "PERMY", "PERMZ", "PERMXY",
    "PERMYZ", "PERMZX", "NTG", "DX", "DY", "DZ", "TOPS", "MULTX", "MULTY", "MULTZ", "MULTX-", "MULTY-", "MULTZ-",
    "MULTPV", "PORV", "SATNUM", "FIPNUM", "EQLNUM", "PVTNUM", "IMBNUM", "ROCKNUM", "MULTNUM", "FLUXNUM", "OPERNUM",
    "ENDNUM", "MISCNUM", "SWATINIT", "SWL", "SWCR", "SWU", "SGL", "SGCR", "SGU", "SOWCR", "SOGCR", "KRW", "KRO", "KRG",
    "PCW", "PCG", "PRESSURE", "SWAT", "SGAS", "SOIL", "RS", "RV", "FACIES", "THCONR", "DEPTH", "TRANX", "TRANY",
    "TRANZ", "PORE", "DIFFMX", "DIFFMY", "DIFFMZ" };
  return names.count(name) > 0;
}

/// Keywords whose records edit cell arrays (see ReadArrayOperations).
bool IsEditKeyword(const std::string& name)
{
  static const std::unordered_set<std::string> names = { "EQUALS", "MULTIPLY", "ADD", "COPY", "MINVALUE", "MAXVALUE",
    "COPYBOX", "OPERATE", "OPERATER", "EQUALREG", "MULTIREG", "ADDREG", "COPYREG" };
  return names.count(name) > 0;
}

bool IsRegionEdit(const std::string& name)
{
  return name == "EQUALREG" || name == "MULTIREG" || name == "ADDREG" || name == "COPYREG";
}

/// Items an edit record must have: array name(s), box or region, value or operation.
std::size_t MinimumEditItems(const std::string& keyword)
{
  if (keyword == "COPYBOX")
    return 13; // array, the box read, the box written
  if (keyword == "OPERATE")
    return 9; // target, box, operation, source
  if (keyword == "OPERATER")
    return 4; // target, region, operation, source
  return IsRegionEdit(keyword) ? 3 : 2;
}

/// Keywords that change the deck when read (geometry, arrays, edits, sections, INCLUDE).
bool IsActedOnKeyword(const std::string& name)
{
  static const std::unordered_set<std::string> names = { "SPECGRID", "DIMENS", "COORD", "ZCORN", "DXV", "DYV", "DZV",
    "MAPAXES", "MAPUNITS", "GRIDUNIT", "GDORIENT", "COORDSYS", "INCLUDE", "IMPORT", "FAULTS", "BOX", "ENDBOX",
    "RUNSPEC", "GRID", "EDIT", "PROPS", "REGIONS", "SOLUTION", "SUMMARY", "SCHEDULE", "END" };
  return names.count(name) > 0 || IsEditKeyword(name) || IsKnownCellArray(name);
}

struct Box
{
  std::array<int64_t, 6> range{}; ///< i1 i2 j1 j2 k1 k2, 0-based inclusive
  int64_t Size() const { return (range[1] - range[0] + 1) * (range[3] - range[2] + 1) * (range[5] - range[4] + 1); }
};

enum class Section
{
  None,
  Runspec,
  Grid,
  Edit,
  Props,
  Regions,
  Solution,
  Summary,
  Schedule
};

/// The cells of a box in ECLIPSE order (i fastest), one after the other.
class BoxWalk
{
public:
  BoxWalk(const Box& box, const std::array<int64_t, 3>& dims)
    : Range(box.range)
    , Dims(dims)
    , I(box.range[0])
    , J(box.range[2])
    , K(box.range[4])
  {
  }
  int64_t Next()
  {
    const int64_t cell = (this->K * this->Dims[1] + this->J) * this->Dims[0] + this->I;
    if (++this->I > this->Range[1])
    {
      this->I = this->Range[0];
      if (++this->J > this->Range[3])
      {
        this->J = this->Range[2];
        ++this->K;
      }
    }
    return cell;
  }

private:
  std::array<int64_t, 6> Range;
  std::array<int64_t, 3> Dims;
  int64_t I, J, K;
};

/// Values of a spooled array put cell by cell, written in runs of consecutive cells.
template<typename T>
class SpoolWriter
{
public:
  explicit SpoolWriter(SpoolFile& file)
    : File(file)
  {
  }
  void Put(int64_t cell, T value)
  {
    if (!this->Values.empty() && cell != this->First + static_cast<int64_t>(this->Values.size()))
    {
      this->Flush();
    }
    if (this->Values.empty())
    {
      this->First = cell;
    }
    this->Values.push_back(value);
    if (this->Values.size() >= (1u << 16))
    {
      this->Flush();
    }
  }
  void Flush()
  {
    this->File.Write(this->First, this->Values.data(), static_cast<int64_t>(this->Values.size()));
    this->Values.clear();
  }

private:
  SpoolFile& File;
  int64_t First = 0;
  std::vector<T> Values;
};

class Parser
{
public:
  Parser(const GrdeclParseOptions& options)
    : Options(options)
  {
    if (this->Options.maxCells <= 0)
    {
      this->Options.maxCells = MaxParsableCells();
    }
  }

  /// Bounded-memory mode (ParseGrdeclGrid): grid arrays to `spool`, properties dropped.
  void SpoolTo(const std::string& folder, GrdeclGridSpool& spool)
  {
    this->SpoolFolder = folder;
    this->Spool = &spool;
  }

  CornerPointModel Run(const std::string& path)
  {
    this->RootDirectory = DirectoryOf(path);
    this->ParseAnyFile(path, 0);
    this->Finish();
    return std::move(this->Deck);
  }

private:
  static std::string DirectoryOf(const std::string& path)
  {
    const auto slash = path.find_last_of('/');
    return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
  }

  void ParseAnyFile(const std::string& path, int depth)
  {
    this->Deck.files.push_back(path);
    if (EclipseKeywordFile::LooksLikeUnformatted(path))
    {
      this->ParseBinaryFile(path);
    }
    else
    {
      this->ParseTextFile(path, depth);
    }
  }

  // ---------------------------------------------------------------- errors and helpers
  [[noreturn]] void Fail(const Token& token, const std::string& keyword, const std::string& what)
  {
    throw InputError(this->Tokens->GetPath(), token.line, keyword, what);
  }

  [[noreturn]] void FailHere(const std::string& keyword, const std::string& what)
  {
    throw InputError(this->CurrentFile, this->CurrentLine, keyword, what);
  }

  static std::string Describe(const Token& token)
  {
    switch (token.kind)
    {
      case TokenKind::End:
        return "end of file";
      case TokenKind::Slash:
        return "'/'";
      case TokenKind::String:
        return "'" + std::string(token.text) + "'";
      default:
        break;
    }
    std::string text(token.text.substr(0, 40));
    for (char& c : text)
    {
      if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126)
      {
        c = '?';
      }
    }
    return "'" + text + "'";
  }

  int64_t CellCount(const std::string& keyword)
  {
    if (this->Deck.dims[0] == 0)
    {
      this->FailHere(
        keyword, "appears before SPECGRID or DIMENS gave the grid dimensions" + this->MissingIncludeNote());
    }
    return this->Deck.CellCount();
  }

  Box WholeGrid() const
  {
    const auto& d = this->Deck.dims;
    return Box{ { 0, d[0] - 1, 0, d[1] - 1, 0, d[2] - 1 } };
  }

  /// Record of bare words / strings / numbers up to '/', as text; `N*` expands to N "".
  std::vector<std::string> ReadRecord(const std::string& keyword, bool* sawSlash = nullptr)
  {
    std::vector<std::string> items;
    for (bool first = true;; first = false)
    {
      const Token& token = this->Tokens->Next();
      if (first)
      {
        this->LastRecordLine = token.line;
      }
      if (token.kind == TokenKind::Slash)
      {
        if (sawSlash)
        {
          *sawSlash = true;
        }
        return items;
      }
      if (token.kind == TokenKind::End)
      {
        this->Fail(token, keyword, "unterminated keyword: reached end of file before '/'");
      }
      // A keyword this parser acts on, opening a new line after some items: this record
      // lost its '/'. (Other words may start lines inside records: GDORIENT's INC, ...)
      if (token.kind == TokenKind::Word && token.atLineStart && !items.empty() &&
        IsActedOnKeyword(std::string(token.text)))
      {
        this->Fail(token, keyword, "record not terminated by '/' before " + Describe(token) + " on a new line");
      }
      if (items.size() > 4096)
      {
        this->Fail(token, keyword, "record longer than 4096 items: missing '/'?");
      }
      NumberToken number;
      if (token.kind == TokenKind::Word && token.text.find('*') != std::string_view::npos &&
        ParseNumberToken(token.text, number) && number.isDefault)
      {
        if (number.repeat > 4096)
        {
          this->Fail(token, keyword, "default repeat count too large");
        }
        items.insert(items.end(), static_cast<std::size_t>(number.repeat), std::string());
        continue;
      }
      items.emplace_back(token.text);
    }
  }

  int64_t RecordInteger(const std::vector<std::string>& items, std::size_t index, const std::string& keyword,
    const std::string& what, int64_t fallback, bool required)
  {
    if (index >= items.size() || items[index].empty())
    {
      if (required)
      {
        this->FailHere(keyword, "missing " + what);
      }
      return fallback;
    }
    double value = 0;
    if (!ParseDouble(items[index], value) || value != std::floor(value) || std::fabs(value) > 9e18)
    {
      this->FailHere(keyword, what + " must be an integer, got '" + items[index] + "'");
    }
    return static_cast<int64_t>(value);
  }

  double RecordNumber(
    const std::vector<std::string>& items, std::size_t index, const std::string& keyword, const std::string& what)
  {
    double value = 0;
    if (index >= items.size() || !ParseDouble(items[index], value))
    {
      this->FailHere(keyword, what + " must be a number, got '" + (index < items.size() ? items[index] : "") + "'");
    }
    return value;
  }

  /// Reads an optional box (i1 i2 j1 j2 k1 k2, 1-based) starting at items[first].
  Box RecordBox(
    const std::vector<std::string>& items, std::size_t first, const Box& fallback, const std::string& keyword)
  {
    Box box = fallback;
    const auto& d = this->Deck.dims;
    for (int axis = 0; axis < 3; ++axis)
    {
      for (int end = 0; end < 2; ++end)
      {
        const std::size_t index = first + 2 * axis + end;
        const int64_t value = this->RecordInteger(items, index, keyword, "box bound", -1, false);
        if (value != -1)
        {
          box.range[2 * axis + end] = value - 1;
        }
      }
      if (box.range[2 * axis] < 0 || box.range[2 * axis] > box.range[2 * axis + 1] ||
        box.range[2 * axis + 1] >= d[axis])
      {
        this->FailHere(keyword,
          "box " + std::to_string(box.range[2 * axis] + 1) + "-" + std::to_string(box.range[2 * axis + 1] + 1) +
            " is outside the grid's " + "IJK"[axis] + " range 1-" + std::to_string(d[axis]));
      }
    }
    return box;
  }

  CellArray& ArrayFor(const std::string& name)
  {
    if (CellArray* existing = this->Deck.FindArray(name))
    {
      return *existing;
    }
    const int64_t n = this->CellCount(name);
    CellArray array;
    array.name = name;
    array.isInteger = IsIntegerArrayName(name);
    array.values.assign(static_cast<std::size_t>(n), NotGiven(name));
    this->Deck.arrays.push_back(std::move(array));
    return this->Deck.arrays.back();
  }

  template<typename Visit>
  void ForEachCell(const Box& box, Visit&& visit)
  {
    const auto& d = this->Deck.dims;
    for (int64_t k = box.range[4]; k <= box.range[5]; ++k)
    {
      for (int64_t j = box.range[2]; j <= box.range[3]; ++j)
      {
        const int64_t row = (k * d[1] + j) * d[0];
        for (int64_t i = box.range[0]; i <= box.range[1]; ++i)
        {
          visit(row + i);
        }
      }
    }
  }

  /// Calls visit(first cell, count) for each row of the box (cells consecutive in i).
  template<typename Visit>
  void ForEachRow(const Box& box, Visit&& visit)
  {
    const auto& d = this->Deck.dims;
    for (int64_t k = box.range[4]; k <= box.range[5]; ++k)
    {
      for (int64_t j = box.range[2]; j <= box.range[3]; ++j)
      {
        visit((k * d[1] + j) * d[0] + box.range[0], box.range[1] - box.range[0] + 1);
      }
    }
  }

  // ---------------------------------------------------------------- bounded-memory mode
  bool Spooling() const { return this->Spool != nullptr; }

  /// Spooling: the cell arrays kept (in temporary files); any other one is dropped.
  bool Spooled(const std::string& name) const { return this->Spooling() && IsGeometryArrayName(name); }

  std::unique_ptr<SpoolFile>& SpoolSlot(const std::string& name)
  {
    GrdeclGridSpool& spool = *this->Spool;
    return name == "ACTNUM" ? spool.actnum
      : name == "DX"        ? spool.dx
      : name == "DY"        ? spool.dy
      : name == "DZ"        ? spool.dz
                            : spool.tops;
  }

  /// The spooled array `name`, created all NaN ("not given") if new, as ArrayFor creates.
  SpoolFile& SpoolFor(const std::string& name)
  {
    std::unique_ptr<SpoolFile>& slot = this->SpoolSlot(name);
    if (!slot)
    {
      const int64_t n = this->CellCount(name);
      slot.reset(new SpoolFile(this->SpoolFolder, name));
      slot->Fill(0, n, NotGiven(name));
    }
    return *slot;
  }

  /// True if the array was given (spooling: kept or dropped).
  bool Defined(const std::string& name)
  {
    if (!this->Spooling())
    {
      return this->Deck.FindArray(name) != nullptr;
    }
    return this->Spooled(name) ? this->SpoolSlot(name) != nullptr : this->DroppedArrays.count(name) > 0;
  }

  /// Applies edit(value&) to the cells of `box` in a spooled array, a row at a time.
  template<typename Edit>
  void EditSpool(SpoolFile& file, const Box& box, Edit&& edit)
  {
    std::vector<double> row;
    this->ForEachRow(box, [&](int64_t first, int64_t count) {
      row.resize(static_cast<std::size_t>(count));
      file.Read(first, row.data(), count);
      for (double& value : row)
      {
        edit(value);
      }
      file.Write(first, row.data(), count);
    });
  }

  // ---------------------------------------------------------------- number arrays
  /// Reads numbers up to '/' and hands each to store(index, value); exactly `expected` values.
  /// Returns false (without consuming the unexpected token) if `lenient` and the data turn
  /// out not to be a plain numeric array.
  template<typename Store>
  bool ReadNumbers(const std::string& keyword, int64_t expected, bool lenient, bool allowDefaults, Store&& store,
    int64_t alsoAccepted = -1)
  {
    int64_t count = 0;
    const double undefined = std::numeric_limits<double>::quiet_NaN();
    for (;;)
    {
      const Token& token = this->Tokens->Next();
      if (token.kind == TokenKind::Slash)
      {
        break;
      }
      if (token.kind == TokenKind::End)
      {
        if (lenient)
        {
          return false;
        }
        this->Fail(token, keyword,
          "unterminated keyword: reached end of file after " + std::to_string(count) + " values, expected " +
            std::to_string(expected) + " and a '/'");
      }
      NumberToken number;
      if (token.kind != TokenKind::Word || !ParseNumberToken(token.text, number))
      {
        if (lenient)
        {
          this->Tokens->PushBack();
          return false;
        }
        if (token.atLineStart && token.kind == TokenKind::Word && LooksLikeKeyword(token.text))
        {
          this->Fail(token, keyword,
            "missing '/' terminator: reached keyword " + Describe(token) + " after " + std::to_string(count) + " of " +
              std::to_string(expected) + " values");
        }
        this->Fail(token, keyword,
          "expected a number, got " + Describe(token) + " (value " + std::to_string(count + 1) + " of " +
            std::to_string(expected) + ")");
      }
      if (!std::isfinite(number.value))
      {
        this->Fail(token, keyword, "value " + Describe(token) + " is not finite");
      }
      if (number.isDefault && !allowDefaults && !lenient)
      {
        this->Fail(token, keyword, "default values (" + Describe(token) + ") are not allowed here");
      }
      if (number.repeat > expected - count)
      {
        if (lenient)
        {
          this->Tokens->PushBack();
          return false;
        }
        this->Fail(token, keyword,
          "too many values: more than the " + std::to_string(expected) + " expected (at " + Describe(token) + ")");
      }
      const double value = number.isDefault ? undefined : number.value;
      for (int64_t r = 0; r < number.repeat; ++r)
      {
        store(count++, value);
      }
    }
    if (count != expected && count != alsoAccepted)
    {
      if (lenient)
      {
        return false;
      }
      this->FailHere(keyword,
        "wrong number of values: expected " + std::to_string(expected) +
          (alsoAccepted >= 0 ? " or " + std::to_string(alsoAccepted) : std::string()) + ", got " +
          std::to_string(count));
    }
    return true;
  }

  void ReadDenseArray(const std::string& keyword, std::vector<double>& target, int64_t expected)
  {
    target.clear();
    target.reserve(static_cast<std::size_t>(expected));
    this->ReadNumbers(keyword, expected, false, false, [&](int64_t, double value) { target.push_back(value); });
  }

  /// Reads a cell array (PORO, ACTNUM, ...) into the current BOX; `lenient` for keywords we
  /// do not know, which are kept only if they turn out to hold one number per cell.
  void ReadCellArray(const std::string& keyword, bool lenient)
  {
    const Box box = this->CurrentBox ? *this->CurrentBox : this->WholeGrid();
    int64_t expected = box.Size();
    const bool wholeGrid = !this->CurrentBox;
    if (keyword == "TOPS" && wholeGrid)
    {
      // TOPS may give the top layer only; accept both forms.
      this->ReadTops();
      return;
    }
    if (!wholeGrid && !IsViewerArray(keyword) && !this->Defined(keyword))
    {
      // Part of an array the viewer does not build (MULTZ or TRANX in a BOX ...): checked,
      // not kept, since the cells outside the box would have no value.
      if (!this->ReadNumbers(keyword, expected, lenient, true, [](int64_t, double) {}))
      {
        this->SkipRestOfKeyword();
        return;
      }
      this->RecordLine = this->CurrentLine;
      this->WarnSkippedEdit(keyword, keyword);
      return;
    }
    if (this->Spooling() && !this->Spooled(keyword))
    {
      // A property: checked as below, not kept.
      if (!this->ReadNumbers(keyword, expected, lenient, true, [](int64_t, double) {}))
      {
        this->SkipRestOfKeyword();
        return;
      }
      this->DroppedArrays.insert(keyword);
      return;
    }
    if (this->Spooling())
    {
      SpoolWriter<double> writer(this->SpoolFor(keyword));
      BoxWalk cells(box, this->Deck.dims);
      this->ReadNumbers(
        keyword, expected, false, true, [&](int64_t, double value) { writer.Put(cells.Next(), value); });
      writer.Flush();
      return;
    }
    if (lenient)
    {
      std::vector<double> values;
      if (!this->ReadNumbers(keyword, expected, true, true, [&](int64_t, double value) { values.push_back(value); }))
      {
        this->SkipRestOfKeyword();
        return;
      }
      CellArray& array = this->ArrayFor(keyword);
      int64_t index = 0;
      this->ForEachCell(box, [&](int64_t cell) { array.values[cell] = values[index++]; });
      return;
    }
    CellArray& array = this->ArrayFor(keyword);
    double* data = array.values.data();
    if (wholeGrid)
    {
      this->ReadNumbers(keyword, expected, false, true, [&](int64_t index, double value) { data[index] = value; });
      return;
    }
    std::vector<int64_t> cells;
    cells.reserve(static_cast<std::size_t>(expected));
    this->ForEachCell(box, [&](int64_t cell) { cells.push_back(cell); });
    this->ReadNumbers(keyword, expected, false, true, [&](int64_t index, double value) { data[cells[index]] = value; });
  }

  void ReadTops()
  {
    const int64_t n = this->CellCount("TOPS");
    const int64_t layer = this->Deck.dims[0] * this->Deck.dims[1];
    if (this->Spooling())
    {
      SpoolWriter<double> writer(this->SpoolFor("TOPS"));
      this->ReadNumbers(
        "TOPS", n, false, true, [&](int64_t index, double value) { writer.Put(index, value); }, layer);
      writer.Flush();
      return;
    }
    double* tops = this->ArrayFor("TOPS").values.data();
    this->ReadNumbers(
      "TOPS", n, false, true, [&](int64_t index, double value) { tops[index] = value; }, layer);
  }

  /// Skips an unknown keyword: up to its '/' or up to the next keyword on a new line.
  void SkipRestOfKeyword()
  {
    for (;;)
    {
      const Token& token = this->Tokens->Next();
      if (token.kind == TokenKind::Slash || token.kind == TokenKind::End)
      {
        return;
      }
      if (token.kind == TokenKind::Word && token.atLineStart && LooksLikeKeyword(token.text))
      {
        this->Tokens->PushBack();
        return;
      }
    }
  }

  // ---------------------------------------------------------------- keywords
  void SetMapAxes(const std::vector<double>& v)
  {
    this->Deck.hasMapAxes = true;
    this->Deck.mapAxes = MapAxes{ { v[0], v[1] }, { v[2], v[3] }, { v[4], v[5] } };
  }

  void SetUnits(const std::string& keyword, const std::vector<std::string>& items)
  {
    std::string& target = keyword == "GRIDUNIT" ? this->Deck.gridUnit : this->Deck.mapUnits;
    target = items.empty() ? "" : items[0];
    if (keyword == "GRIDUNIT")
    {
      this->Deck.gridUnitIsMap = items.size() > 1 && Upper(items[1]).rfind("MAP", 0) == 0;
    }
  }

  /// DIMENS and SPECGRID may both appear, but must agree: every array, BOX and FAULTS record
  /// read so far was sized and checked against the first.
  void SetDimensions(const std::array<int64_t, 3>& dims, const std::string& keyword)
  {
    const auto& old = this->Deck.dims;
    if (old[0] != 0 && old != dims)
    {
      this->FailHere(keyword,
        "grid dimensions " + std::to_string(dims[0]) + " x " + std::to_string(dims[1]) + " x " +
          std::to_string(dims[2]) + " differ from the " + std::to_string(old[0]) + " x " + std::to_string(old[1]) +
          " x " + std::to_string(old[2]) + " given before");
    }
    this->Deck.dims = dims;
  }

  void ReadDimensions(const std::string& keyword)
  {
    const std::vector<std::string> items = this->ReadRecord(keyword);
    std::array<int64_t, 3> dims{};
    for (int axis = 0; axis < 3; ++axis)
    {
      dims[axis] = this->RecordInteger(items, axis, keyword, std::string("N") + "XYZ"[axis], 0, true);
    }
    double numres = 1;
    if (keyword == "SPECGRID" && items.size() > 3 && ParseDouble(items[3], numres) && numres != 1)
    {
      this->FailHere(keyword, "multiple reservoirs (NUMRES > 1) are not supported");
    }
    CheckedCellCount(dims, this->Options.maxCells, this->CurrentFile, this->CurrentLine, keyword);
    this->SetDimensions(dims, keyword);
  }

  void ReadFaults()
  {
    const std::string keyword = "FAULTS";
    for (;;)
    {
      bool slash = false;
      const std::vector<std::string> items = this->ReadRecord(keyword, &slash);
      if (items.empty())
      {
        return; // empty record ends the keyword
      }
      if (this->Deck.dims[0] == 0)
      {
        this->FailHere(keyword, "appears before SPECGRID or DIMENS gave the grid dimensions");
      }
      if (items.size() < 8)
      {
        this->FailHere(keyword, "record for fault '" + items[0] + "' needs NAME I1 I2 J1 J2 K1 K2 FACE");
      }
      FaultFace face;
      const Box box = this->RecordBox(items, 1, this->WholeGrid(), keyword);
      for (int b = 0; b < 6; ++b)
      {
        face.box[b] = static_cast<int32_t>(box.range[b]);
      }
      const std::string direction = Upper(items[7]);
      static const std::pair<const char*, FaultFace::Direction> directions[] = { { "I", FaultFace::IPlus },
        { "I+", FaultFace::IPlus }, { "X", FaultFace::IPlus }, { "X+", FaultFace::IPlus }, { "I-", FaultFace::IMinus },
        { "X-", FaultFace::IMinus }, { "J", FaultFace::JPlus }, { "J+", FaultFace::JPlus }, { "Y", FaultFace::JPlus },
        { "Y+", FaultFace::JPlus }, { "J-", FaultFace::JMinus }, { "Y-", FaultFace::JMinus }, { "K", FaultFace::KPlus },
        { "K+", FaultFace::KPlus }, { "Z", FaultFace::KPlus }, { "Z+", FaultFace::KPlus }, { "K-", FaultFace::KMinus },
        { "Z-", FaultFace::KMinus } };
      bool known = false;
      for (const auto& entry : directions)
      {
        if (direction == entry.first)
        {
          face.face = entry.second;
          known = true;
        }
      }
      if (!known)
      {
        this->FailHere(keyword,
          "fault '" + items[0] + "' has unknown face '" + items[7] +
            "' (expected I, I-, J, J-, K, K- or X, Y, Z forms)");
      }
      Fault* fault = nullptr;
      auto found = this->FaultIndex.find(items[0]);
      if (found == this->FaultIndex.end())
      {
        this->FaultIndex.emplace(items[0], this->Deck.faults.size());
        this->Deck.faults.push_back(Fault{ items[0], {} });
        fault = &this->Deck.faults.back();
      }
      else
      {
        fault = &this->Deck.faults[found->second];
      }
      fault->faces.push_back(face);
    }
  }

  // ---------------------------------------------------------------- array edits
  /// One record of an edit keyword, read and checked before it touches any array.
  struct ArrayEdit
  {
    std::string target;                          ///< array written
    std::string source;                          ///< array read (COPY, COPYBOX, OPERATE ...), or ""
    bool readsTarget = false;                    ///< the target's old values matter (MULTIPLY, ADD ...)
    Box box;                                     ///< cells written
    Box sourceBox;                               ///< cells read, cell for cell (COPYBOX; else `box`)
    std::string regionArray;                     ///< *REG, OPERATER: only cells of this region ...
    int64_t region = 0;                          ///< ... with this number
    std::function<double(double, double)> apply; ///< (old target, source) -> new target
  };

  /// EQUALS, MULTIPLY, ADD, COPY, MINVALUE, MAXVALUE, COPYBOX, OPERATE and the region forms
  /// EQUALREG, MULTIREG, ADDREG, COPYREG, OPERATER: records ended by an empty one.
  void ReadArrayOperations(const std::string& keyword)
  {
    Box lastBox = this->CurrentBox ? *this->CurrentBox : this->WholeGrid();
    for (;;)
    {
      const std::vector<std::string> items = this->ReadRecord(keyword);
      if (items.empty())
      {
        return;
      }
      this->RecordLine = this->LastRecordLine;
      ArrayEdit edit = this->ReadEditRecord(keyword, items, lastBox);
      if (this->CanApply(keyword, edit))
      {
        this->ApplyEdit(keyword, edit);
      }
    }
  }

  double EditValue(
    const std::vector<std::string>& items, std::size_t index, const std::string& keyword, const std::string& target)
  {
    const double value = this->RecordNumber(items, index, keyword, "value for " + target);
    if (!std::isfinite(value))
    {
      this->FailHere(keyword, "value for " + target + " is not finite");
    }
    return value;
  }

  /// The record's arrays, cells and operation; `lastBox` is the box a record without one
  /// uses (the previous record's, as ECLIPSE does).
  ArrayEdit ReadEditRecord(const std::string& keyword, const std::vector<std::string>& items, Box& lastBox)
  {
    const std::size_t needed = MinimumEditItems(keyword);
    if (items.size() < needed || items[0].empty())
    {
      this->FailHere(keyword,
        "record needs at least " + std::to_string(needed) + " items (array name, values ...), got " +
          std::to_string(items.size()));
    }
    ArrayEdit edit;
    edit.target = Upper(items[0]);
    if (keyword == "OPERATE" || keyword == "OPERATER")
    {
      return this->ReadOperateRecord(keyword, items, edit);
    }
    if (IsRegionEdit(keyword))
    {
      edit.box = this->WholeGrid();
      edit.sourceBox = edit.box;
      edit.region = this->RecordInteger(items, 2, keyword, "region number", 0, true);
      edit.regionArray = this->RegionArrayFor(keyword, items, 3, "M");
      if (keyword == "COPYREG")
      {
        edit.source = edit.target;
        edit.target = Upper(items[1]);
        edit.apply = [](double, double x) { return x; };
        return edit;
      }
      const double value = this->EditValue(items, 1, keyword, edit.target);
      edit.readsTarget = keyword != "EQUALREG";
      if (keyword == "EQUALREG")
        edit.apply = [value](double, double) { return value; };
      else if (keyword == "MULTIREG")
        edit.apply = [value](double r, double) { return r * value; };
      else
        edit.apply = [value](double r, double) { return r + value; };
      return edit;
    }
    if (keyword == "COPYBOX")
    {
      edit.source = edit.target;
      edit.sourceBox = this->RecordBox(items, 1, this->WholeGrid(), keyword);
      edit.box = this->RecordBox(items, 7, this->WholeGrid(), keyword);
      for (int axis = 0; axis < 3; ++axis)
      {
        const auto& s = edit.sourceBox.range;
        const auto& d = edit.box.range;
        if (s[2 * axis + 1] - s[2 * axis] != d[2 * axis + 1] - d[2 * axis])
        {
          this->FailHere(keyword, "the boxes copied from and to differ in size along " + std::string(1, "IJK"[axis]));
        }
      }
      edit.apply = [](double, double x) { return x; };
      return edit;
    }
    edit.box = this->RecordBox(items, 2, lastBox, keyword);
    edit.sourceBox = edit.box;
    lastBox = edit.box;
    if (keyword == "COPY")
    {
      edit.source = edit.target;
      edit.target = Upper(items[1]);
      edit.apply = [](double, double x) { return x; };
      return edit;
    }
    const double value = this->EditValue(items, 1, keyword, edit.target);
    edit.readsTarget = keyword != "EQUALS";
    if (keyword == "EQUALS")
      edit.apply = [value](double, double) { return value; };
    else if (keyword == "MULTIPLY")
      edit.apply = [value](double r, double) { return r * value; };
    else if (keyword == "ADD")
      edit.apply = [value](double r, double) { return r + value; };
    else if (keyword == "MINVALUE")
      edit.apply = [value](double r, double) { return std::isnan(r) ? r : std::max(r, value); };
    else
      edit.apply = [value](double r, double) { return std::isnan(r) ? r : std::min(r, value); };
    return edit;
  }

  /// OPERATE: target, box, operation, source, alpha, beta. OPERATER: target, region number,
  /// operation, source, alpha, beta, region array (OPERNUM if not given).
  ArrayEdit ReadOperateRecord(const std::string& keyword, const std::vector<std::string>& items, ArrayEdit& edit)
  {
    std::size_t next = 1;
    if (keyword == "OPERATE")
    {
      edit.box = this->RecordBox(items, 1, this->CurrentBox ? *this->CurrentBox : this->WholeGrid(), keyword);
      next = 7;
    }
    else
    {
      edit.box = this->WholeGrid();
      edit.region = this->RecordInteger(items, 1, keyword, "region number", 0, true);
      next = 2;
    }
    edit.sourceBox = edit.box;
    const std::string operation = next < items.size() ? Upper(items[next]) : std::string();
    edit.source = next + 1 < items.size() ? Upper(items[next + 1]) : std::string();
    if (edit.source.empty())
    {
      this->FailHere(keyword, "record for " + edit.target + " names no source array");
    }
    const double alpha = next + 2 < items.size() && !items[next + 2].empty()
      ? this->EditValue(items, next + 2, keyword, edit.target)
      : 0.0;
    const double beta = next + 3 < items.size() && !items[next + 3].empty()
      ? this->EditValue(items, next + 3, keyword, edit.target)
      : 0.0;
    edit.apply = ArrayOperation(operation, alpha, beta);
    if (!edit.apply)
    {
      this->FailHere(keyword,
        "unknown operation '" + operation + "' for " + edit.target +
          " (MULTA, POLY, SLOG, LOG10, LOGE, INV, MULTX, ADDX, COPY, MAXLIM, MINLIM, MULTP, "
          "ABS, MULTIPLY)");
    }
    edit.readsTarget = OperationReadsTarget(operation);
    if (keyword == "OPERATER")
    {
      edit.regionArray = this->RegionArrayFor(keyword, items, 6, "OPERNUM");
    }
    return edit;
  }

  std::string RegionArrayFor(
    const std::string& keyword, const std::vector<std::string>& items, std::size_t index, const std::string& fallback)
  {
    const std::string given = index < items.size() && !items[index].empty() ? Upper(items[index]) : fallback;
    const std::string name = RegionArrayName(given);
    if (name.empty())
    {
      this->FailHere(keyword, "region array '" + given + "' is not M, F, O or a *NUM array");
    }
    return name;
  }

  /// Whether the edit can be applied: skipped with a warning when it touches only arrays the
  /// viewer does not build; an error when it needs a viewer array that is missing.
  bool CanApply(const std::string& keyword, const ArrayEdit& edit)
  {
    const bool viewerEdit =
      IsViewerArray(edit.target) || (!edit.source.empty() && IsViewerArray(edit.source) && this->Defined(edit.source));
    if (!edit.source.empty() && !this->Defined(edit.source) && !IsRegionArrayName(edit.source))
    {
      if (IsViewerArray(edit.source) || IsViewerArray(edit.target))
      {
        this->FailHere(keyword, "source array " + edit.source + " has not been defined" + this->MissingIncludeNote());
      }
      this->WarnSkippedEdit(keyword, edit.source);
      return false;
    }
    if (this->Defined(edit.target) || IsRegionArrayName(edit.target))
    {
      return true; // region numbers not given are 1
    }
    if (edit.readsTarget && IsViewerArray(edit.target))
    {
      this->FailHere(keyword, "array " + edit.target + " has not been defined" + this->MissingIncludeNote());
    }
    if (edit.readsTarget || !viewerEdit || !IsViewerArray(edit.target))
    {
      this->WarnSkippedEdit(keyword, edit.target);
      return false;
    }
    return true;
  }

  /// One warning per keyword, array and place.
  void WarnSkippedEdit(const std::string& keyword, const std::string& array)
  {
    const std::string kind = SimulatorArrayKind(array);
    const std::string why = kind.empty() ? "is not defined by this deck and is not an array the viewer knows"
                                         : "is a " + kind + ", which the viewer does not build";
    this->Warn(keyword, "array " + array + " " + why + "; edit skipped");
  }

  void Warn(const std::string& keyword, const std::string& what)
  {
    const std::string message = InputError::Format(this->CurrentFile, this->RecordLine, keyword, what);
    if (this->WarningsGiven.insert(message).second)
    {
      this->Deck.warnings.push_back(message);
    }
  }

  /// A cell array's values a row of cells at a time, whether held in the deck or spooled.
  struct ArrayRows
  {
    CellArray* held = nullptr;
    SpoolFile* spooled = nullptr;
    void Read(int64_t first, int64_t count, double* out) const
    {
      if (this->held)
      {
        std::copy_n(this->held->values.data() + first, count, out);
      }
      else
      {
        this->spooled->Read(first, out, count);
      }
    }
    void Write(int64_t first, int64_t count, const double* in) const
    {
      if (this->held)
      {
        std::copy_n(in, count, this->held->values.data() + first);
      }
      else
      {
        this->spooled->Write(first, in, count);
      }
    }
  };

  /// Applies a checked edit, row by row in the box (backwards when a COPYBOX within one array
  /// would otherwise read rows it has already written).
  void ApplyEdit(const std::string& keyword, const ArrayEdit& edit)
  {
    ArrayRows out, in, regions;
    if (this->Spooling())
    {
      if (!this->Spooled(edit.target))
      {
        this->DroppedArrays.insert(edit.target); // a property: checked, not kept
        return;
      }
      if (!edit.source.empty() && !this->Spooled(edit.source))
      {
        this->FailHere(keyword,
          "cannot set " + edit.target + " from " + edit.source +
            ": when the grid is read with bounded memory (resmr build) property arrays are not "
            "kept; give " +
            edit.target + " its values directly (or with EQUALS)");
      }
      if (!edit.regionArray.empty() && this->Defined(edit.regionArray))
      {
        this->FailHere(keyword,
          "cannot edit " + edit.target + " by region " + edit.regionArray +
            ": when the grid is read with bounded memory (resmr build) " + "region arrays are not kept");
      }
      out.spooled = &this->SpoolFor(edit.target);
      in.spooled = edit.source.empty() ? nullptr : &this->SpoolFor(edit.source);
    }
    else
    {
      if (!edit.source.empty())
      {
        this->ArrayFor(edit.source); // a region array not given yet: 1 in every cell
      }
      out.held = &this->ArrayFor(edit.target); // before taking pointers: it may move arrays
      in.held = edit.source.empty() ? nullptr : this->Deck.FindArray(edit.source);
      regions.held = edit.regionArray.empty() ? nullptr : this->Deck.FindArray(edit.regionArray);
    }
    const bool hasSource = in.held || in.spooled;
    const bool hasRegions = regions.held != nullptr;
    const auto& s = edit.sourceBox.range;
    const auto& d = edit.box.range;
    const bool backwards = edit.source == edit.target && std::make_pair(d[4], d[2]) > std::make_pair(s[4], s[2]);
    const int64_t rows = (d[5] - d[4] + 1) * (d[3] - d[2] + 1);
    const int64_t count = d[1] - d[0] + 1;
    std::vector<double> target(count), source(count), region(count);
    for (int64_t r = 0; r < rows; ++r)
    {
      const int64_t row = backwards ? rows - 1 - r : r;
      const int64_t dj = row % (d[3] - d[2] + 1), dk = row / (d[3] - d[2] + 1);
      const int64_t to = this->CellIndex(d[0], d[2] + dj, d[4] + dk);
      const int64_t from = this->CellIndex(s[0], s[2] + dj, s[4] + dk);
      out.Read(to, count, target.data());
      if (hasSource)
      {
        in.Read(from, count, source.data());
      }
      if (hasRegions)
      {
        regions.Read(to, count, region.data());
      }
      for (int64_t e = 0; e < count; ++e)
      {
        // A region array the deck does not give is 1 in every cell, as for ECLIPSE.
        if (!edit.regionArray.empty() && (hasRegions ? region[e] : 1.0) != double(edit.region))
        {
          continue;
        }
        const double value = edit.apply(target[e], hasSource ? source[e] : 0.0);
        target[e] = std::isfinite(value) ? value : std::numeric_limits<double>::quiet_NaN();
      }
      out.Write(to, count, target.data());
    }
  }

  int64_t CellIndex(int64_t i, int64_t j, int64_t k) const
  {
    return (k * this->Deck.dims[1] + j) * this->Deck.dims[0] + i;
  }

  // ---------------------------------------------------------------- skipped keywords
  /// Reads a keyword the viewer has no use for to its end (see SkippedKeyword), with one
  /// warning naming it.
  void SkipUnusedKeyword(const std::string& keyword, SkippedShape shape, const std::string& why)
  {
    if (shape == SkippedShape::OneRecord)
    {
      this->ReadRecord(keyword);
      this->RecordLine = this->CurrentLine;
      this->Warn(keyword, "skipped: the viewer does not use " + why);
      return;
    }
    if (shape == SkippedShape::Records)
    {
      while (!this->ReadRecord(keyword).empty())
      {
      }
      this->RecordLine = this->CurrentLine;
      this->Warn(keyword, "skipped: the viewer does not use " + why);
      return;
    }
    const std::vector<std::string> items = this->ReadRecord(keyword);
    const std::string name = items.empty() || items[0].empty() ? "(unnamed)" : "'" + items[0] + "'";
    for (;;)
    {
      const Token& token = this->Tokens->Next();
      if (token.kind == TokenKind::End)
      {
        this->FailHere(keyword, "local grid " + name + " has no ENDFIN");
      }
      if (token.kind == TokenKind::Word && token.atLineStart && Upper(token.text) == "ENDFIN")
      {
        break;
      }
    }
    this->RecordLine = this->CurrentLine;
    this->Warn(keyword,
      why + " " + name + " (" + keyword +
        " ... ENDFIN) is not shown; the "
        "viewer shows the global grid");
  }

  /// For errors caused by something a missing INCLUDE would have given.
  std::string MissingIncludeNote() const
  {
    if (this->MissingIncludes.empty())
    {
      return "";
    }
    std::string note = " (";
    for (std::size_t i = 0; i < this->MissingIncludes.size(); ++i)
    {
      note += (i ? ", " : "") + this->MissingIncludes[i];
    }
    return note + (this->MissingIncludes.size() == 1 ? " was" : " were") + " not found)";
  }

  void ReadInclude(const std::string& keyword, int depth)
  {
    const std::vector<std::string> items = this->ReadRecord(keyword);
    if (items.empty() || items[0].empty())
    {
      this->FailHere(keyword, "missing file name");
    }
    const std::string name = items[0];
    const std::string here = DirectoryOf(this->Tokens->GetPath());
    std::vector<std::string> candidates;
    if (name[0] == '/')
    {
      candidates.push_back(name);
    }
    else
    {
      candidates.push_back(here + "/" + name);
      candidates.push_back(this->RootDirectory + "/" + name);
    }
    for (const std::string& candidate : candidates)
    {
      if (std::FILE* probe = std::fopen(candidate.c_str(), "rb"))
      {
        std::fclose(probe);
        if (depth + 1 > MaxIncludeDepth)
        {
          this->FailHere(keyword,
            "includes nested deeper than " + std::to_string(MaxIncludeDepth) + " levels (does a file include itself?)");
        }
        const std::string savedFile = this->CurrentFile;
        const int64_t savedLine = this->CurrentLine;
        GrdeclTokenizer* savedTokens = this->Tokens;
        this->ParseAnyFile(candidate, depth + 1);
        this->Tokens = savedTokens;
        this->CurrentFile = savedFile;
        this->CurrentLine = savedLine;
        return;
      }
    }
    const std::string message = "included file '" + name + "' not found (looked in " + here +
      (here == this->RootDirectory ? "" : " and " + this->RootDirectory) + ")";
    if (!this->Options.skipMissingIncludes)
    {
      this->FailHere(keyword, message);
    }
    this->Deck.warnings.push_back(
      InputError::Format(this->CurrentFile, this->CurrentLine, keyword, message + "; skipped"));
    this->MissingIncludes.push_back(
      keyword + " of '" + name + "' at " + this->CurrentFile + ":" + std::to_string(this->CurrentLine));
  }

  void ParseTextFile(const std::string& path, int depth)
  {
    GrdeclTokenizer tokens(path);
    this->Tokens = &tokens;
    this->CurrentFile = path;
    for (;;)
    {
      if (this->Stopped)
      {
        return;
      }
      const Token& token = tokens.Next();
      if (token.kind == TokenKind::End)
      {
        return;
      }
      // Outside a keyword only keywords in column 1 matter: anything else is the remainder
      // of a skipped keyword (tables, well records ...).
      if (token.kind != TokenKind::Word || !token.atLineStart || !LooksLikeKeyword(token.text))
      {
        continue;
      }
      const std::string keyword(token.text);
      this->CurrentLine = token.line;
      this->HandleKeyword(keyword, depth);
    }
  }

  bool InPropertySection() const
  {
    return this->CurrentSection != Section::Runspec && this->CurrentSection != Section::Summary &&
      this->CurrentSection != Section::Schedule;
  }

  /// Section keywords (RUNSPEC ... SCHEDULE, END): true if `keyword` is one.
  bool EnterSection(const std::string& keyword)
  {
    static const std::unordered_map<std::string, Section> sections = { { "RUNSPEC", Section::Runspec },
      { "GRID", Section::Grid }, { "EDIT", Section::Edit }, { "PROPS", Section::Props },
      { "REGIONS", Section::Regions }, { "SOLUTION", Section::Solution }, { "SUMMARY", Section::Summary },
      { "SCHEDULE", Section::Schedule }, { "END", Section::Schedule } };
    const auto found = sections.find(keyword);
    if (found == sections.end())
    {
      return false;
    }
    this->CurrentSection = found->second;
    if (found->second == Section::Schedule)
    {
      this->Stopped = this->Options.stopAtSchedule || keyword == "END";
    }
    return true;
  }

  void HandleKeyword(const std::string& keyword, int depth)
  {
    GrdeclTokenizer& tokens = *this->Tokens;
    std::string why;
    if (this->CurrentSection == Section::Summary)
    {
      static const std::unordered_set<std::string> leaving = { "SCHEDULE", "END", "RUNSPEC", "GRID", "EDIT", "PROPS",
        "REGIONS", "SOLUTION" };
      if (!leaving.count(keyword))
      {
        return; // summary vectors: nothing for the grid
      }
    }
    if (keyword == "SPECGRID" || keyword == "DIMENS")
    {
      this->ReadDimensions(keyword);
    }
    else if (keyword == "COORD")
    {
      const auto& d = this->Deck.dims;
      this->CellCount(keyword);
      this->ReadDenseArray(keyword, this->Deck.coord, 6 * (d[0] + 1) * (d[1] + 1));
    }
    else if (keyword == "ZCORN" && this->Spooling())
    {
      const int64_t expected = 8 * this->CellCount(keyword);
      std::unique_ptr<SpoolFile> file(new SpoolFile(this->SpoolFolder, keyword));
      SpoolWriter<float> writer(*file);
      this->ReadNumbers(keyword, expected, false, false,
        [&](int64_t index, double value) { writer.Put(index, static_cast<float>(value)); });
      writer.Flush();
      this->Spool->zcorn = std::move(file); // a second ZCORN replaces the first
    }
    else if (keyword == "ZCORN")
    {
      this->ReadDenseArray(keyword, this->Deck.zcorn, 8 * this->CellCount(keyword));
    }
    else if (keyword == "DXV" || keyword == "DYV" || keyword == "DZV")
    {
      this->CellCount(keyword);
      const int axis = keyword[1] - 'X';
      std::vector<double>& target = axis == 0 ? this->Deck.dxv : (axis == 1 ? this->Deck.dyv : this->Deck.dzv);
      this->ReadDenseArray(keyword, target, this->Deck.dims[axis]);
    }
    else if (keyword == "MAPAXES")
    {
      std::vector<double> values;
      this->ReadNumbers(keyword, 6, false, false, [&](int64_t, double v) { values.push_back(v); });
      this->SetMapAxes(values);
    }
    else if (keyword == "MAPUNITS" || keyword == "GRIDUNIT")
    {
      this->SetUnits(keyword, this->ReadRecord(keyword));
    }
    else if (keyword == "GDORIENT")
    {
      this->Deck.gdorient = this->ReadRecord(keyword);
    }
    else if (keyword == "COORDSYS")
    {
      const auto items = this->ReadRecord(keyword);
      const int64_t k1 = this->RecordInteger(items, 0, keyword, "K1", 1, true);
      const int64_t k2 = this->RecordInteger(items, 1, keyword, "K2", 1, true);
      if (k1 < 1 || k2 < k1 || (this->Deck.dims[2] > 0 && k2 > this->Deck.dims[2]))
      {
        this->FailHere(keyword, "layer range " + std::to_string(k1) + "-" + std::to_string(k2) + " is not valid");
      }
      this->Deck.coordsysLayers.push_back({ static_cast<int32_t>(k1), static_cast<int32_t>(k2) });
    }
    else if (keyword == "INCLUDE")
    {
      this->ReadInclude(keyword, depth);
    }
    else if (keyword == "IMPORT")
    {
      this->ReadInclude(keyword, depth); // IMPORT names a binary GRDECL; ParseAnyFile detects it
    }
    else if (keyword == "FAULTS")
    {
      this->ReadFaults();
    }
    else if (IsEditKeyword(keyword))
    {
      this->CellCount(keyword);
      this->ReadArrayOperations(keyword);
    }
    else if (keyword == "BOX")
    {
      this->CellCount(keyword);
      const auto items = this->ReadRecord(keyword);
      this->CurrentBox = this->RecordBox(items, 0, this->WholeGrid(), keyword);
    }
    else if (keyword == "ENDBOX")
    {
      this->CurrentBox.reset();
    }
    else if (keyword == "TITLE")
    {
      tokens.SkipRestOfLine();
      const Token& next = tokens.Next(); // the title line itself, whatever it holds
      if (next.kind != TokenKind::End)
      {
        tokens.SkipRestOfLine();
      }
    }
    else if (this->EnterSection(keyword))
    {
    }
    else if (this->CurrentSection == Section::Schedule)
    {
      this->SkipRestOfKeyword();
    }
    else if (this->InPropertySection() && SkippedKeyword(keyword, why) != SkippedShape::None)
    {
      this->SkipUnusedKeyword(keyword, SkippedKeyword(keyword, why), why);
    }
    else if (IsKnownCellArray(keyword) && this->InPropertySection())
    {
      this->CellCount(keyword);
      this->ReadCellArray(keyword, false);
    }
    else if (this->InPropertySection() && this->Deck.dims[0] != 0)
    {
      this->ReadCellArray(keyword, true);
    }
    else
    {
      this->SkipRestOfKeyword();
    }
  }

  // ---------------------------------------------------------------- binary GRDECL
  void ParseBinaryFile(const std::string& path)
  {
    const EclipseKeywordFile reader(path);
    std::vector<double> values;
    const std::string savedFile = this->CurrentFile;
    this->CurrentFile = path;
    this->CurrentLine = 0;
    for (const EclipseRecord& header : reader.Records())
    {
      const std::string& keyword = header.name;
      const auto fail = [&](const std::string& what) {
        throw InputError(
          path, 0, keyword, what + " (keyword header at byte " + std::to_string(header.headerOffset) + ")");
      };
      if (!header.IsNumeric())
      {
        if (keyword == "GRIDUNIT" || keyword == "MAPUNITS")
        {
          this->SetUnits(keyword, reader.ReadStrings(header));
        }
        continue;
      }
      if (keyword == "SPECGRID" || keyword == "DIMENS")
      {
        reader.ReadNumbers(header, values);
        if (values.size() < 3)
        {
          fail("needs at least 3 values");
        }
        std::array<int64_t, 3> dims{};
        for (int axis = 0; axis < 3; ++axis)
        {
          // INTE data arrive as doubles; anything else (REAL NaN, 1e30 ...) is rejected here.
          if (!(std::fabs(values[axis]) <= 4e9) || values[axis] != std::floor(values[axis]))
          {
            fail("dimension " + std::to_string(axis + 1) + " is not an integer");
          }
          dims[axis] = static_cast<int64_t>(values[axis]);
        }
        CheckedCellCount(dims, this->Options.maxCells, path, 0, keyword);
        this->CurrentLine = 0;
        this->SetDimensions(dims, keyword);
        continue;
      }
      if (keyword == "MAPAXES")
      {
        reader.ReadNumbers(header, values);
        if (values.size() != 6)
        {
          fail("needs 6 values");
        }
        this->SetMapAxes(values);
        continue;
      }
      if (this->Deck.dims[0] == 0)
      {
        continue;
      }
      const auto& d = this->Deck.dims;
      const int64_t n = this->Deck.CellCount();
      int64_t expected = -1;
      std::vector<double>* target = nullptr;
      if (keyword == "COORD")
      {
        expected = 6 * (d[0] + 1) * (d[1] + 1);
        target = &this->Deck.coord;
      }
      else if (keyword == "ZCORN")
      {
        expected = 8 * n;
        target = &this->Deck.zcorn;
      }
      if (target)
      {
        if (header.count != expected)
        {
          fail("expected " + std::to_string(expected) + " values, file has " + std::to_string(header.count));
        }
        if (keyword == "ZCORN" && this->Spooling())
        {
          std::unique_ptr<SpoolFile> file(new SpoolFile(this->SpoolFolder, keyword));
          this->SpoolRecord<float>(reader, header, *file, [&](const double* v, int64_t count, float* out) {
            for (int64_t i = 0; i < count; ++i)
            {
              if (!std::isfinite(v[i]))
              {
                fail("holds a value that is not finite");
              }
              out[i] = static_cast<float>(v[i]);
            }
          });
          this->Spool->zcorn = std::move(file);
          continue;
        }
        reader.ReadNumbers(header, *target);
        for (double v : *target)
        {
          if (!std::isfinite(v))
          {
            fail("holds a value that is not finite");
          }
        }
        continue;
      }
      if (header.count != n)
      {
        if (IsKnownCellArray(keyword))
        {
          fail("expected " + std::to_string(n) + " values (one per cell), file has " + std::to_string(header.count));
        }
        continue;
      }
      if (this->Spooling())
      {
        if (!this->Spooled(keyword))
        {
          this->DroppedArrays.insert(keyword);
          continue;
        }
        std::unique_ptr<SpoolFile> file(new SpoolFile(this->SpoolFolder, keyword));
        this->SpoolRecord<double>(
          reader, header, *file, [](const double* v, int64_t count, double* out) { std::copy(v, v + count, out); });
        this->SpoolSlot(keyword) = std::move(file); // replaces any earlier values, as below
        continue;
      }
      reader.ReadNumbers(header, values);
      CellArray& array = this->ArrayFor(keyword);
      array.isInteger = header.type == EclipseDataType::Integer || IsIntegerArrayName(keyword);
      array.values.swap(values);
    }
    this->CurrentFile = savedFile;
  }

  /// Copies a binary record into a spool file piece by piece: convert(values as doubles,
  /// count, out) fills the spool's values (checking them).
  template<typename T, typename Convert>
  void SpoolRecord(const EclipseKeywordFile& reader, const EclipseRecord& header, SpoolFile& file, Convert&& convert)
  {
    constexpr int64_t Piece = 1 << 16;
    std::vector<double> values(static_cast<std::size_t>(std::min<int64_t>(Piece, header.count)));
    std::vector<T> converted(values.size());
    EclipseRecordCursor cursor(reader, header);
    for (int64_t first = 0; first < header.count; first += Piece)
    {
      const int64_t count = std::min(Piece, header.count - first);
      cursor.Read(count, values.data());
      convert(values.data(), count, converted.data());
      file.Write(first, converted.data(), count);
    }
  }

  // ---------------------------------------------------------------- final checks
  void Finish()
  {
    CornerPointModel& deck = this->Deck;
    const std::string& file = deck.files.front();
    if (deck.dims[0] == 0)
    {
      throw InputError(
        file, 0, "SPECGRID", "no SPECGRID or DIMENS: grid dimensions unknown" + this->MissingIncludeNote());
    }
    const bool hasZcorn = this->Spooling() ? this->Spool->zcorn != nullptr : !deck.zcorn.empty();
    if (deck.coord.empty() == hasZcorn)
    {
      throw InputError(file, 0, deck.coord.empty() ? "COORD" : "ZCORN",
        "missing; corner-point grids need both COORD and ZCORN" + this->MissingIncludeNote());
    }
    const auto given = [&](const std::string& name, const std::vector<double>& vector) {
      return !vector.empty() || this->Defined(name);
    };
    const bool cartesian = given("DX", deck.dxv) && given("DY", deck.dyv) && given("DZ", deck.dzv) && given("TOPS", {});
    if (!hasZcorn && !cartesian && !this->MissingIncludes.empty())
    {
      throw InputError(file, 0, "COORD",
        "no grid geometry: need COORD and ZCORN, or DX/DXV, DY/DYV, DZ/DZV and TOPS" + this->MissingIncludeNote());
    }
    if (this->Spooling() && this->Spool->actnum)
    {
      // As below, a piece at a time.
      SpoolFile& actnum = *this->Spool->actnum;
      const int64_t n = deck.CellCount();
      std::vector<double> values;
      for (int64_t first = 0; first < n; first += 1 << 16)
      {
        const int64_t count = std::min<int64_t>(1 << 16, n - first);
        values.resize(static_cast<std::size_t>(count));
        actnum.Read(first, values.data(), count);
        for (double& value : values)
        {
          if (std::isnan(value))
          {
            value = 1;
          }
          else if (value != std::floor(value) || value < 0)
          {
            throw InputError(file, 0, "ACTNUM", "values must be non-negative integers");
          }
        }
        actnum.Write(first, values.data(), count);
      }
    }
    if (CellArray* actnum = deck.FindArray("ACTNUM"))
    {
      for (double& value : actnum->values)
      {
        if (std::isnan(value))
        {
          value = 1; // cells outside an ACTNUM box stay active
        }
        else if (value != std::floor(value) || value < 0)
        {
          throw InputError(file, 0, "ACTNUM", "values must be non-negative integers");
        }
      }
    }
  }

  GrdeclParseOptions Options;
  CornerPointModel Deck;
  GrdeclTokenizer* Tokens = nullptr;
  std::string RootDirectory;
  std::string CurrentFile;
  int64_t CurrentLine = 0;
  Section CurrentSection = Section::None;
  bool Stopped = false;
  std::optional<Box> CurrentBox;
  std::unordered_map<std::string, std::size_t> FaultIndex;
  GrdeclGridSpool* Spool = nullptr; ///< bounded-memory mode when set
  std::string SpoolFolder;
  std::unordered_set<std::string> DroppedArrays; ///< bounded-memory mode: given, not kept
  int64_t LastRecordLine = 0;                    ///< line of the first token of the last record read
  int64_t RecordLine = 0;                        ///< line a warning names
  std::unordered_set<std::string> WarningsGiven;
  std::vector<std::string> MissingIncludes; ///< "'name' (file:line)" of each INCLUDE not found
};
} // namespace

bool LooksLikeGrdeclFile(const std::string& path)
{
  if (EclipseKeywordFile::LooksLikeUnformatted(path))
  {
    return true;
  }
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file)
  {
    return false;
  }
  std::string head(1 << 16, '\0');
  head.resize(std::fread(&head[0], 1, head.size(), file));
  std::fclose(file);
  // Any ECLIPSE keyword name alone at the start of a line, within the first 64 KiB.
  std::size_t start = 0;
  while (start < head.size())
  {
    std::size_t end = head.find('\n', start);
    if (end == std::string::npos)
    {
      end = head.size();
    }
    std::string_view line(head.data() + start, end - start);
    const std::size_t word = line.find_first_of(" \t\r/");
    if (LooksLikeKeyword(line.substr(0, word)))
    {
      return true;
    }
    start = end + 1;
  }
  return false;
}

CornerPointModel ParseGrdeclFile(const std::string& path, const GrdeclParseOptions& options)
{
  Parser parser(options);
  return parser.Run(path);
}

SpoolFile* GrdeclGridSpool::Find(const std::string& name) const
{
  return name == "ACTNUM" ? this->actnum.get()
    : name == "DX"        ? this->dx.get()
    : name == "DY"        ? this->dy.get()
    : name == "DZ"        ? this->dz.get()
    : name == "TOPS"      ? this->tops.get()
                          : nullptr;
}

CornerPointModel ParseGrdeclGrid(
  const std::string& path, const std::string& spoolFolder, GrdeclGridSpool& spool, GrdeclParseOptions options)
{
  if (options.maxCells <= 0)
  {
    options.maxCells = std::numeric_limits<int64_t>::max(); // nothing cell-sized is held
  }
  spool = GrdeclGridSpool();
  Parser parser(options);
  parser.SpoolTo(spoolFolder, spool);
  return parser.Run(path);
}

} // namespace resmr
