// Internal: bilinear reads of a DensityImageView with its world-to-texel transform hoisted out of the
// per-point loop (the query loop and DensityImageView::at share it).
#pragma once

#include <algorithm>
#include <cstddef>

#include "kdm/runtime/density_image.h"

namespace kdm::detail {

struct ImageSampler {
  const DensityImageView* image = nullptr;
  double sx = 0, sy = 0;
  ImageSampler() = default;
  explicit ImageSampler(const DensityImageView* im) : image(im) {
    if (im) sx = im->width / (im->x1 - im->x0), sy = im->height / (im->y1 - im->y0);
  }
  double at(double x, double y) const {
    const DensityImageView& im = *image;
    const double fx = std::clamp((x - im.x0) * sx - 0.5, 0.0, im.width - 1.0);
    const double fy = std::clamp((y - im.y0) * sy - 0.5, 0.0, im.height - 1.0);
    const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
    const int jx = std::min(ix + 1, im.width - 1), jy = std::min(iy + 1, im.height - 1);
    const double ax = fx - ix, ay = fy - iy;
    const float* r0 = im.values + static_cast<std::size_t>(iy) * im.width;
    const float* r1 = im.values + static_cast<std::size_t>(jy) * im.width;
    return (1 - ay) * ((1 - ax) * r0[ix] + ax * r0[jx]) + ay * ((1 - ax) * r1[ix] + ax * r1[jx]);
  }
};

}  // namespace kdm::detail
