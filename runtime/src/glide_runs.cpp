// Glide counts for blocks of points; see glide_runs.h.
#include "glide_runs.h"

#include <algorithm>

#include "run_clones.h"

namespace kdm_runs {  // outside kdm: float_runs.h says why
using namespace kdm;
using namespace kdm::detail;

KDM_RUN_CLONES void glide_corners_run(const double* __restrict expected, const double* __restrict x,
                                      const double* __restrict y, std::size_t count, double side,
                                      double* __restrict cx, double* __restrict cy,
                                      double* __restrict coarse) {
  // The lattices, then their corners: as one loop the compiler did not vectorise it.
  double fx[kGlideBlock], fy[kGlideBlock], h[kGlideBlock], wx[kGlideBlock], wy[kGlideBlock];
  for (std::size_t k = 0; k < count; ++k) {
    const GlideLattice lattice(expected[k], x[k], y[k], side);
    fx[k] = lattice.fine_x, fy[k] = lattice.fine_y, h[k] = lattice.h;
    wx[k] = lattice.coarse_x, wy[k] = lattice.coarse_y, coarse[k] = lattice.coarse;
  }
  // GlideLattice::corner's positions, corner by corner.
  for (int c = 0; c < GlideLattice::kCorners; ++c) {
    const bool wide = c >= 4, right = c & 1, up = c & 2;
    double* __restrict to_x = cx + c * count;
    double* __restrict to_y = cy + c * count;
    for (std::size_t k = 0; k < count; ++k) {
      const double side_k = wide ? 2 * h[k] : h[k];
      to_x[k] = (wide ? wx[k] : fx[k]) + right * side_k, to_y[k] = (wide ? wy[k] : fy[k]) + up * side_k;
    }
  }
}

KDM_RUN_CLONES void glide_counts_run(const double* __restrict expected, const double* __restrict coarse,
                                     const double* __restrict value, std::size_t count, double area,
                                     double* __restrict out) {
  const double *v0 = value, *v1 = v0 + count, *v2 = v1 + count, *v3 = v2 + count, *v4 = v3 + count,
               *v5 = v4 + count, *v6 = v5 + count, *v7 = v6 + count;
  for (std::size_t k = 0; k < count; ++k) {
    // glide_count's expressions, in its order.
    const double fine = std::max(std::max(v0[k], v1[k]), std::max(v2[k], v3[k]));
    const double wide = std::max(std::max(v4[k], v5[k]), std::max(v6[k], v7[k]));
    out[k] = std::max(expected[k], ((1 - coarse[k]) * fine + coarse[k] * wide) * area);
  }
}

}  // namespace kdm_runs
