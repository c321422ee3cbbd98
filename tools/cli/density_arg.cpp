#include "density_arg.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "commands.h"

namespace kdm::cli {

void check_gamma(double gamma) {
  if (std::isfinite(gamma) && gamma > 0) return;
  char text[80];
  std::snprintf(text, sizeof text, "--gamma must be a finite number > 0, got %g", gamma);
  throw CommandError(text);
}

tools::DensitySpec parse_density(const std::string& text, double gamma, bool invert, std::uint64_t max_pixels,
                                 const tools::KeptPixels& kept, double white) {
  check_gamma(gamma);
  try {
    return tools::parse_density_spec(text, gamma, invert, max_pixels, kept, white);
  } catch (const std::exception& e) {  // a bad value, or an image that cannot be read
    throw CommandError(e.what());
  }
}

void check_class_images(const std::vector<const tools::DensitySpec*>& classes) {
  const auto [i, j] = tools::images_of_different_shapes(classes);
  if (j < 0) return;
  auto shape = [](const tools::DensitySpec& s) {
    return "'" + s.text + "' is " + std::to_string(s.width) + "x" + std::to_string(s.height);
  };
  throw CommandError(
      "--class images must have one shape (width to height), each stretched over the same "
      "rectangle: " +
      shape(*classes[i]) + ", " + shape(*classes[j]));
}

void check_image_options(const std::vector<const tools::DensitySpec*>& densities, double gamma, bool invert) {
  if (gamma == 1 && !invert) return;
  for (const tools::DensitySpec* s : densities)
    if (s->kind == tools::DensitySpec::Kind::kImage) return;
  throw CommandError(std::string(invert ? "--invert" : "--gamma") +
                     " applies to image files only, and no density given is one");
}

}  // namespace kdm::cli
