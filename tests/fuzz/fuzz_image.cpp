// Fuzz target: the image path of `kdm stipple`, `sample` and `query`: an image file's bytes (PNG 8/16-bit,
// grey or colour, JPEG, and whatever else stb_image reads) through load_grey_image_memory, then into a
// density as the command line makes one (darkness to the power gamma, rows flipped; gamma and --invert
// from the last byte) for the sampler (Density::from_values) and the runtime (make_density_max_mip).
// The pixel limit is lowered to kFuzzMaxPixels so that each input stays cheap; the limit's logic is the
// same. Checks: an accepted image is non-empty, within the limit, with width·height values in [0, 1];
// a refused one has an error naming the image; read averaged down (as kdm stipple reads a large picture)
// it keeps its size rule, its range and its mean; the density is accepted by the runtime, and its max-mip
// bounds the density at sample points; the sampler's density is finite and >= 0 there.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "image_io.h"
#include "kdm/generator/sampler.h"
#include "kdm/runtime/query.h"

namespace {

constexpr std::uint64_t kFuzzMaxPixels = 1 << 12;  // e.g. 64×64

[[noreturn]] void fail() {
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  kdm::tools::GreyImage image;
  std::string error;
  if (!kdm::tools::load_grey_image_memory(data, size, image, error, "fuzz.png", kFuzzMaxPixels)) {
    if (error.find("'fuzz.png'") == std::string::npos) fail();
    return 0;
  }
  const int w = image.width, h = image.height;
  if (w <= 0 || h <= 0 || std::uint64_t(w) * std::uint64_t(h) > kFuzzMaxPixels) fail();
  if (image.pixels.size() != std::size_t(w) * std::size_t(h)) fail();
  for (float v : image.pixels)
    if (!(v >= 0 && v <= 1)) fail();

  // Averaged down as kdm stipple reads a large picture: the kept size, values in [0, 1], the same mean
  // (every pixel weighs its area in the kept ones: equal up to float rounding).
  const std::uint8_t share = data[size - 1] % 7 + 1;
  kdm::tools::GreyImage kept;
  const auto keep = [share](int width, int height) {
    return std::uint64_t(width) * height / (share * share);
  };
  if (!kdm::tools::load_grey_image_memory(data, size, kept, error, "fuzz.png", kFuzzMaxPixels, keep)) fail();
  if (kept.width < 1 || kept.height < 1 || kept.width > w || kept.height > h) fail();
  if (kept.pixels.size() != std::size_t(kept.width) * std::size_t(kept.height)) fail();
  double mean = 0, kept_mean = 0;
  for (float v : image.pixels) mean += v;
  for (float v : kept.pixels) {
    if (!(v >= 0 && v <= 1)) fail();
    kept_mean += v;
  }
  if (!(std::fabs(mean / image.pixels.size() - kept_mean / kept.pixels.size()) < 1e-4)) fail();

  // As tools/cli/density_arg.cpp: density = tone^gamma, tone = darkness (or brightness with --invert).
  const std::uint8_t last = data[size - 1];
  const double gamma = 0.25 * (1 + last % 16);
  const bool invert = last & 0x80;
  std::vector<float> values(image.pixels.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double grey = image.at(x, h - 1 - y), tone = invert ? grey : 1.0 - grey;
      values[static_cast<std::size_t>(y) * w + x] = static_cast<float>(std::pow(std::max(0.0, tone), gamma));
    }

  // The runtime's density (kdm query, stipple): valid, and its max-mip bounds it everywhere.
  kdm::DensityImageView view;
  view.width = w, view.height = h;
  view.values = values.data();
  std::vector<float> mip;
  if (kdm::make_density_max_mip(view, mip) != kdm::Status::kOk) fail();
  // (Up to rounding: bilinear weights summing to 1 can give a value one ulp above equal corners.)
  const double slack = 1 + 1e-12, bound = view.max_over(0, 0, 1, 1) * slack;
  for (int i = 0; i <= 8; ++i) {
    const double u = i / 8.0, v = (8 - i) / 8.0, rho = view.at(u, v);
    if (!(rho >= 0 && rho <= bound)) fail();
    if (!(rho <= view.max_over(u, v, u, v) * slack)) fail();
    if (!(rho >= view.min_over(u, v, u, v) / slack)) fail();
  }

  // The sampler's density (kdm sample, stipple): refused only when zero everywhere.
  const bool any_ink = std::any_of(values.begin(), values.end(), [](float v) { return v > 0; });
  try {
    const kdm::gen::Density density = kdm::gen::Density::from_values(w, h, values);
    if (!any_ink) fail();
    for (int i = 0; i <= 4; ++i) {
      const double u[2] = {i / 4.0, 1 - i / 8.0};
      const double rho = density.function(u);
      if (!(rho >= 0 && std::isfinite(rho))) fail();
    }
  } catch (const kdm::gen::InvalidArgument&) {
    if (any_ink) fail();
  }
  return 0;
}
