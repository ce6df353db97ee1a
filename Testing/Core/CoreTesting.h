// Minimal assertion support shared by the Core unit tests: CHECK counts failures and
// reports file and line; main returns non-zero when any failed.
#pragma once

#include <cstdio>

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
