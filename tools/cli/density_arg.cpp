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

}  // namespace kdm::cli
