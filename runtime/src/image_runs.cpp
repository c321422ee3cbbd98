// Image densities at blocks of candidates; see image_runs.h.
#include "image_runs.h"

#include <algorithm>

#include "run_clones.h"

namespace kdm_runs {  // outside kdm: float_runs.h says why
using namespace kdm;
using namespace kdm::detail;

namespace {

/// Where the candidates fall among the texels (ImageSampler::texels, with 32-bit indices): the four
/// texels' indices and the weights of the second ones.
struct BlockTexels {
  int i00[kImageBlock], i01[kImageBlock], i10[kImageBlock], i11[kImageBlock];
  double ax[kImageBlock], ay[kImageBlock];
};

/// Texel k of a block: ImageSampler::texels at world (px, py), its transform and limits passed in.
[[gnu::always_inline]] inline void texels_at(double px, double py, double x0, double y0, double sx, double sy,
                                             double last_x, double last_y, int w, int wmax, int hmax,
                                             BlockTexels& __restrict t, std::size_t k) {
  double fx = (px - x0) * sx - 0.5, fy = (py - y0) * sy - 0.5;
  fx = std::min(std::max(0.0, fx), last_x), fy = std::min(std::max(0.0, fy), last_y);  // ImageSampler's
  const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
  const int jx = std::min(ix + 1, wmax), jy = std::min(iy + 1, hmax);
  t.i00[k] = iy * w + ix, t.i01[k] = iy * w + jx, t.i10[k] = jy * w + ix, t.i11[k] = jy * w + jx;
  t.ax[k] = fx - ix, t.ay[k] = fy - iy;
}

[[gnu::always_inline]] inline void block_texels(const TilePoint* __restrict from, std::size_t count,
                                                double wx, double wy, double S, const ImageSampler& sampler,
                                                double* __restrict x, double* __restrict y,
                                                BlockTexels& __restrict t) {
  const DensityImageView& image = *sampler.image;
  const double x0 = image.x0, y0 = image.y0, sx = sampler.sx, sy = sampler.sy;
  const double last_x = image.width - 1.0, last_y = image.height - 1.0;
  const int w = image.width, wmax = image.width - 1, hmax = image.height - 1;
  for (std::size_t k = 0; k < count; ++k) {
    const double px = wx + ((from[k].x + 0.5) * (1.0 / 65536.0)) * S;  // TilePoint::unit_x
    const double py = wy + ((from[k].y + 0.5) * (1.0 / 65536.0)) * S;
    x[k] = px, y[k] = py;
    texels_at(px, py, x0, y0, sx, sy, last_x, last_y, w, wmax, hmax, t, k);
  }
}

/// The same at world positions (x[k], y[k]).
[[gnu::always_inline]] inline void block_texels_at(const double* __restrict x, const double* __restrict y,
                                                   std::size_t count, const ImageSampler& sampler,
                                                   BlockTexels& __restrict t) {
  const DensityImageView& image = *sampler.image;
  const double x0 = image.x0, y0 = image.y0, sx = sampler.sx, sy = sampler.sy;
  const double last_x = image.width - 1.0, last_y = image.height - 1.0;
  const int w = image.width, wmax = image.width - 1, hmax = image.height - 1;
  for (std::size_t k = 0; k < count; ++k)
    texels_at(x[k], y[k], x0, y0, sx, sy, last_x, last_y, w, wmax, hmax, t, k);
}

/// ImageSampler::blend of `values` at the block's texels, k < count.
[[gnu::always_inline]] inline double blend(const float* __restrict values, const BlockTexels& t,
                                           std::size_t k) {
  const double ax = t.ax[k], ay = t.ay[k];
  return (1 - ay) * ((1 - ax) * values[t.i00[k]] + ax * values[t.i01[k]]) +
         ay * ((1 - ax) * values[t.i10[k]] + ax * values[t.i11[k]]);
}

}  // namespace

KDM_RUN_CLONES void image_run(const TilePoint* from, std::size_t count, double wx, double wy, double S,
                              const ImageSampler& sampler, double* x, double* y, double* rho) {
  BlockTexels t;
  block_texels(from, count, wx, wy, S, sampler, x, y, t);
  const float* values = sampler.image->values;
  for (std::size_t k = 0; k < count; ++k) rho[k] = blend(values, t, k);
}

KDM_RUN_CLONES void image_read_run(const double* x, const double* y, std::size_t count,
                                   const ImageSampler& sampler, double* rho) {
  BlockTexels t;
  block_texels_at(x, y, count, sampler, t);
  const float* values = sampler.image->values;
  for (std::size_t k = 0; k < count; ++k) rho[k] = blend(values, t, k);
}

KDM_RUN_CLONES void image_sums_run(const TilePoint* from, std::size_t count, double wx, double wy, double S,
                                   const ImageSampler& sampler, const float* const* values,
                                   std::uint32_t images, double* x, double* y, double* sums) {
  BlockTexels t;
  block_texels(from, count, wx, wy, S, sampler, x, y, t);
  for (std::size_t k = 0; k < count; ++k) sums[k] = 0.0 + blend(values[0], t, k);
  for (std::uint32_t i = 1; i < images; ++i) {
    double* __restrict to = sums + i * kImageBlock;
    const double* __restrict from_sums = to - kImageBlock;
    for (std::size_t k = 0; k < count; ++k) to[k] = from_sums[k] + blend(values[i], t, k);
  }
}

KDM_RUN_CLONES void image_sum_classes_run(const TilePoint* from, std::size_t count, double wx, double wy,
                                          double S, const ImageSampler& sampler, const float* const* sums,
                                          std::uint32_t planes, const float* thresholds, double area,
                                          std::uint8_t first_class, std::uint8_t* cls) {
  BlockTexels t;
  double x[kImageBlock], y[kImageBlock];
  block_texels(from, count, wx, wy, S, sampler, x, y, t);
  std::uint8_t found[kImageBlock];
  for (std::size_t k = 0; k < count; ++k) found[k] = first_class;
  for (std::uint32_t i = 0; i < planes; ++i)
    for (std::size_t k = 0; k < count; ++k)
      found[k] += !TilesetShape::emits(thresholds[k], blend(sums[i], t, k) * area);
  std::copy(found, found + count, cls);
}

KDM_RUN_CLONES void image_classes_run(const TilePoint* from, std::size_t count, double wx, double wy,
                                      double S, const ImageSampler& sampler, const float* const* sums,
                                      std::uint32_t classes, const double* lo, const double* hi,
                                      const float* thresholds, double area_scale, double area, double* x,
                                      double* y, double* rho, std::uint8_t* cls) {
  BlockTexels t;
  block_texels(from, count, wx, wy, S, sampler, x, y, t);
  const float* values = sampler.image->values;
  for (std::size_t k = 0; k < count; ++k) rho[k] = blend(values, t, k);
  // Thresholds rise with the rank, and so do the sums with the class: a block whose first threshold
  // every sum but the last falls short of everywhere is all of the last class.
  if (classes > 1 && !TilesetShape::emits(thresholds[0], hi[classes - 2])) {
    std::fill(cls, cls + count, static_cast<std::uint8_t>(classes - 1));
    return;
  }
  // The emitted candidates whose class the bounds leave open are gathered, so that the loops stay
  // branch-free; the bounds settle the others (the classes short of a threshold are a prefix).
  std::uint8_t short_everywhere[kImageBlock] = {}, short_somewhere[kImageBlock] = {};
  for (std::uint32_t c = 0; c + 1 < classes; ++c) {
    const double l = lo[c], h = hi[c];
    for (std::size_t k = 0; k < count; ++k) {
      short_everywhere[k] += !TilesetShape::emits(thresholds[k], h);
      short_somewhere[k] += !TilesetShape::emits(thresholds[k], l);
    }
  }
  std::copy(short_everywhere, short_everywhere + count, cls);
  // A byte store may alias any pointer: the gathering loop stores only into locals.
  std::uint8_t open[kImageBlock];
  std::uint32_t m = 0;
  for (std::size_t k = 0; k < count; ++k) {
    open[m] = static_cast<std::uint8_t>(k);
    m +=
        TilesetShape::emits(thresholds[k], rho[k] * area_scale) & (short_everywhere[k] != short_somewhere[k]);
  }
  std::uint8_t found[kImageBlock] = {};
  for (std::uint32_t c = 0; c + 1 < classes; ++c)
    for (std::uint32_t i = 0; i < m; ++i) {
      const std::size_t k = open[i];
      found[i] += !TilesetShape::emits(thresholds[k], blend(sums[c], t, k) * area);
    }
  for (std::uint32_t i = 0; i < m; ++i) cls[open[i]] = found[i];
}

}  // namespace kdm_runs
