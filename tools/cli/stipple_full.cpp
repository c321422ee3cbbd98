#include "stipple_full.h"

#include "commands.h"
#include "generator_density.h"
#include "kdm/generator/sampler.h"

namespace kdm::cli {

tools::PointSet stipple_full(const tools::DensitySpec& spec, std::int64_t points, double aspect,
                             std::uint64_t seed) {
  gen::SamplerOptions o;
  o.n = points;
  o.domain = gen::Domain::kBox;
  o.extent[0] = aspect;
  o.seed = seed;
  tools::PointSet set;
  set.dim = 2;
  try {
    set.coords = gen::sample(o, to_generator_density(spec)).points;
  } catch (const gen::InvalidArgument& e) {
    throw CommandError(e.what());
  }
  return set;
}

}  // namespace kdm::cli
