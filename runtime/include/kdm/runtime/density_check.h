// A debugging aid for density callbacks. A query counts a callback's NaN, infinite and negative values as
// 0 and treats values above callback_max as the bound (QueryDensity): a bug in a density function or its
// bound then shows only as too few points somewhere. A DensityCheck wraps a callback density so that the
// first such value is recorded, with where it was read, for the caller to report after the query.
#pragma once

#include <atomic>
#include <cmath>
#include <cstddef>

#include "kdm/runtime/export.h"
#include "kdm/runtime/query.h"

namespace kdm {

/// True if `value` is a density a callback bounded by `max` may return: finite, >= 0 and at most `max`
/// (within 10^-9 of it, as a bound computed another way may differ by rounding).
inline bool density_value_fits(double value, double max) {
  return value >= 0 && value <= max * (1 + 1e-9) && value < HUGE_VAL;
}

/// What a DensityCheck found: the first value that did not fit, where it was read and the bound it broke.
struct DensityFinding {
  double value = 0;     ///< the value returned (NaN, infinite, negative or above `limit`)
  double x = 0, y = 0;  ///< the world position it was read at
  double limit = 0;     ///< the wrapped density's callback_max
};

/// Records the first value a wrapped callback density returns that does not fit (density_value_fits).
/// Checking costs a comparison per value and one more indirect call per read; the points are those of the
/// unwrapped density wherever the values fit. Thread-safe: parallel and concurrent queries may share one
/// check. It must outlive every query using a density it wrapped, at the same address (not copyable).
class KDM_RUNTIME_API DensityCheck {
 public:
  DensityCheck() = default;
  DensityCheck(const DensityCheck&) = delete;
  DensityCheck& operator=(const DensityCheck&) = delete;

  /// `density` with its callback, batch callback and bounds routed through this check (which keeps a copy
  /// of it): use the result in QueryParams::density or a class query's classes[k]. A density that is not
  /// a callback (a constant, an image) is returned unchanged. Wrapping again replaces what was wrapped;
  /// one check per density.
  QueryDensity wrap(const QueryDensity& density);

  /// True once a value that does not fit has been read; `*finding` (optional) receives the first.
  bool failed(DensityFinding* finding = nullptr) const;

  /// The finding in one line ("density callback returned nan at (2.5, 7)", "... returned 3 at (1, 1),
  /// above its bound callback_max 2"), or "no bad density value". Writes at most `size` bytes, NUL
  /// included, into `text` and returns the whole line's length, as snprintf does. Allocates nothing.
  std::size_t describe(char* text, std::size_t size) const;

  /// Forgets the finding (not while a query using this check runs).
  void reset();

 private:
  static double call(void* user, double x, double y);
  static void call_batch(void* user, std::size_t n, const double* x, const double* y, double* out);
  static void call_bounds(void* user, double x0, double y0, double x1, double y1, double* lo, double* hi);
  void check(double value, double x, double y);

  QueryDensity inner_;
  std::atomic<int> state_{0};  // 0: nothing found; 1: a finding being written; 2: written
  DensityFinding finding_;
};

}  // namespace kdm
