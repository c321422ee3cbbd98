// Internal: bilinear reads of a DensityImageView with its world-to-texel transform hoisted out of the
// per-point loop (the query loop and DensityImageView::at share it).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "kdm/runtime/density_image.h"

namespace kdm::detail {

/// make_density_max_mip's mips of an image it has checked (values finite and >= 0, a usable rectangle).
void fill_mips(DensityImageView& image, std::vector<float>& mip);

/// Whether world positions map to texels as numbers: a finite rectangle of positive size whose texels per
/// world unit are finite (a rectangle hundreds of orders of magnitude smaller than its texels is not, nor one
/// whose size overflows), so that no position gives NaN (0 · ∞) where the texels are found, and whose sides
/// leave texel and block indices within int (kMaxDensityImageSide).
inline bool image_rect_usable(const DensityImageView& im) {
  if (!(im.width > 0 && im.height > 0 && im.width <= kMaxDensityImageSide &&
        im.height <= kMaxDensityImageSide))
    return false;
  const double sx = im.width / (im.x1 - im.x0), sy = im.height / (im.y1 - im.y0);
  return std::isfinite(im.x0) && std::isfinite(im.y0) && sx > 0 && sy > 0 && std::isfinite(sx) &&
         std::isfinite(sy) && std::isfinite(im.x1 - im.x0) && std::isfinite(im.y1 - im.y0);
}

/// Whether a query can read `im`: values, and a max-mip whose blocks match its size (a view reused for a
/// larger image with its old mips would read past them), over a usable rectangle.
inline bool image_queryable(const DensityImageView& im) {
  return im.values && im.max_mip && image_rect_usable(im) && im.mip_width == (im.width + 7) / 8 &&
         im.mip_height == (im.height + 7) / 8;
}

struct ImageSampler {
  const DensityImageView* image = nullptr;
  double sx = 0, sy = 0;
  ImageSampler() = default;
  explicit ImageSampler(const DensityImageView* im) : image(im) {
    if (im) sx = im->width / (im->x1 - im->x0), sy = im->height / (im->y1 - im->y0);
  }
  /// Where a world position falls among the texels: the four texels around it (rows r0, r1 from the
  /// image's values, columns ix, jx) and the weights of the second ones.
  struct Texels {
    std::size_t r0, r1;
    int ix, jx;
    double ax, ay;
  };
  Texels texels(double x, double y) const {
    const DensityImageView& im = *image;
    // Clamped to the texels, NaN (a NaN position) to the first.
    const double fx = std::min(std::max(0.0, (x - im.x0) * sx - 0.5), im.width - 1.0);
    const double fy = std::min(std::max(0.0, (y - im.y0) * sy - 0.5), im.height - 1.0);
    const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
    const int jx = std::min(ix + 1, im.width - 1), jy = std::min(iy + 1, im.height - 1);
    return Texels{static_cast<std::size_t>(iy) * im.width,
                  static_cast<std::size_t>(jy) * im.width,
                  ix,
                  jx,
                  fx - ix,
                  fy - iy};
  }
  /// The bilinear value at `t` of `values`, an image of this one's size.
  static double blend(const float* values, const Texels& t) {
    const float *r0 = values + t.r0, *r1 = values + t.r1;
    return (1 - t.ay) * ((1 - t.ax) * r0[t.ix] + t.ax * r0[t.jx]) +
           t.ay * ((1 - t.ax) * r1[t.ix] + t.ax * r1[t.jx]);
  }
  double at(double x, double y) const { return blend(image->values, texels(x, y)); }
  /// Whether `other` lies on the same texels as this image: then texels() serves both.
  bool same_grid(const DensityImageView& other) const {
    const DensityImageView& im = *image;
    return im.width == other.width && im.height == other.height && im.x0 == other.x0 && im.y0 == other.y0 &&
           im.x1 == other.x1 && im.y1 == other.y1;
  }
};

}  // namespace kdm::detail
