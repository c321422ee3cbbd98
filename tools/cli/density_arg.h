// Parsing of --density: "const:V", the test maps "ramp:R" and "radial:R", or an image whose darkness is
// the density.
#pragma once

#include <string>
#include <vector>

#include "kdm/generator/sampler.h"

namespace kdm::cli {

struct DensityArg {
  gen::Density density;
  bool from_image = false;
  bool analytic = false;  ///< ramp:R or radial:R (a function, not an image)
  int image_width = 0, image_height = 0;
  std::vector<float> values;  ///< the image's density values, row 0 at the bottom (images only)
  double constant = 1;        ///< the value of const:V
};

/// `spec` is "const:V" (V finite, > 0; or >= 0 with `allow_zero`, for queries, where 0 emits nothing),
/// "ramp:R" (R^-x: from 1 at the left edge to 1/R at the right), "radial:R" (R^-(r/0.5) with r the
/// distance from the centre, 1/R beyond r = 0.5; continuous across a torus's edges), R in [1, 1e9], or a
/// path to an image. Image darkness (1 - luminance) raised to `gamma` is the density; `invert` uses
/// luminance instead (bright = dense). Throws CommandError.
DensityArg parse_density(const std::string& spec, double gamma, bool invert, bool allow_zero = false);

}  // namespace kdm::cli
