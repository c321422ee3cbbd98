#include "full_stippler.h"

#include <stdexcept>

#include "kdm/generator/sampler.h"

namespace kdm::tools {

PointSet stipple_full(const DensitySpec& spec, std::int64_t points, double aspect, std::uint64_t seed,
                      int threads) {
  if (spec.kind != DensitySpec::Kind::kImage) throw std::invalid_argument("stippling needs an image");
  gen::SamplerOptions o;
  o.n = points;
  o.domain = gen::Domain::kBox;
  o.extent[0] = aspect;
  o.seed = seed;
  o.threads = threads;
  PointSet set;
  set.dim = 2;
  set.coords = gen::sample(o, gen::Density::from_values(spec.width, spec.height, spec.values)).points;
  return set;
}

}  // namespace kdm::tools
