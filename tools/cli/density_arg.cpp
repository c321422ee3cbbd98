#include "density_arg.h"

#include <stdexcept>

#include "commands.h"

namespace kdm::cli {

tools::DensitySpec parse_density(const std::string& text, double gamma, bool invert) {
  try {
    return tools::parse_density_spec(text, gamma, invert);
  } catch (const std::exception& e) {  // a bad value, or an image that cannot be read
    throw CommandError(e.what());
  }
}

void check_class_images(const std::vector<const tools::DensitySpec*>& classes) {
  const tools::DensitySpec* first = nullptr;
  for (const tools::DensitySpec* s : classes) {
    if (s->kind != tools::DensitySpec::Kind::kImage) continue;
    if (!first) {
      first = s;
    } else if (s->width != first->width || s->height != first->height) {
      auto size = [](const tools::DensitySpec& i) {
        return "'" + i.text + "' is " + std::to_string(i.width) + "x" + std::to_string(i.height);
      };
      throw CommandError("--class images must all have one size: " + size(*first) + ", " + size(*s));
    }
  }
}

void check_image_options(const std::vector<const tools::DensitySpec*>& densities, double gamma, bool invert) {
  if (gamma == 1 && !invert) return;
  for (const tools::DensitySpec* s : densities)
    if (s->kind == tools::DensitySpec::Kind::kImage) return;
  throw CommandError(std::string(invert ? "--invert" : "--gamma") +
                     " applies to image files only, and no density given is one");
}

}  // namespace kdm::cli
