// The running sums of classes' density images (kdm/runtime/class_image_sums.h).
#include "kdm/runtime/class_image_sums.h"

#include <cstddef>
#include <limits>

#include "image_sampler.h"

namespace kdm {

Status ClassImageSums::build(const DensityImageView* const* images, std::uint32_t count,
                             const char** problem) {
  *this = ClassImageSums();
  auto refuse = [&](const char* what) {
    *this = ClassImageSums();
    if (problem) *problem = what;
    return Status::kInvalidArgument;
  };
  if (count < 1 || count > kMaxQueryClasses) return refuse("the class count is not 1 ... 8");
  if (!images) return refuse("images is null");
  for (std::uint32_t k = 0; k < count; ++k) {
    if (!images[k] || !images[k]->values) return refuse("an image or its values is null");
    if (!detail::ImageSampler(images[0]).same_grid(*images[k]))
      return refuse("an image is not on the first image's grid (size and world rectangle)");
  }
  const DensityImageView& first = *images[0];
  if (first.width <= 0 || first.height <= 0) return refuse("an image is empty");
  if (first.width > kMaxDensityImageSide || first.height > kMaxDensityImageSide)
    return refuse("an image is wider or taller than kMaxDensityImageSide texels");
  if (!detail::image_rect_usable(first)) return refuse("the images' world rectangle is unusable");
  const std::size_t n = static_cast<std::size_t>(first.width) * static_cast<std::size_t>(first.height);
  texels_.resize(n * count);
  for (std::uint32_t k = 0; k < count; ++k) {
    const float* v = images[k]->values;
    float* out = texels_.data() + k * n;
    const float* below = k > 0 ? out - n : nullptr;
    bool valid = true, finite = true;  // checked after the loop, which then has no branch
    for (std::size_t i = 0; i < n; ++i) {
      valid &= v[i] >= 0 && v[i] <= std::numeric_limits<float>::max();  // false for NaN
      out[i] = below ? below[i] + v[i] : v[i];
      finite &= out[i] <= std::numeric_limits<float>::max();
    }
    if (!valid) return refuse("an image has a negative or non-finite value");
    if (!finite) return refuse("the images' sum overflows a float");
    DensityImageView& s = sums_[k];
    s = first;
    s.values = out;
    detail::fill_mips(s, mips_[k]);
  }
  count_ = count;
  return Status::kOk;
}

}  // namespace kdm
