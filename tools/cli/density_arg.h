// --density on the command line: the neutral description of tools/common/density_spec.h, with its
// errors as CommandError. The full sampler's commands convert it with generator_density.h, the runtime's
// with runtime_args.h.
#pragma once

#include <string>

#include "density_spec.h"

namespace kdm::cli {

/// Parses --density (see tools::parse_density_spec). Throws CommandError naming the problem.
tools::DensitySpec parse_density(const std::string& text, double gamma, bool invert);

}  // namespace kdm::cli
