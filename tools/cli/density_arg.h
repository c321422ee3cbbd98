// Parsing of --density: "const:V" or an image whose darkness is the density.
#pragma once

#include <string>
#include <vector>

#include "kdm/generator/sampler.h"

namespace kdm::cli {

struct DensityArg {
  gen::Density density;
  bool from_image = false;
  int image_width = 0, image_height = 0;
  std::vector<float> values;  ///< the image's density values, row 0 at the bottom (images only)
  double constant = 1;        ///< the value of const:V
};

/// `spec` is "const:V" (V finite, > 0; or >= 0 with `allow_zero`, for queries, where 0 emits nothing) or
/// a path to an image. Image darkness (1 - luminance) raised to `gamma` is the density; `invert` uses
/// luminance instead (bright = dense). Throws CommandError.
DensityArg parse_density(const std::string& spec, double gamma, bool invert, bool allow_zero = false);

}  // namespace kdm::cli
