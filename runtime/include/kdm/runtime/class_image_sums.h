// Classes whose densities are images on one grid of texels, given to a class query (class_query.h) by
// the images of their running sums: the query reads one image for the union, as a one-class query reads
// one, and finds each emitted point's class from the same texels of the others.
#pragma once

#include <cstdint>
#include <vector>

#include "kdm/runtime/class_query.h"
#include "kdm/runtime/density_image.h"
#include "kdm/runtime/export.h"
#include "kdm/runtime/status.h"

namespace kdm {

/// The running sums of `count` classes' density images, texel by texel: sum(k) = ρ_0 + … + ρ_k, each
/// with its mips. Set ClassQueryParams::image_sums to it: the class query then runs as the one-class
/// query at sum(count - 1) runs (exactly that query's points, in stable mode classes 0 … k together
/// exactly the one-class query at sum(k)), where classes given image by image read every image at every
/// candidate. Built once, shared read-only; it owns its texels, so it moves but does not copy.
class KDM_RUNTIME_API ClassImageSums {
 public:
  ClassImageSums() = default;
  ClassImageSums(const ClassImageSums&) = delete;
  ClassImageSums& operator=(const ClassImageSums&) = delete;
  ClassImageSums(ClassImageSums&&) noexcept = default;
  ClassImageSums& operator=(ClassImageSums&&) noexcept = default;

  /// Builds the sums of images[0 … count), class 0 first; each image's values are read (its mips are not
  /// needed). Sums are added in float, class by class, so sum(0) is images[0]'s texels exactly.
  /// Returns kOk, or kInvalidArgument (this left empty) with `problem` (optional) naming the fault in a
  /// static string: a count of 0 or more than kMaxQueryClasses, a null image or values, an image not on
  /// images[0]'s grid (width, height and world rectangle), or one make_density_max_mip refuses.
  Status build(const DensityImageView* const* images, std::uint32_t count, const char** problem = nullptr);

  /// How many classes: 0 until built.
  std::uint32_t count() const { return count_; }
  /// The image of classes 0 … k's summed density, k < count().
  const DensityImageView& sum(std::uint32_t k) const { return sums_[k]; }

 private:
  std::uint32_t count_ = 0;
  DensityImageView sums_[kMaxQueryClasses];
  std::vector<float> texels_;
  std::vector<float> mips_[kMaxQueryClasses];
};

}  // namespace kdm
