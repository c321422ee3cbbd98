// Density images for queries (kdm/runtime/density_image.h): bilinear reads and the block bounds.
#include "kdm/runtime/density_image.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "image_sampler.h"

namespace kdm {

double DensityImageView::at(double x, double y) const {
  if (!values || !detail::image_rect_usable(*this)) return 0;  // an image no query takes: nothing there
  return detail::ImageSampler(this).at(x, y);
}

namespace {

/// The max-mip's or min-mip's blocks over a world rectangle, folded with `pick` from `start`.
template <class Pick>
double fold_blocks(const DensityImageView& im, const float* mip, double qx0, double qy0, double qx1,
                   double qy1, float start, Pick pick) {
  auto block = [](double v, double lo, double hi, int n, int blocks) {
    const double t = std::min(std::max(0.0, (v - lo) / (hi - lo) * n), double(n - 1));  // NaN to 0
    return std::min(blocks - 1, static_cast<int>(t) / 8);
  };
  const int bx0 = block(qx0, im.x0, im.x1, im.width, im.mip_width),
            bx1 = block(qx1, im.x0, im.x1, im.width, im.mip_width);
  const int by0 = block(qy0, im.y0, im.y1, im.height, im.mip_height),
            by1 = block(qy1, im.y0, im.y1, im.height, im.mip_height);
  float m = start;
  for (int by = by0; by <= by1; ++by)
    for (int bx = bx0; bx <= bx1; ++bx) m = pick(m, mip[static_cast<std::size_t>(by) * im.mip_width + bx]);
  return m;
}

}  // namespace

double DensityImageView::max_over(double qx0, double qy0, double qx1, double qy1) const {
  return fold_blocks(*this, max_mip, qx0, qy0, qx1, qy1, 0.0f,
                     [](float a, float b) { return std::max(a, b); });
}

double DensityImageView::min_over(double qx0, double qy0, double qx1, double qy1) const {
  if (!min_mip) return 0;
  return fold_blocks(*this, min_mip, qx0, qy0, qx1, qy1, std::numeric_limits<float>::infinity(),
                     [](float a, float b) { return std::min(a, b); });
}

Status make_density_max_mip(DensityImageView& image, std::vector<float>& mip) {
  if (!image.values || !detail::image_rect_usable(image)) return Status::kInvalidArgument;
  const std::size_t count = static_cast<std::size_t>(image.width) * image.height;
  for (std::size_t i = 0; i < count; ++i)
    if (!(image.values[i] >= 0 && std::isfinite(image.values[i]))) return Status::kInvalidArgument;
  detail::fill_mips(image, mip);
  return Status::kOk;
}

void detail::fill_mips(DensityImageView& image, std::vector<float>& mip) {
  image.mip_width = (image.width + 7) / 8;
  image.mip_height = (image.height + 7) / 8;
  const int w = image.width, h = image.height, bw = image.mip_width, bh = image.mip_height;
  const std::size_t blocks = static_cast<std::size_t>(bw) * bh;
  mip.assign(2 * blocks, 0.0f);
  // Each block also covers one texel around it: bilinear values inside a block mix in its neighbours. Rows
  // first (each row's extremes over every block's columns), then each block's rows: about two reads a texel.
  std::vector<float> row_max(static_cast<std::size_t>(h) * bw), row_min(row_max.size());
  for (int y = 0; y < h; ++y) {
    const float* row = image.values + static_cast<std::size_t>(y) * w;
    for (int bx = 0; bx < bw; ++bx) {
      const int x0 = std::max(0, 8 * bx - 1), x1 = std::min(w, 8 * bx + 9);
      float hi = row[x0], lo = row[x0];
      for (int x = x0 + 1; x < x1; ++x) hi = std::max(hi, row[x]), lo = std::min(lo, row[x]);
      row_max[static_cast<std::size_t>(y) * bw + bx] = hi,
                                                 row_min[static_cast<std::size_t>(y) * bw + bx] = lo;
    }
  }
  for (int by = 0; by < bh; ++by) {
    const int y0 = std::max(0, 8 * by - 1), y1 = std::min(h, 8 * by + 9);
    float* hi = mip.data() + static_cast<std::size_t>(by) * bw;
    float* lo = hi + blocks;
    std::copy(row_max.begin() + std::ptrdiff_t(y0) * bw, row_max.begin() + std::ptrdiff_t(y0 + 1) * bw, hi);
    std::copy(row_min.begin() + std::ptrdiff_t(y0) * bw, row_min.begin() + std::ptrdiff_t(y0 + 1) * bw, lo);
    for (int y = y0 + 1; y < y1; ++y)
      for (int bx = 0; bx < bw; ++bx) {
        hi[bx] = std::max(hi[bx], row_max[static_cast<std::size_t>(y) * bw + bx]);
        lo[bx] = std::min(lo[bx], row_min[static_cast<std::size_t>(y) * bw + bx]);
      }
  }
  image.max_mip = mip.data(), image.min_mip = mip.data() + blocks;
}

}  // namespace kdm
