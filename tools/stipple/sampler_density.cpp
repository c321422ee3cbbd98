// A DensitySpec as the full sampler's density, and the analysis's view of it (sampler_density.h).
#include "sampler_density.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace kdm::tools {

gen::Density to_generator_density(const DensitySpec& spec) {
  using Kind = DensitySpec::Kind;
  switch (spec.kind) {
    case Kind::kConstant:
      if (!(spec.constant > 0))
        throw std::invalid_argument(
            "density const:V needs V > 0 here (zero everywhere: nothing to place or compare)");
      return gen::Density::constant();
    case Kind::kRamp:
    case Kind::kRadial: {
      gen::Density d;
      d.function = [spec](const double* u) { return spec.map_at(u[0], u[1]); };
      d.thread_safe = true;
      return d;
    }
    case Kind::kVolume:
      try {
        return gen::Density::from_volume(spec.width, spec.height, spec.depth, spec.values);
      } catch (const gen::InvalidArgument& e) {
        throw std::invalid_argument("volume '" + spec.text + "': " + e.what());
      }
    case Kind::kImage:
      break;
  }
  try {
    return gen::Density::from_values(spec.width, spec.height, spec.values);
  } catch (const gen::InvalidArgument& e) {
    const bool blank = std::string(e.what()).find("zero everywhere") != std::string::npos;
    if (spec.array)  // numbers, not a picture's ink
      throw std::invalid_argument("array '" + spec.text + "': " +
                                  (blank ? "its densities are zero everywhere: nothing to sample (it needs "
                                           "some density > 0)"
                                         : e.what()));
    throw std::invalid_argument("image '" + spec.text + "': " + e.what() +
                                (blank && !spec.inverted ? " (an all-white image has no ink)" : ""));
  }
}

gen::Density to_class_density(const DensitySpec& spec) {
  const bool constant = spec.kind == DensitySpec::Kind::kConstant;
  // A class with no points, whatever its kind (const:0, a blank image); also a constant too small for a
  // float texel (it would have none anyway).
  if (constant ? static_cast<float>(spec.constant) == 0 : !(spec.max_value() > 0)) {
    gen::Density none;
    none.function = [](const double*) { return 0.0; };
    none.thread_safe = true;
    return none;
  }
  if (!constant) return to_generator_density(spec);
  return gen::Density::from_values(1, 1, {static_cast<float>(spec.constant)});
}

std::function<double(double, double)> analysis_density(const gen::Density& density) {
  if (!density.function) return [](double, double) { return 1.0; };
  return [f = density.function](double x, double y) {
    const double u[3] = {x, y, 0.5};  // a third coordinate for a volume's function, though 2D sets refuse it
    return f(u);
  };
}

double mean_energy_per_point(const std::vector<PointSet>& sets, bool torus, const gen::Density& density,
                             int threads, const double* extent) {
  double sum = 0;
  for (const PointSet& set : sets) {
    gen::SamplerOptions o;
    o.dim = set.dim;
    o.domain = torus ? gen::Domain::kTorus : gen::Domain::kBox;
    o.threads = threads;
    if (extent) std::copy(extent, extent + 3, o.extent);
    std::vector<double> coords = set.coords;
    for (double& c : coords) c = std::min(c, std::nextafter(1.0, 0.0));  // writers may round up to 1
    sum += gen::energy_per_point(o, density, coords);
  }
  return sets.empty() ? 0.0 : sum / double(sets.size());
}

}  // namespace kdm::tools
