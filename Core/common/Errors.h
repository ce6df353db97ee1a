// The two error types of this project. InputError: a user's model files (Eclipse decks, EGRID,
// INIT, restart files; paper Sec. 3), with messages naming the file, the line (or byte offset
// for binary files) and the keyword, so users can fix their deck. FileFormatError: this
// project's own binary files (.resmr, .resmrp, build scratch; Sec. 6.1) found damaged,
// truncated or foreign, with messages naming the file and the place.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace resmr
{

class InputError : public std::runtime_error
{
public:
  InputError(const std::string& file, int64_t line, const std::string& keyword, const std::string& what)
    : std::runtime_error(Format(file, line, keyword, what))
  {
  }

  static std::string Format(const std::string& file, int64_t line, const std::string& keyword, const std::string& what)
  {
    std::string message = file;
    if (line > 0)
    {
      message += ":" + std::to_string(line);
    }
    message += ": ";
    if (!keyword.empty())
    {
      message += "keyword " + keyword + ": ";
    }
    return message + what;
  }
};

class FileFormatError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

} // namespace resmr
