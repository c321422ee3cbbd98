// Internal: the count a point glides by in smooth mode with a varying density, one rule for emit_tile.h
// and descent.cpp.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace kdm::detail {

/// Where a point's glide count reads the density besides its stable position (x, y): the corners of its
/// cells in two world-aligned square lattices, of sides h = 2^L ≤ √2 · its mean spacing < 2h and 2h.
/// Corners 0–3 are the finer lattice's, 4–7 the coarser one's; `coarse` is the coarser one's weight.
struct GlideLattice {
  static constexpr int kCorners = 8;
  double fine_x, fine_y, h, coarse_x, coarse_y, coarse;  // the cells' lower corners, the fine side
  /// A point of expected count `expected` in a tile of side `side`.
  [[gnu::always_inline]] GlideLattice(double expected, double x, double y, double side) {
    // √2 · its spacing = 2^L · m, m in [1, 2): L and the coarser lattice's weight m − 1 (a piecewise linear
    // log₂, continuous and increasing) straight from the bits, without a library call.
    const double u = side * std::sqrt(2.0 / std::max(expected, 1.0));
    std::uint64_t bits;
    std::memcpy(&bits, &u, sizeof bits);
    // L within a normal double's exponents (a spacing never nears either end; this keeps the bits valid).
    const std::uint64_t biased = (bits >> 52) & 0x7ff;  // selects, not branches: glide_runs.cpp vectorises
    const std::uint64_t exponent = biased < 1 ? 1 : biased > 2045 ? 2045 : biased;
    const std::uint64_t one = (bits & ~(std::uint64_t(0x7ff) << 52)) | (std::uint64_t(1023) << 52);
    double m;
    std::memcpy(&m, &one, sizeof m);
    coarse = m - 1;
    h = power_of_two(static_cast<int>(exponent) - 1023);
    const double inverse = power_of_two(1023 - static_cast<int>(exponent));
    const double ix = floor(x * inverse), iy = floor(y * inverse);
    fine_x = ix * h, fine_y = iy * h;
    coarse_x = floor(ix * 0.5) * (2 * h), coarse_y = floor(iy * 0.5) * (2 * h);
  }
  [[gnu::always_inline]] static double power_of_two(int e) {  // 2^e, -1022 <= e <= 1023
    const std::uint64_t bits = std::uint64_t(e + 1023) << 52;
    double v;
    std::memcpy(&v, &bits, sizeof v);
    return v;
  }
  /// std::floor (but +0 for −0), which is a library call without SSE4.1; without branches or integer
  /// conversions, so that loops over many points vectorise (glide_runs.cpp). Below 2^52, adding and taking
  /// away 2^52 (of v's sign) rounds v to an integer exactly; 2^52 and above (and NaN) are whole already.
  [[gnu::always_inline]] static double floor(double v) {
    const double big = std::copysign(4503599627370496.0, v), r = (v + big) - big;
    const double below = r > v ? r - 1 : r;
    return std::fabs(v) < 4503599627370496.0 ? below : v;
  }
  void corner(int k, double& x, double& y) const {
    const double s = k < 4 ? h : 2 * h;
    x = (k < 4 ? fine_x : coarse_x) + (k & 1) * s, y = (k < 4 ? fine_y : coarse_y) + ((k >> 1) & 1) * s;
  }
  /// The glide count from the most density at the fine corners and at the coarse ones; `area` is the count
  /// per unit of density.
  double count(double expected, double fine_max, double coarse_max, double area) const {
    return std::max(expected, ((1 - coarse) * fine_max + coarse * coarse_max) * area);
  }
};

/// The expected count a point at stable position (x, y) glides by: the most of its own (`expected`, in a
/// tile of side `side`) and, blended between the two lattices by where its spacing lies between their
/// sides, the most density at its cell's corners in each (`read(x, y)`; `area`: the count per unit of
/// density). Where the density changes from one dot to the next, the neighbours that make room for a
/// point then do not lag the count at which it appears; gliding by their own counts they would, and close
/// up on it. The corners stay put as the scale changes and the blend moves with it, so a point glides
/// continuously even across a step of the density. Whether a point is emitted still follows its own count.
template <class Read>
inline double glide_count(double expected, double x, double y, double side, double area, Read&& read) {
  const GlideLattice c(expected, x, y, side);
  const double h = c.h, H = 2 * h;
  const double fine = std::max(std::max(read(c.fine_x, c.fine_y), read(c.fine_x + h, c.fine_y)),
                               std::max(read(c.fine_x, c.fine_y + h), read(c.fine_x + h, c.fine_y + h)));
  const double coarse =
      std::max(std::max(read(c.coarse_x, c.coarse_y), read(c.coarse_x + H, c.coarse_y)),
               std::max(read(c.coarse_x, c.coarse_y + H), read(c.coarse_x + H, c.coarse_y + H)));
  return c.count(expected, fine, coarse, area);
}

}  // namespace kdm::detail
