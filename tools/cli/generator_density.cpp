// --density for the full sampler's commands: the shared conversion, its refusals as CommandError.
#include "generator_density.h"

#include <stdexcept>

#include "commands.h"
#include "sampler_density.h"

namespace kdm::cli {

gen::Density to_generator_density(const tools::DensitySpec& spec) {
  try {
    return tools::to_generator_density(spec);
  } catch (const std::invalid_argument& e) {
    throw CommandError(e.what());
  }
}

gen::Density to_class_density(const tools::DensitySpec& spec) {
  try {
    return tools::to_class_density(spec);
  } catch (const std::invalid_argument& e) {
    throw CommandError(e.what());
  }
}

}  // namespace kdm::cli
