#include "generator_density.h"

#include "commands.h"

namespace kdm::cli {

gen::Density to_generator_density(const tools::DensitySpec& spec) {
  using Kind = tools::DensitySpec::Kind;
  switch (spec.kind) {
    case Kind::kConstant:
      if (!(spec.constant > 0))
        throw CommandError("--density const:V needs V > 0 for the full sampler (it has nothing to sample)");
      return gen::Density::constant();
    case Kind::kRamp:
    case Kind::kRadial: {
      gen::Density d;
      d.function = [spec](const double* u) { return spec.map_at(u[0], u[1]); };
      d.thread_safe = true;
      return d;
    }
    case Kind::kImage:
      break;
  }
  try {
    return gen::Density::from_values(spec.width, spec.height, spec.values);
  } catch (const gen::InvalidArgument& e) {
    throw CommandError("image '" + spec.text + "': " + e.what() +
                       (spec.inverted ? "" : " (an all-white image has no ink)"));
  }
}

}  // namespace kdm::cli
