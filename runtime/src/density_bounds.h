// Internal: how queries read a density's values and bounds (query.h's QueryDensity), the one reading of
// each for every path (one-class, class, past the top level).
#pragma once

#include <algorithm>
#include <cmath>

#include "kdm/runtime/density_image.h"
#include "kdm/runtime/query.h"

namespace kdm::detail {

/// A density value as queries use it: NaN, ±∞ and negatives count as 0.
inline double density_or_zero(double v) {
  return (v > 0 && v < HUGE_VAL) ? v : 0.0;
}

/// A callback density's value at (x, y), through whichever of its two functions the caller set.
inline double callback_value(const QueryDensity& d, double x, double y) {
  if (d.callback) return density_or_zero(d.callback(d.user, x, y));
  double v;
  d.batch_callback(d.user, 1, &x, &y, &v);
  return density_or_zero(v);
}

/// A caller's bounds l ≤ ρ ≤ h of a density whose maximum is `max`, as queries use them: a pair that
/// contradicts itself (l > h, or either NaN) is no bounds at all; an upper bound that is not a number in
/// [0, max) is max, a lower one that is not positive is 0.
inline void trusted_bounds(double l, double h, double max, double& lo, double& hi) {
  if (!(l <= h)) l = 0, h = max;
  hi = h >= 0 && h < max ? h : max;
  lo = l > 0 ? std::min(l, hi) : 0;
}

/// Bounds of `d` over [x0, x1] × [y0, y1]: a constant's value, an image's min- and max-mip, a callback's own
/// bounds where it gives true numbers (else 0 and callback_max).
inline void density_bounds(const QueryDensity& d, double x0, double y0, double x1, double y1, double& lo,
                           double& hi) {
  switch (d.kind) {
    case QueryDensity::Kind::kConstant:
      lo = hi = density_or_zero(d.constant);
      return;
    case QueryDensity::Kind::kImage:
      lo = d.image->min_over(x0, y0, x1, y1), hi = d.image->max_over(x0, y0, x1, y1);
      return;
    case QueryDensity::Kind::kCallback:
      break;
  }
  double l = std::nan(""), h = std::nan("");
  if (d.bounds) d.bounds(d.user, x0, y0, x1, y1, &l, &h);
  trusted_bounds(l, h, d.callback_max, lo, hi);
}

}  // namespace kdm::detail
