#include "density_arg.h"

#include <cmath>
#include <cstdlib>

#include "commands.h"
#include "image_io.h"

namespace kdm::cli {

DensityArg parse_density(const std::string& spec, double gamma, bool invert, bool allow_zero) {
  DensityArg arg;
  if (!(std::isfinite(gamma) && gamma > 0)) throw CommandError("--gamma must be a finite number > 0");
  if (spec.rfind("const:", 0) == 0) {
    const std::string value = spec.substr(6);
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (value.empty() || *end != '\0' || !std::isfinite(v) || v < 0 || (v == 0 && !allow_zero))
      throw CommandError(std::string("--density const:V needs a finite V ") + (allow_zero ? ">= 0" : "> 0") +
                         ", got '" + value + "'");
    arg.density = gen::Density::constant();
    arg.constant = v;
    return arg;
  }
  tools::GreyImage image;
  std::string error;
  if (!tools::load_grey_image(spec, image, error)) throw CommandError(error);
  // Densities keep row 0 at the bottom (y up); the picture's row 0 is its top: flipped here, once.
  std::vector<float> values(image.pixels.size());
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const double grey = image.at(x, image.height - 1 - y), tone = invert ? grey : 1.0 - grey;
      values[static_cast<std::size_t>(y) * image.width + x] =
          static_cast<float>(std::pow(std::max(0.0, tone), gamma));
    }
  try {
    arg.density = gen::Density::from_values(image.width, image.height, values);
    arg.values = std::move(values);
  } catch (const gen::InvalidArgument& e) {
    throw CommandError("image '" + spec + "': " + e.what() +
                       (invert ? "" : " (an all-white image has no ink)"));
  }
  arg.from_image = true;
  arg.image_width = image.width;
  arg.image_height = image.height;
  return arg;
}

}  // namespace kdm::cli
