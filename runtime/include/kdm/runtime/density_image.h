// A density image for queries (kdm/runtime/query.h): caller-owned texels over a world rectangle, with the
// block bounds that let a query skip what the density can never emit.
#pragma once

#include <vector>

#include "kdm/runtime/export.h"
#include "kdm/runtime/status.h"

namespace kdm {

/// The widest and tallest density image, in texels (2^30): texel and block arithmetic stays within int.
inline constexpr int kMaxDensityImageSide = 1 << 30;

/// A density image over a world rectangle: bilinear between texel centres, clamped at the edges.
/// Values must be finite and >= 0 (validated by make_density_max_mip). Built once, shared read-only.
struct KDM_RUNTIME_API DensityImageView {
  int width = 0, height = 0;              ///< texels
  double x0 = 0, y0 = 0, x1 = 1, y1 = 1;  ///< world rectangle covered; row 0 at y0
  const float* values = nullptr;          ///< width·height, row-major, owned by the caller
  const float* max_mip = nullptr;         ///< per 8×8 texel block maximum (see make_density_max_mip)
  const float* min_mip = nullptr;         ///< per 8×8 texel block minimum (optional: null means 0)
  int mip_width = 0, mip_height = 0;      ///< blocks of 8×8 texels: ceil(width / 8) × ceil(height / 8)
  /// The density at world position (x, y): bilinear, clamped at the edges (a NaN position reads the first
  /// texel, an infinite one the edge's: queries never ask for either; the C kdm_density_image_at returns 0
  /// for both); 0 for an image without values or with a rectangle make_density_max_mip refuses.
  double at(double x, double y) const;
  /// Upper bound of the density over a world rectangle (from the max-mip, which must be set; exact bound,
  /// maybe loose).
  double max_over(double x0, double y0, double x1, double y1) const;
  /// Lower bound of the density over a world rectangle (from the min-mip; 0 without one).
  double min_over(double x0, double y0, double x1, double y1) const;
};

/// Fills `mip` (resized to 2·ceil(w/8)·ceil(h/8)) with the 8×8 block maxima of `image.values`, then their
/// minima, each block widened by one texel so they bound bilinear values too, and points the image's
/// max_mip and min_mip at them. Returns kInvalidArgument for empty images, a side longer than
/// kMaxDensityImageSide, values that are negative or
/// not finite, and a world rectangle that is not finite and of positive size, or whose texels per world
/// unit overflow (a rectangle narrower than about 10^-300 of a unit per texel). Queries refuse such an
/// image too ("density.image"), should its rectangle change after this call, and one whose size no longer
/// matches its mips' (make the mips again for a new size).
KDM_RUNTIME_API Status make_density_max_mip(DensityImageView& image, std::vector<float>& mip);

}  // namespace kdm
