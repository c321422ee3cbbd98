#include "full_stippler.h"

#include <stdexcept>

#include "kdm/generator/multiclass.h"
#include "kdm/generator/sampler.h"

namespace kdm::tools {
namespace {

/// The sampler's options for `points` dots of an image over [0, aspect] × [0, 1] in a box.
gen::SamplerOptions stipple_options(std::int64_t points, double aspect, std::uint64_t seed, int threads,
                                    const std::function<void(double)>& progress) {
  gen::SamplerOptions o;
  o.progress = progress;
  o.n = points;
  o.domain = gen::Domain::kBox;
  o.extent[0] = aspect;
  o.seed = seed;
  o.threads = threads;
  return o;
}

}  // namespace

PointSet stipple_full(const DensitySpec& spec, std::int64_t points, double aspect, std::uint64_t seed,
                      int threads, const std::function<void(double)>& progress) {
  if (spec.kind != DensitySpec::Kind::kImage) throw std::invalid_argument("stippling needs an image");
  const gen::SamplerOptions o = stipple_options(points, aspect, seed, threads, progress);
  PointSet set;
  set.dim = 2;
  set.coords = gen::sample(o, gen::Density::from_values(spec.width, spec.height, spec.values)).points;
  return set;
}

PointSet stipple_full(const std::vector<const DensitySpec*>& inks, std::int64_t points, double aspect,
                      std::uint64_t seed, int threads, const std::function<void(double)>& progress) {
  if (inks.size() == 1) {
    PointSet set = stipple_full(*inks.front(), points, aspect, seed, threads, progress);
    set.classes.assign(set.size(), 0);
    return set;
  }
  std::vector<gen::Density> densities;
  for (const DensitySpec* spec : inks) {
    if (spec->kind != DensitySpec::Kind::kImage) throw std::invalid_argument("stippling needs an image");
    if (spec->max_value() > 0) {
      densities.push_back(gen::Density::from_values(spec->width, spec->height, spec->values));
    } else {  // an ink no pixel uses: a class without points
      densities.emplace_back();
      densities.back().function = [](const double*) { return 0.0; };
      densities.back().thread_safe = true;
    }
  }
  const gen::SamplerOptions o = stipple_options(points, aspect, seed, threads, progress);
  gen::ClassSample sample = gen::sample_classes(o, densities);
  PointSet set;
  set.dim = 2;
  set.coords = std::move(sample.points);
  set.classes = std::move(sample.classes);
  return set;
}

}  // namespace kdm::tools
