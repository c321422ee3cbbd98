// The compact output's runs of points; see float_runs.h.
#include "float_runs.h"

#include <algorithm>

// Clones for AVX-512 (x86-64-v4), AVX2 and the baseline, picked once by the loader (GCC on x86-64;
// elsewhere the baseline).
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define KDM_RUN_CLONES __attribute__((target_clones("arch=x86-64-v4", "avx2", "default")))
#else
#define KDM_RUN_CLONES
#endif

namespace kdm::detail {

KDM_RUN_CLONES void stable_run_xy(const TilePoint* from, std::size_t count, float rx, float ry, float unit,
                                  float* to) {
  for (std::size_t k = 0; k < count; ++k)
    to[2 * k] = rx + float(from[k].x) * unit, to[2 * k + 1] = ry + float(from[k].y) * unit;
}

KDM_RUN_CLONES void glided_run_xy(const TilePoint* from, const std::int8_t* o0, const std::int8_t* o1,
                                  std::size_t count, float rx, float ry, float unit, float w0, float w1,
                                  float* to) {
  for (std::size_t k = 0; k < count; ++k) {
    to[2 * k] = rx + float(from[k].x) * unit + (float(o0[2 * k]) * w0 + float(o1[2 * k]) * w1);
    to[2 * k + 1] = ry + float(from[k].y) * unit + (float(o0[2 * k + 1]) * w0 + float(o1[2 * k + 1]) * w1);
  }
}

KDM_RUN_CLONES void box_flags(const float* xy, std::size_t count, FloatBox sure, FloatBox may,
                              std::uint8_t* flags) {
  for (std::size_t k = 0; k < count; ++k) {
    const float x = xy[2 * k], y = xy[2 * k + 1];
    const int in = (x >= sure.x0) & (x < sure.x1) & (y >= sure.y0) & (y < sure.y1);
    const int may_in = (x >= may.x0) & (x < may.x1) & (y >= may.y0) & (y < may.y1);
    flags[k] = static_cast<std::uint8_t>(2 * may_in - in);  // sure lies inside may
  }
}

KDM_RUN_CLONES void key_run(std::uint64_t* to, std::size_t count, std::uint64_t first, std::uint64_t step) {
  for (std::size_t k = 0; k < count; ++k) to[k] = first + k * step;
}

KDM_RUN_CLONES void image_run(const TilePoint* __restrict from, std::size_t count, double wx, double wy,
                              double S, const DensityImageView& image, double sx, double sy,
                              double* __restrict x, double* __restrict y, double* __restrict rho) {
  const float* __restrict values = image.values;
  const double x0 = image.x0, y0 = image.y0, last_x = image.width - 1.0, last_y = image.height - 1.0;
  const int w = image.width, wmax = image.width - 1, hmax = image.height - 1;
  for (std::size_t k = 0; k < count; ++k) {
    const double px = wx + ((from[k].x + 0.5) * (1.0 / 65536.0)) * S;
    const double py = wy + ((from[k].y + 0.5) * (1.0 / 65536.0)) * S;
    double fx = (px - x0) * sx - 0.5, fy = (py - y0) * sy - 0.5;
    fx = std::min(std::max(fx, 0.0), last_x), fy = std::min(std::max(fy, 0.0), last_y);  // std::clamp's
    const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
    const int jx = std::min(ix + 1, wmax), jy = std::min(iy + 1, hmax);
    const double ax = fx - ix, ay = fy - iy;
    const int r0 = iy * w, r1 = jy * w;  // 32-bit texel indices, which the vector gathers take
    x[k] = px, y[k] = py;
    rho[k] = (1 - ay) * ((1 - ax) * values[r0 + ix] + ax * values[r0 + jx]) +
             ay * ((1 - ax) * values[r1 + ix] + ax * values[r1 + jx]);
  }
}

}  // namespace kdm::detail
