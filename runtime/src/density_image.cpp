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
  if (image.width <= 0 || image.height <= 0 || !image.values) return Status::kInvalidArgument;
  if (!detail::image_rect_usable(image)) return Status::kInvalidArgument;
  const std::size_t count = static_cast<std::size_t>(image.width) * image.height;
  for (std::size_t i = 0; i < count; ++i)
    if (!(image.values[i] >= 0 && std::isfinite(image.values[i]))) return Status::kInvalidArgument;
  image.mip_width = (image.width + 7) / 8;
  image.mip_height = (image.height + 7) / 8;
  const std::size_t blocks = static_cast<std::size_t>(image.mip_width) * image.mip_height;
  mip.assign(2 * blocks, 0.0f);
  std::fill(mip.begin() + std::ptrdiff_t(blocks), mip.end(), std::numeric_limits<float>::infinity());
  // Each block also covers one texel around it: bilinear values inside a block mix in its neighbours.
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const float v = image.values[static_cast<std::size_t>(y) * image.width + x];
      for (int by = std::max(0, (y - 1) / 8); by <= std::min(image.mip_height - 1, (y + 1) / 8); ++by)
        for (int bx = std::max(0, (x - 1) / 8); bx <= std::min(image.mip_width - 1, (x + 1) / 8); ++bx) {
          const std::size_t b = static_cast<std::size_t>(by) * image.mip_width + bx;
          mip[b] = std::max(mip[b], v), mip[blocks + b] = std::min(mip[blocks + b], v);
        }
    }
  image.max_mip = mip.data(), image.min_mip = mip.data() + blocks;
  return Status::kOk;
}

}  // namespace kdm
