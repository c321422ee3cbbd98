// Public entry points of the KDM sampler; see kdm/generator/sampler.h and multiscale.h.
#include "kdm/generator/sampler.h"

#include <chrono>
#include <cmath>

#include "platform/parallel.h"
#include "sampler/chain.h"
#include "sampler/multiscale.h"
#include "sampler/setup.h"

namespace kdm::gen {
namespace {

template <int D>
SampleResult sample_dim(const SamplerOptions& options, const Density& density) {
  const auto t0 = std::chrono::steady_clock::now();
  ModelSetup<D> setup = build_model<D>(options, density);
  const double model_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  SampleResult result = run_multiscale<D>(options, setup);
  if (options.progress) options.progress(1.0);  // the sweeps' last report stops short of the finish
  result.report.model_seconds = model_seconds;
  result.report.threads = thread_count(options.threads);
  result.report.seconds += model_seconds;
  return result;
}

template <int D>
double energy_dim(const SamplerOptions& options, const Density& density, const std::vector<double>& points) {
  ModelSetup<D> setup = build_model<D>(options, density);
  const DensityGrid<D>& finest = setup.levels.front();
  Chain<D> chain(finest, ChainParams{});
  typename Chain<D>::Scratch scratch;
  const std::size_t n = points.size() / D;
  for (std::size_t j = 0; j < n; ++j) {
    Particle<D> p;
    for (int k = 0; k < D; ++k) {
      const double u = points[j * D + k];
      if (!(u >= 0 && u < 1)) throw InvalidArgument("points must lie in [0, 1) on every axis");
      p.x[k] = u * finest.grid.dims[k];
    }
    if (!finest.grid.canonical(p.x)) throw InvalidArgument("point lies outside the unit domain");
    chain.splat(p, 1.0f, scratch);
  }
  return chain.energy() / double(n);
}

}  // namespace

SampleResult sample(const SamplerOptions& options, const Density& density) {
  if (!options.initial_points.empty()) {
    if (options.dim != 2 && options.dim != 3) throw InvalidArgument("dimension must be 2 or 3");
    if (options.initial_points.size() % options.dim != 0)
      throw InvalidArgument("initial points: coordinate count is not a multiple of the dimension");
    for (double u : options.initial_points)
      if (!(u >= 0 && u < 1)) throw InvalidArgument("initial points must lie in [0, 1) on every axis");
    SamplerOptions o = options;
    o.n = static_cast<std::int64_t>(options.initial_points.size() / options.dim);
    validate_options(o);
    return o.dim == 2 ? sample_dim<2>(o, density) : sample_dim<3>(o, density);
  }
  validate_options(options);
  return options.dim == 2 ? sample_dim<2>(options, density) : sample_dim<3>(options, density);
}

double energy_per_point(const SamplerOptions& options, const Density& density,
                        const std::vector<double>& points) {
  if (options.dim != 2 && options.dim != 3) throw InvalidArgument("dimension must be 2 or 3");
  if (points.empty() || points.size() % options.dim != 0)
    throw InvalidArgument("point set is empty or its coordinate count is not a multiple of the dimension");
  SamplerOptions o = options;
  o.n = static_cast<std::int64_t>(points.size() / options.dim);
  return o.dim == 2 ? energy_dim<2>(o, density, points) : energy_dim<3>(o, density, points);
}

}  // namespace kdm::gen
