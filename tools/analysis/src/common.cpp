// Reference spacings (docs/design.md §6: d_hex = sqrt(2/(sqrt(3) n)) on the unit square; FCC
// nearest-neighbour spacing (sqrt(2)/n)^(1/3) on the unit cube) and input validation shared by every metric.
#include "kdm/analysis/common.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace kdm::analysis {

double hex_spacing(std::size_t n) {
  if (n == 0) return std::numeric_limits<double>::infinity();
  return std::sqrt(2.0 / (std::sqrt(3.0) * static_cast<double>(n)));
}

double fcc_spacing(std::size_t n) {
  if (n == 0) return std::numeric_limits<double>::infinity();
  return std::cbrt(std::sqrt(2.0) / static_cast<double>(n));
}

double reference_spacing(int dim, std::size_t n) {
  if (dim == 2) return hex_spacing(n);
  if (dim == 3) return fcc_spacing(n);
  throw InvalidInput("dimension must be 2 or 3, got " + std::to_string(dim));
}

Sides unit_measure_sides(const double* extent, int dim) {
  if (dim != 2 && dim != 3) throw InvalidInput("dimension must be 2 or 3, got " + std::to_string(dim));
  double lo = HUGE_VAL, hi = 0, product = 1;
  for (int a = 0; a < dim; ++a) {
    if (!(extent[a] > 0) || !std::isfinite(extent[a]))
      throw InvalidInput("the domain's sides must be positive finite numbers, got " +
                         std::to_string(extent[a]) + " for " + "xyz"[a]);
    lo = std::min(lo, extent[a]), hi = std::max(hi, extent[a]), product *= extent[a];
  }
  // Past this a set of any size has under a spacing across the short side: nothing to measure there.
  if (hi > 1e4 * lo) throw InvalidInput("the domain's sides are more than 10^4 apart");
  Sides sides = kUnitSides;
  if (hi == lo) return sides;  // exactly the unit square (cube), whatever the common length
  const double scale = dim == 2 ? std::sqrt(product) : std::cbrt(product);
  for (int a = 0; a < dim; ++a) sides[a] = extent[a] / scale;
  return sides;
}

void validate_points(const std::vector<double>& coords, int dim) {
  if (dim != 2 && dim != 3) throw InvalidInput("dimension must be 2 or 3, got " + std::to_string(dim));
  if (coords.size() % static_cast<std::size_t>(dim) != 0)
    throw InvalidInput("coordinate count " + std::to_string(coords.size()) + " is not a multiple of " +
                       std::to_string(dim));
  for (std::size_t i = 0; i < coords.size(); ++i) {
    const double v = coords[i];
    if (!std::isfinite(v))
      throw InvalidInput("point " + std::to_string(i / dim) +
                         " (counting from 0) has a non-finite coordinate");
    if (v < 0.0 || v > 1.0) {
      // The shortest text that reads back as v: std::to_string prints 1e300 with 300 digits, %g
      // 1.0000001 as 1.
      char value[32];
      const std::to_chars_result end = std::to_chars(value, value + sizeof value, v);
      throw InvalidInput("point " + std::to_string(i / dim) +
                         " (counting from 0) lies outside the unit domain (coordinate " +
                         std::string(value, end.ptr) + "); normalise points to [0, 1]");
    }
  }
}

}  // namespace kdm::analysis
