// Streaming tokenizer for Eclipse ASCII decks (GRDECL / DATA / INCLUDE files).
// Paper Sec. 3: the black oil model arrives as an (ni x nj x nk) corner-point deck; this
// is the first stage that turns its text into values without holding the text in memory.
//
// Contract:
// - Reads the file in fixed-size chunks; memory use is independent of the file size.
// - Recognises `--` comments, quoted strings, `/` record terminators (the rest of the line
//   after a `/` is a comment, as in ECLIPSE), `N*value` repeats and `N*` defaults.
// - Every token carries its 1-based line number for error messages.
// - Never throws on content; malformed numbers are reported by the caller, which knows the
//   keyword. Throws InputError only when the file cannot be opened or read.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace resmr
{

enum class TokenKind
{
  End,    ///< end of file
  Word,   ///< bare word: keyword, number, T/F, `N*value` ...
  String, ///< quoted string, quotes removed
  Slash,  ///< record terminator `/`
};

struct Token
{
  TokenKind kind = TokenKind::End;
  std::string_view text;    ///< valid until the next call to Next()
  int64_t line = 0;         ///< 1-based line of the token's first character
  bool atLineStart = false; ///< token starts in column 1 (ECLIPSE keywords must)
};

/// A parsed number token: `value`, `N*value` or `N*` (default).
struct NumberToken
{
  double value = 0.0;
  int64_t repeat = 1;
  bool isDefault = false; ///< `N*` with no value
};

/// Parses a bare word as a number or a repeat. Accepts Fortran `D` exponents.
/// Returns false if the word is not a number.
bool ParseNumberToken(std::string_view word, NumberToken& out);

/// Parses a plain decimal or floating point number (no repeat). Returns false on failure.
bool ParseDouble(std::string_view word, double& out);

class GrdeclTokenizer
{
public:
  explicit GrdeclTokenizer(const std::string& path, std::size_t chunkSize = 1 << 22);
  ~GrdeclTokenizer();
  GrdeclTokenizer(const GrdeclTokenizer&) = delete;
  GrdeclTokenizer& operator=(const GrdeclTokenizer&) = delete;

  /// Returns the next token; kind End at end of file.
  const Token& Next();

  /// The last token again on the next call to Next().
  void PushBack() { this->PushedBack = true; }

  /// Skips the rest of the current line (used after keyword names: ECLIPSE ignores it).
  void SkipRestOfLine();

  const std::string& GetPath() const { return this->Path; }
  int64_t GetLine() const { return this->Line; }
  /// Bytes consumed so far (for throughput reports).
  uint64_t GetBytesRead() const { return this->BytesRead; }

private:
  bool Refill(std::size_t keepFrom);
  bool EnsureAvailable(std::size_t& pos);

  std::string Path;
  std::FILE* File = nullptr;
  std::vector<char> Buffer;
  std::size_t ChunkSize;
  std::size_t Begin = 0; ///< next unread byte in Buffer
  std::size_t EndOfData = 0;
  bool Eof = false;
  int64_t Line = 1;
  bool LineStart = true;
  uint64_t BytesRead = 0;
  Token Current;
  bool PushedBack = false;
};

} // namespace resmr
