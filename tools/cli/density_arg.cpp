#include "density_arg.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include <unistd.h>

#include "commands.h"

namespace kdm::cli {

void check_gamma(double gamma) {
  if (std::isfinite(gamma) && gamma > 0) return;
  char text[80];
  std::snprintf(text, sizeof text, "--gamma must be a finite number > 0, got %g", gamma);
  throw CommandError(text);
}

std::vector<std::uint8_t> standard_input_bytes() {
  if (isatty(STDIN_FILENO))
    throw CommandError("'-' reads standard input, and it is a terminal: pipe the input into kdm (< file)");
  std::vector<std::uint8_t> bytes;
  std::string error;
  if (!tools::read_standard_input(bytes, error)) throw CommandError(error);
  if (bytes.empty()) throw CommandError("'-' reads standard input, and it is empty");
  return bytes;
}

void check_one_standard_input(const std::vector<std::pair<std::string, std::string>>& inputs) {
  std::string first;
  for (const auto& [option, value] : inputs) {
    if (value != "-") continue;
    if (!first.empty())
      throw CommandError("standard input is read once: '-' given to " + first + " and to " + option +
                         " (write one of them to a file)");
    first = option;
  }
}

tools::DensitySpec parse_density(const std::string& text, double gamma, bool invert, std::uint64_t max_pixels,
                                 const tools::KeptPixels& kept, double white) {
  check_gamma(gamma);
  try {
    if (text == "-") {
      const std::vector<std::uint8_t> bytes = standard_input_bytes();
      return tools::parse_density_bytes(bytes.data(), bytes.size(), kStandardInputName, gamma, invert,
                                        max_pixels, kept, white);
    }
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
