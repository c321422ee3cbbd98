// Classes whose densities are images on one grid of texels, given to a class query (class_query.h) by
// the images of their running sums: the query reads one image for the union, as a one-class query reads
// one, and finds each emitted point's class from the same texels of the others.
#pragma once

#include <cstdint>
#include <utility>
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
/// candidate. Against those, which sum the images' values in double, stable mode emits the same points
/// (their classes too, but for a threshold within rounding of a density); smooth mode the same ids at
/// positions that may differ in their last bits, under 3 · 10^-7 of a tile side (at most 1.5 · 10^-7 measured
/// over 11 million points, tile sides 0.25 to 4, 4 to 4 · 10^5 points per tile; most at 10 to 200, where a
/// glide is fastest against the count). Built once, shared read-only; it owns its texels, so it moves but
/// does not copy.
class KDM_RUNTIME_API ClassImageSums {
 public:
  ClassImageSums() = default;
  ClassImageSums(const ClassImageSums&) = delete;
  ClassImageSums& operator=(const ClassImageSums&) = delete;
  /// A move leaves `other` empty (count() 0, refused by a query), its views no longer into texels it gave.
  ClassImageSums(ClassImageSums&& other) noexcept { *this = std::move(other); }
  ClassImageSums& operator=(ClassImageSums&& other) noexcept {
    if (this != &other) {
      count_ = other.count_, texels_ = std::move(other.texels_);
      for (std::uint32_t k = 0; k < kMaxQueryClasses; ++k) {
        sums_[k] = other.sums_[k], mips_[k] = std::move(other.mips_[k]);
        other.sums_[k] = DensityImageView{}, other.mips_[k].clear();
      }
      other.count_ = 0, other.texels_.clear();
    }
    return *this;
  }

  /// Builds the sums of images[0 … count), class 0 first; each image's values are read (its mips are not
  /// needed). Sums are added in float, class by class, so sum(0) is images[0]'s texels exactly.
  /// Returns kOk, or kInvalidArgument (this left empty) with `problem` (optional) naming the fault in a
  /// static string: a count of 0 or more than kMaxQueryClasses, a null image or values, an image not on
  /// images[0]'s grid (width, height and world rectangle), or one make_density_max_mip refuses. Its texels
  /// come from the C++ allocator, not the tile-set allocator hooks (allocator.h): one float per texel and
  /// class, and the mips; where that throws std::bad_alloc, so does build (the C API returns
  /// KDM_OUT_OF_MEMORY).
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
