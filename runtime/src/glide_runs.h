// Internal: glide_count.h's counts for a block of points at once (emit_tile.h, subtile_loops.h), in loops
// the compiler vectorises (run_clones.h), bit for bit as glide_count computes one point's.
#pragma once

#include <algorithm>
#include <cstddef>

#include "glide_count.h"

// Outside namespace kdm: GCC gives a target_clones function's ifunc default visibility whatever
// -fvisibility says, and the shared library's version script exports kdm::* (run_clones.h).
namespace kdm_runs {
using namespace kdm;
using namespace kdm::detail;

/// The corners of points k < count ≤ kGlideBlock (expected count expected[k] at stable position (x[k],
/// y[k]) in a tile of side `side`): corner c of point k (GlideLattice::corner) at (cx[c · count + k],
/// cy[c · count + k]), so that the 8 · count positions are contiguous; the coarser lattice's weight into
/// coarse[k].
void glide_corners_run(const double* expected, const double* x, const double* y, std::size_t count,
                       double side, double* cx, double* cy, double* coarse);

/// Their glide counts into out[k]: glide_count's, from the density at corner c of point k in
/// value[c · count + k], `area` the count per unit of density.
void glide_counts_run(const double* expected, const double* coarse, const double* value, std::size_t count,
                      double area, double* out);

}  // namespace kdm_runs

namespace kdm::detail {
using kdm_runs::glide_corners_run;
using kdm_runs::glide_counts_run;

/// Most points one block holds: their corners, 8 a point, fill one batch callback's call (kDensityBatch).
inline constexpr std::size_t kGlideBlock = 16;

/// The glide counts of points i < count (expected count expected[i] at stable position (x[i], y[i]) in a
/// tile of side `side`, `area` the count per unit of density) into out[i], a block at a time:
/// read(n, x, y, value) puts the density at n ≤ 8 · kGlideBlock positions into value (each ≥ 0, finite).
template <class Read>
void glide_counts(const double* expected, const double* x, const double* y, std::size_t count, double side,
                  double area, Read&& read, double* out) {
  constexpr std::size_t kReads = GlideLattice::kCorners * kGlideBlock;
  double cx[kReads], cy[kReads], value[kReads], coarse[kGlideBlock];
  for (std::size_t b = 0; b < count; b += kGlideBlock) {
    const std::size_t m = std::min(kGlideBlock, count - b);
    glide_corners_run(expected + b, x + b, y + b, m, side, cx, cy, coarse);
    read(GlideLattice::kCorners * m, cx, cy, value);
    glide_counts_run(expected + b, coarse, value, m, area, out + b);
  }
}

}  // namespace kdm::detail
