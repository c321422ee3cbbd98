// A debugging aid for density callbacks. A query counts a callback's NaN, infinite and negative values as
// 0, treats values above callback_max as the bound, and trusts its bounds (QueryDensity): a bug in a
// density function, its bound or its bounds then shows only as too few or too many points somewhere. A
// DensityCheck routes a callback density through itself and records the first value that does not fit,
// or bounds that the density breaks, with where, for the caller to report after the query.
#pragma once

#include <atomic>
#include <cmath>
#include <cstddef>

#include "kdm/runtime/class_query.h"
#include "kdm/runtime/export.h"
#include "kdm/runtime/query.h"
#include "kdm/runtime/status.h"

namespace kdm {

/// True if `value` is a density a callback bounded by `max` may return: finite, >= 0 and at most `max`
/// (within 10^-9 of it, as a bound computed another way may differ by rounding).
inline bool density_value_fits(double value, double max) {
  return value >= 0 && value <= max * (1 + 1e-9) && value < HUGE_VAL;
}

/// What a DensityCheck found first.
struct DensityFinding {
  enum class Kind : int {
    kValue,   ///< the callback returned `value` at (x, y): NaN, infinite, negative or above `limit`
    kBounds,  ///< the bounds gave [lo, hi] over `rect`, but the density is `value` at (x, y) in it
  };
  Kind kind = Kind::kValue;
  double value = 0;
  double x = 0, y = 0;            ///< the world position the value was read at
  double limit = 0;               ///< the wrapped density's callback_max (a joint density's max[cls])
  int cls = -1;                   ///< a joint density's class the value or bounds are of; -1 for one density
  double lo = 0, hi = 0;          ///< kBounds: the bounds given
  double rect[4] = {0, 0, 0, 0};  ///< kBounds: x0, y0, x1, y1 they were asked for
};

/// Records the first value a wrapped callback density returns that does not fit (density_value_fits),
/// and bounds the density breaks: each bounds call is checked against the density at 9 points of its
/// rectangle (corners, edge middles and centre), so bounds wrong over a large part of it are found. It
/// costs a comparison and one more call per value read, and 9 reads per bounds call; the points are those
/// of the unwrapped density. Thread-safe: parallel and concurrent queries may share one check. It must
/// outlive every query using a density it wrapped, at the same address (not copyable).
class KDM_RUNTIME_API DensityCheck {
 public:
  DensityCheck() = default;
  DensityCheck(const DensityCheck&) = delete;
  DensityCheck& operator=(const DensityCheck&) = delete;

  /// Routes `*density`'s callback, batch callback and bounds through this check, which keeps a copy of
  /// the density as it is now: wrap it last, once its functions, user and callback_max are final (a user
  /// pointer set afterwards reaches the check's functions in place of the check). Wrapping the same
  /// density again (a new QueryParams per chunk with the same functions and user, or the wrapped one
  /// itself) takes its callback_max. kOk, also for a density that is not a callback (left as it is);
  /// kInvalidArgument for a null `density`, or another density than the one this check wraps: one check
  /// per density (a class query's classes each need their own), until reset().
  Status wrap(QueryDensity* density);

  /// The same for a class query's joint density (ClassQueryParams::joint) of `class_count` classes: its
  /// densities, batch densities and bounds, each class's values against its max[k], its bounds at the 9
  /// points too. kInvalidArgument for a null `joint`, a class_count outside 1 … kMaxQueryClasses, or
  /// another density than the one this check wraps.
  Status wrap(JointClassDensity* joint, std::uint32_t class_count);

  /// True once the check found something; `*finding` (optional) receives the first finding.
  bool failed(DensityFinding* finding = nullptr) const;

  /// The largest finite value read so far, of any class (-1 before any): far under callback_max, a tighter
  /// bound lets queries skip more candidates (a bound of 50 for values up to 1 has them read up to 50 times
  /// as many).
  double largest() const { return largest_.load(std::memory_order_relaxed); }

  /// The finding in one line ("density callback returned nan at (2.5, 7)", "joint density's class 1 was
  /// nan at (2.5, 7)", "... returned 3 at (1, 1),
  /// above its bound callback_max 2", "density bounds gave [0.3, 0.9] over (0, 0) to (8, 8), but the
  /// density is 0.05 at (4, 8)"), or "no bad density value", followed where the largest value read is
  /// under half the bound by "; the largest value read, 0.9, is under half of callback_max 50: a tighter
  /// bound makes queries faster". Writes at most `size` bytes, NUL included,
  /// into `text` and returns the whole line's length, as snprintf does. Allocates nothing.
  std::size_t describe(char* text, std::size_t size) const;

  /// Forgets the finding and the density wrapped, so that the check can wrap another (densities wrapped
  /// before must no longer be queried). Not while a query using the check runs.
  void reset();

 private:
  static double call(void* user, double x, double y);
  static void call_batch(void* user, std::size_t n, const double* x, const double* y, double* out);
  static void call_bounds(void* user, double x0, double y0, double x1, double y1, double* lo, double* hi);
  static void call_joint(void* user, double x, double y, double* values);
  static void call_joint_batch(void* user, std::size_t n, const double* x, const double* y, double* values);
  static void call_joint_bounds(void* user, double x0, double y0, double x1, double y1, double* lo,
                                double* hi);
  bool routes(const QueryDensity& density) const;
  void record(const DensityFinding& finding);
  void check(double value, double x, double y, double limit, int cls = -1);
  /// Records bounds [lo, hi] over the rectangle r that `value` at (x, y) in it breaks; false if it fits.
  bool check_bounds(double value, double x, double y, double lo, double hi, const double (&r)[4],
                    double limit, int cls);

  QueryDensity inner_;
  JointClassDensity inner_joint_;
  std::uint32_t classes_ = 0;  // a joint density's class count; 0 for one density
  bool wrapping_ = false;
  std::atomic<int> state_{0};  // 0: nothing found; 1: a finding being written; 2: written
  std::atomic<double> largest_{-1};
  DensityFinding finding_;
};

}  // namespace kdm
