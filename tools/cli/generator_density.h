// A parsed --density as the full sampler's density (kdm sample, kdm stipple --method full, kdm analyze):
// tools::to_generator_density (tools/stipple/sampler_density.h, which the Python package shares) with its
// refusals as CommandError.
#pragma once

#include "density_spec.h"
#include "kdm/generator/sampler.h"

namespace kdm::cli {

/// The generator's density for `spec`. The full sampler needs some density: const:0 and an image that is
/// zero everywhere are refused with a CommandError (a query of them is simply empty).
gen::Density to_generator_density(const tools::DensitySpec& spec);
/// The same for a class (tools::to_class_density): a constant keeps its value, 0 gives the class no points.
gen::Density to_class_density(const tools::DensitySpec& spec);

}  // namespace kdm::cli
