// Minimal assertion support shared by the Core unit tests: CHECK counts failures and
// reports file and line; main returns non-zero when any failed.
#pragma once

#include <cstdio>
#include <exception>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace resmr_testing
{
inline int Failures = 0;
}

#define CHECK(condition)                                                                                               \
  do                                                                                                                   \
  {                                                                                                                    \
    if (!(condition))                                                                                                  \
    {                                                                                                                  \
      std::fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #condition);                               \
      ++resmr_testing::Failures;                                                                                       \
    }                                                                                                                  \
  } while (0)

namespace resmr_testing
{
/// Runs `action`, which must throw `Error` with every fragment in its message.
template<typename Error>
void ExpectError(
  const std::string& label, const std::function<void()>& action, const std::vector<std::string>& fragments)
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

/// Runs each named test, counting an exception it lets out as a failure, and prints one line
/// a test; true when nothing failed.
inline bool RunNamedTests(const std::vector<std::pair<const char*, std::function<void()>>>& tests)
{
  for (const auto& test : tests)
  {
    const int before = Failures;
    try
    {
      test.second();
    }
    catch (const std::exception& error)
    {
      std::fprintf(stderr, "%s: unexpected exception: %s\n", test.first, error.what());
      ++Failures;
    }
    std::printf("%-24s %s\n", test.first, Failures == before ? "ok" : "FAILED");
  }
  return Failures == 0;
}
} // namespace resmr_testing
