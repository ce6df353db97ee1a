// Minimal assertion support shared by the Core unit tests: CHECK counts failures and
// reports file and line; main returns non-zero when any failed.
#pragma once

#include <cstdio>
#include <functional>
#include <string>
#include <vector>

namespace resmr_testing
{
inline int Failures = 0;
}

#define CHECK(condition)                                                                         \
  do                                                                                             \
  {                                                                                              \
    if (!(condition))                                                                            \
    {                                                                                            \
      std::fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #condition);        \
      ++resmr_testing::Failures;                                                                 \
    }                                                                                            \
  } while (0)

namespace resmr_testing
{
/// Runs `action`, which must throw `Error` with every fragment in its message.
template <typename Error>
void ExpectError(const std::string& label, const std::function<void()>& action,
  const std::vector<std::string>& fragments)
{
  try
  {
    action();
    std::fprintf(stderr, "%s: expected an error, none thrown\n", label.c_str());
    ++Failures;
  }
  catch (const Error& error)
  {
    for (const std::string& fragment : fragments)
    {
      if (std::string(error.what()).find(fragment) == std::string::npos)
      {
        std::fprintf(stderr, "%s: message lacks '%s': %s\n", label.c_str(), fragment.c_str(), error.what());
        ++Failures;
      }
    }
  }
}
} // namespace resmr_testing
