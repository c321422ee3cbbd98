// The compact output's runs of points; see float_runs.h.
#include "float_runs.h"

#include "run_clones.h"

namespace kdm_runs {  // outside kdm: float_runs.h says why
using namespace kdm;
using namespace kdm::detail;

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

}  // namespace kdm_runs
