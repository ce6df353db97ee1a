// Error type for every Eclipse input path (paper Sec. 3: model input). Messages always name
// the file, the line (or byte offset for binary files) and the keyword, so users can fix
// their deck.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace resmr
{

class GrdeclError : public std::runtime_error
{
public:
  GrdeclError(const std::string& file, int64_t line, const std::string& keyword,
    const std::string& what)
    : std::runtime_error(Format(file, line, keyword, what))
  {
  }

  static std::string Format(const std::string& file, int64_t line, const std::string& keyword,
    const std::string& what)
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

} // namespace resmr
