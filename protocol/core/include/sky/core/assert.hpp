// SKY_ASSERT: checks an invariant of our own code (a bug if it fails), never
// outside input. Active when SKY_ENABLE_ASSERTS is set (every build of ours).
#pragma once

#include <cstdio>
#include <cstdlib>

#if defined(SKY_ENABLE_ASSERTS) && SKY_ENABLE_ASSERTS
#define SKY_ASSERT(cond)                                                     \
  do {                                                                       \
    if (!(cond)) {                                                           \
      std::fprintf(stderr, "%s:%d: assertion failed: %s\n", __FILE__,        \
                   __LINE__, #cond);                                         \
      std::abort();                                                          \
    }                                                                        \
  } while (0)
#else
#define SKY_ASSERT(cond) ((void)0)
#endif
