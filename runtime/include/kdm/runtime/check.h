// KDM_CHECK(condition): an internal precondition or invariant, as pbrt-v4's CHECK. A failure is a bug in
// kdm, never bad input (bad input gets a Status or an error naming the problem): it prints the condition
// and where it failed, then aborts. Checked in debug builds (NDEBUG not defined) and wherever
// KDM_ENABLE_CHECKS is defined (the sanitizer builds in CI); compiled out otherwise, so hot paths pay
// nothing.
#pragma once

#include <cstdio>
#include <cstdlib>

namespace kdm::detail {

[[noreturn]] inline void check_failed(const char* condition, const char* file, int line) {
  std::fprintf(stderr, "kdm: internal check failed: %s (%s:%d)\n", condition, file, line);
  std::abort();
}

}  // namespace kdm::detail

#if !defined(NDEBUG) || defined(KDM_ENABLE_CHECKS)
#define KDM_CHECK(condition) \
  ((condition) ? static_cast<void>(0) : ::kdm::detail::check_failed(#condition, __FILE__, __LINE__))
#else
// Not evaluated, but still compiled: a check cannot rot in release builds.
#define KDM_CHECK(condition) static_cast<void>(sizeof(static_cast<bool>(condition)))
#endif
