// A neutral density (density_spec.h) as the full sampler's: what `kdm sample`, `kdm analyze` and the Python
// package share, so that the same --density gives the same bits everywhere. Part of kdm::stipple, the
// tools' library that links the generator.
#pragma once

#include <functional>
#include <vector>

#include "density_spec.h"
#include "kdm/generator/sampler.h"
#include "point_io.h"

namespace kdm::tools {

/// The generator's density for `spec`. The full sampler needs some density: const:0 and an image that is
/// zero everywhere are refused with std::invalid_argument, a one-line message (a query of them is simply
/// empty).
gen::Density to_generator_density(const DensitySpec& spec);

/// A class's density for the full sampler (gen::sample_classes): as to_generator_density, but a constant
/// keeps its value, as a one-texel image, since a class's share of the points follows it, and a density
/// of 0 (const:0, a blank image) is a class with no points.
gen::Density to_class_density(const DensitySpec& spec);

/// `density` as the point-set analysis reads it: a function of (x, y) in the unit square (1 for a constant).
std::function<double(double, double)> analysis_density(const gen::Density& density);

/// E/n of each set under the KDM model for its own count, domain and density, averaged over the sets
/// (gen::energy_per_point). `extent`: the domain's relative sides x y z (gen::SamplerOptions::extent;
/// null: a square or cube). Throws gen::InvalidArgument for sets the model cannot take.
double mean_energy_per_point(const std::vector<PointSet>& sets, bool torus, const gen::Density& density,
                             int threads = 0, const double* extent = nullptr);

}  // namespace kdm::tools
