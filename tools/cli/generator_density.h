// A parsed --density as the full sampler's density (kdm sample, kdm stipple --method full, kdm analyze).
#pragma once

#include "density_spec.h"
#include "kdm/generator/sampler.h"

namespace kdm::cli {

/// The generator's density for `spec`. The full sampler needs some density: const:0 and an image that is
/// zero everywhere are refused with a CommandError (a query of them is simply empty).
gen::Density to_generator_density(const tools::DensitySpec& spec);

}  // namespace kdm::cli
