// Public entry points of the KDM sampler; see kdm/generator/sampler.h and multiscale.h.
#include "kdm/generator/sampler.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <mutex>

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

/// Thrown into a set's sweeps (through its progress hook) when another set has failed: ends it early.
struct SetStopped {};

/// sample_sets(): builds the model once, then runs a copy of it per seed, one set per thread of a team,
/// handing each finished set to keep(k, result) (on the thread that ran it; distinct k never race).
template <int D, class Keep>
void sets_dim(const SamplerOptions& options, const Density& density, const std::vector<std::uint64_t>& seeds,
              Keep&& keep) {
  const auto t0 = std::chrono::steady_clock::now();
  const ModelSetup<D> model = build_model<D>(options, density);
  const double model_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::int64_t count = static_cast<std::int64_t>(seeds.size());
  const int threads = thread_count(options.threads);
  const int team = static_cast<int>(std::min<std::int64_t>(threads, count));
  // Fewer sets than threads (a few large sets): each set shares out the threads left over.
  const int inner = std::max(1, threads / team);
  std::atomic<std::int64_t> next{0}, finished{0};
  std::atomic<bool> stop{false};
  std::mutex error_mutex;
  std::exception_ptr error;
  double reported = 0;  // the calling thread's last progress, kept rising
  run_team(team, team > 1, [&](int thread, int) {
    SamplerOptions o = options;
    o.threads = inner;
    std::int64_t k = 0;
    try {
      while (!stop.load(std::memory_order_relaxed) && (k = next.fetch_add(1)) < count) {
        o.seed = seeds[static_cast<std::size_t>(k)];
        // Between sweeps: stop when another set has failed; on the calling thread, report to the caller.
        o.progress = [&, thread](double f) {
          if (stop.load(std::memory_order_relaxed)) throw SetStopped{};
          if (thread != 0 || !options.progress) return;
          reported = std::max(reported, std::min(1.0, (double(finished.load()) + f) / double(count)));
          options.progress(reported);
        };
        ModelSetup<D> setup = model;  // run_multiscale changes its levels (constrained sampling)
        SampleResult result = run_multiscale<D>(o, setup);
        result.report.model_seconds = model_seconds;
        result.report.threads = inner;
        keep(k, std::move(result));
        ++finished;
      }
    } catch (const SetStopped&) {
    } catch (...) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
      stop = true;
    }
  });
  if (error) std::rethrow_exception(error);
  if (options.progress) options.progress(1.0);
}

/// `options` as sample() runs them (n from initial_points when there are some), checked.
SamplerOptions checked_options(const SamplerOptions& options) {
  if (options.initial_points.empty()) {
    validate_options(options);
    return options;
  }
  if (options.dim != 2 && options.dim != 3) throw InvalidArgument("dimension must be 2 or 3");
  if (options.initial_points.size() % options.dim != 0)
    throw InvalidArgument("initial points: coordinate count is not a multiple of the dimension");
  for (double u : options.initial_points)
    if (!(u >= 0 && u < 1)) throw InvalidArgument("initial points must lie in [0, 1) on every axis");
  SamplerOptions o = options;
  o.n = static_cast<std::int64_t>(options.initial_points.size() / options.dim);
  validate_options(o);
  return o;
}

/// sample_sets() without its output: options checked, the seed count and total size within bounds.
SamplerOptions checked_set_options(const SamplerOptions& options, const std::vector<std::uint64_t>& seeds) {
  SamplerOptions o = checked_options(options);
  if (o.n <= 0)
    throw InvalidArgument(
        "point sets need a point count n > 0 (with a resolution the count could differ "
        "between sets)");
  if (seeds.empty()) throw InvalidArgument("no seeds: give one seed per point set");
  const std::int64_t sets = static_cast<std::int64_t>(seeds.size());
  if (sets > kMaxSampleSets)
    throw InvalidArgument("too many point sets: " + std::to_string(sets) + ", at most " +
                          std::to_string(kMaxSampleSets) + " per call");
  if (o.n > kMaxSampleSetPoints / sets)  // n <= 2^31 and sets <= 2^20: the product fits
    throw InvalidArgument(std::to_string(sets) + " sets of " + std::to_string(o.n) + " points are " +
                          std::to_string(sets * o.n) + " points in all, more than the " +
                          std::to_string(kMaxSampleSetPoints) + " one call returns: ask for fewer at a time");
  return o;
}

}  // namespace

SampleResult sample(const SamplerOptions& options, const Density& density) {
  const SamplerOptions o = checked_options(options);
  return o.dim == 2 ? sample_dim<2>(o, density) : sample_dim<3>(o, density);
}

std::vector<SampleResult> sample_sets(const SamplerOptions& options, const Density& density,
                                      const std::vector<std::uint64_t>& seeds) {
  const SamplerOptions o = checked_set_options(options, seeds);
  std::vector<SampleResult> results(seeds.size());
  auto keep = [&](std::int64_t k, SampleResult&& r) { results[static_cast<std::size_t>(k)] = std::move(r); };
  if (o.dim == 2)
    sets_dim<2>(o, density, seeds, keep);
  else
    sets_dim<3>(o, density, seeds, keep);
  return results;
}

std::vector<SampleReport> sample_sets(const SamplerOptions& options, const Density& density,
                                      const std::vector<std::uint64_t>& seeds, double* points) {
  const SamplerOptions o = checked_set_options(options, seeds);
  if (!points) throw InvalidArgument("sample_sets: the output pointer is null");
  const std::size_t per_set = static_cast<std::size_t>(o.n) * static_cast<std::size_t>(o.dim);
  std::vector<SampleReport> reports(seeds.size());
  auto keep = [&](std::int64_t k, SampleResult&& r) {
    if (r.points.size() != per_set)  // sample() returns exactly n points with n > 0
      throw std::logic_error("sample_sets: a set came out with " + std::to_string(r.size()) +
                             " points, not " + std::to_string(o.n));
    std::copy(r.points.begin(), r.points.end(), points + static_cast<std::size_t>(k) * per_set);
    reports[static_cast<std::size_t>(k)] = std::move(r.report);
  };
  if (o.dim == 2)
    sets_dim<2>(o, density, seeds, keep);
  else
    sets_dim<3>(o, density, seeds, keep);
  return reports;
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
