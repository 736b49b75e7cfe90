#pragma once
/// \file
/// CALIBER_ASSERT(condition, "what must hold"): the invariants that the code relies on and a test
/// cannot see from outside (node-test conservation, stack bounds, sorted output). On in Debug and
/// sanitizer builds (CMake defines CALIBER_ASSERTIONS there), compiled out in Release: a failure
/// prints the file, line and statement to stderr and aborts, so that a test or fuzzer run stops at
/// the first broken invariant instead of at a wrong answer further on.

#ifdef CALIBER_ASSERTIONS
#include <cstdio>
#include <cstdlib>

namespace caliber::util {
[[noreturn]] inline void assertion_failed(const char* condition, const char* what, const char* file, int line) {
  std::fprintf(stderr, "%s:%d: caliber internal assertion failed: %s (%s)\n", file, line, what, condition);
  std::abort();
}
}  // namespace caliber::util

#define CALIBER_ASSERT(condition, what) \
  ((condition) ? static_cast<void>(0) : ::caliber::util::assertion_failed(#condition, what, __FILE__, __LINE__))
#else
#define CALIBER_ASSERT(condition, what) static_cast<void>(0)
#endif
