#include "density_arg.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

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
  for (const char* kind : {"ramp:", "radial:"}) {
    const std::size_t len = std::char_traits<char>::length(kind);
    if (spec.compare(0, len, kind) != 0) continue;
    const std::string value = spec.substr(len);
    char* end = nullptr;
    const double range = std::strtod(value.c_str(), &end);
    if (value.empty() || *end != '\0' || !(range >= 1 && range <= 1e9))
      throw CommandError("--density " + std::string(kind) + "R needs a dynamic range R in [1, 1e9], got '" +
                         value + "'");
    const double a = std::log(range);
    if (std::string(kind) == "ramp:")
      arg.density.function = [a](const double* u) { return std::exp(-a * u[0]); };
    else
      arg.density.function = [a](const double* u) {
        const double dx = u[0] - 0.5, dy = u[1] - 0.5;
        return std::exp(-a * std::min(1.0, 2 * std::sqrt(dx * dx + dy * dy)));
      };
    arg.density.thread_safe = true;
    arg.analytic = true;
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
