// Points per second of the full KDM sampler (uniform torus, default temperature) for n = 16k, 64k, 256k
// on 1 and 2 threads, in a process that has already sampled (a warm-up run of the same size and thread
// count): what a program that samples repeatedly gets. A process's first call also starts the worker
// team and faults in its memory; `kdm sample --timing` shows that cost (docs/performance.md).
// BM_TwoThreadsOverOne gives the two-thread speed-up as the median of back-to-back rounds (one thread,
// then two, same seed), which holds still while this machine's speed drifts from one minute to the next,
// and sets it against what two independent one-thread samplers get from the same machine.
// Run: build/benchmarks/sampler_benchmark (medians of 5 runs each).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>
#include <vector>

#include "kdm/generator/sampler.h"

static void BM_SampleUniformTorus(benchmark::State& state) {
  kdm::gen::SamplerOptions o;
  o.n = state.range(0);
  o.threads = static_cast<int>(state.range(1));
  std::uint64_t seed = 1;
  for (auto _ : state) {
    o.seed = seed++;
    benchmark::DoNotOptimize(kdm::gen::sample(o).points.data());
  }
  state.counters["points_per_second"] =
      benchmark::Counter(static_cast<double>(o.n) * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SampleUniformTorus)
    ->ArgsProduct({{16384, 65536, 262144}, {1, 2}})
    ->ArgNames({"n", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinWarmUpTime(0.05)  // one untimed run: every run takes longer than this
    ->MinTime(0.05)        // so one timed run per repetition
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);

static double seconds_to_sample(kdm::gen::SamplerOptions o) {
  const auto start = std::chrono::steady_clock::now();
  benchmark::DoNotOptimize(kdm::gen::sample(o).points.data());
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

static double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5)];
}

// Two independent one-thread samplers at once, each on a std::thread (sample() is reentrant): the
// seconds until both are done.
static double seconds_for_two_side_by_side(kdm::gen::SamplerOptions o) {
  o.threads = 1;
  kdm::gen::SamplerOptions other = o;
  other.seed += 1000003;
  const auto start = std::chrono::steady_clock::now();
  std::thread second([&] { benchmark::DoNotOptimize(kdm::gen::sample(other).points.data()); });
  benchmark::DoNotOptimize(kdm::gen::sample(o).points.data());
  second.join();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Each round times one thread, two threads, and two one-thread samplers side by side (same n, so twice
// the points). Counters, medians over the rounds: speedup = t1/t2, with speedup_q1 and speedup_q3 its
// quartiles; ceiling = 2·t1/t_side_by_side, what this machine gives two samplers that share nothing
// (the most two threads could reach: it counts what the two processors' shared caches, memory and
// host cost); efficiency = t_side_by_side / (2·t2), two threads' points per second as a share of that;
// and the median seconds of each. The benchmark's own time is that of the rounds.
static void BM_TwoThreadsOverOne(benchmark::State& state) {
  kdm::gen::SamplerOptions o;
  o.n = state.range(0);
  o.seed = 1;
  o.threads = 1;
  seconds_to_sample(o);  // warm-up: the first call starts the worker threads and faults in memory
  o.threads = 2;
  seconds_to_sample(o);
  seconds_for_two_side_by_side(o);
  std::vector<double> one, two, side_by_side, ratio, ceiling, efficiency;
  for (auto _ : state) {
    o.threads = 1;
    one.push_back(seconds_to_sample(o));
    o.threads = 2;
    two.push_back(seconds_to_sample(o));
    side_by_side.push_back(seconds_for_two_side_by_side(o));
    ratio.push_back(one.back() / two.back());
    ceiling.push_back(2 * one.back() / side_by_side.back());
    efficiency.push_back(side_by_side.back() / (2 * two.back()));
    ++o.seed;
  }
  state.counters["speedup"] = quantile(ratio, 0.5);
  state.counters["speedup_q1"] = quantile(ratio, 0.25);
  state.counters["speedup_q3"] = quantile(ratio, 0.75);
  state.counters["t1_seconds"] = quantile(one, 0.5);
  state.counters["t2_seconds"] = quantile(two, 0.5);
  state.counters["ceiling"] = quantile(ceiling, 0.5);
  state.counters["efficiency"] = quantile(efficiency, 0.5);
  state.counters["side_by_side_seconds"] = quantile(side_by_side, 0.5);
}
BENCHMARK(BM_TwoThreadsOverOne)->Arg(16384)->Iterations(31)->ArgName("n")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TwoThreadsOverOne)->Arg(65536)->Iterations(15)->ArgName("n")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TwoThreadsOverOne)->Arg(262144)->Iterations(7)->ArgName("n")->Unit(benchmark::kMillisecond);

// Many small sets (Monte Carlo: a set per pixel or per frame), uniform torus, on two threads: rounds of
// `sets` sample() calls one after another, one sample_sets() call with the same seeds (the same points),
// and two std::threads side by side each making half the sample() calls on one thread. A set this small
// runs its sweeps on one thread, so the batch's gain is running a set per thread. Counters, medians over
// the rounds: single_sets_per_second and batch_sets_per_second; speedup, their ratio, with its quartiles;
// ceiling = t_single / t_side_by_side, what this machine gives two threads that share nothing (on a shared
// machine, how much of the second core was there); efficiency = t_side_by_side / t_batch.
static void BM_SmallSets(benchmark::State& state) {
  kdm::gen::SamplerOptions o;
  o.n = state.range(0);
  o.threads = 2;
  const int sets = static_cast<int>(state.range(1));
  std::vector<std::uint64_t> seeds(static_cast<std::size_t>(sets));
  std::uint64_t next_seed = 1;
  auto time = [](auto&& work) {
    const auto start = std::chrono::steady_clock::now();
    work();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  auto calls = [&seeds](kdm::gen::SamplerOptions options, std::size_t from, std::size_t step) {
    for (std::size_t k = from; k < seeds.size(); k += step) {
      options.seed = seeds[k];
      benchmark::DoNotOptimize(kdm::gen::sample(options).points.data());
    }
  };
  benchmark::DoNotOptimize(
      kdm::gen::sample_sets(o, kdm::gen::Density::constant(), {1, 2}).data());  // warm-up
  std::vector<double> single, batch, side_by_side, ratio, ceiling, efficiency;
  for (auto _ : state) {
    for (auto& s : seeds) s = next_seed++;
    single.push_back(time([&] { calls(o, 0, 1); }));
    batch.push_back(time([&] {
      benchmark::DoNotOptimize(kdm::gen::sample_sets(o, kdm::gen::Density::constant(), seeds).data());
    }));
    side_by_side.push_back(time([&] {
      kdm::gen::SamplerOptions one = o;
      one.threads = 1;
      std::thread second([&] { calls(one, 1, 2); });
      calls(one, 0, 2);
      second.join();
    }));
    ratio.push_back(single.back() / batch.back());
    ceiling.push_back(single.back() / side_by_side.back());
    efficiency.push_back(side_by_side.back() / batch.back());
  }
  state.counters["single_sets_per_second"] = sets / quantile(single, 0.5);
  state.counters["batch_sets_per_second"] = sets / quantile(batch, 0.5);
  state.counters["speedup"] = quantile(ratio, 0.5);
  state.counters["speedup_q1"] = quantile(ratio, 0.25);
  state.counters["speedup_q3"] = quantile(ratio, 0.75);
  state.counters["ceiling"] = quantile(ceiling, 0.5);
  state.counters["efficiency"] = quantile(efficiency, 0.5);
}
BENCHMARK(BM_SmallSets)
    ->Args({16, 256})
    ->Args({64, 64})
    ->Args({256, 16})
    ->Args({1024, 4})
    ->ArgNames({"n", "sets"})
    ->Iterations(9)
    ->Unit(benchmark::kMillisecond);

// Linear in n: rounds of n = 16,384 then n = 262,144 on one thread, back to back. Counters: ratio, the
// median of t(262,144)/t(16,384) over the rounds (18 or less is the target; 16 would be exactly linear),
// with its quartiles.
static void BM_LinearInN(benchmark::State& state) {
  kdm::gen::SamplerOptions small, large;
  small.n = 16384;
  large.n = 262144;
  small.threads = large.threads = 1;
  seconds_to_sample(small);  // warm-up, as above
  seconds_to_sample(large);
  std::vector<double> ratio;
  for (auto _ : state) {
    const double t_small = seconds_to_sample(small);
    ratio.push_back(seconds_to_sample(large) / t_small);
    ++small.seed, ++large.seed;
  }
  state.counters["ratio"] = quantile(ratio, 0.5);
  state.counters["ratio_q1"] = quantile(ratio, 0.25);
  state.counters["ratio_q3"] = quantile(ratio, 0.75);
}
BENCHMARK(BM_LinearInN)->Iterations(7)->Unit(benchmark::kMillisecond);

// The count balance's cost on an image density: rounds of n = 65,536 on one thread with the balance
// off, then on (same seed), on a 512×512 radial 1:1000 image. Counter: cost, the median of t(on)/t(off)
// over the rounds, and the points per second with it on.
static void BM_CountBalanceCostOnAnImage(benchmark::State& state) {
  std::vector<float> values(512 * 512);
  for (int y = 0; y < 512; ++y)
    for (int x = 0; x < 512; ++x) {
      const double dx = (x + 0.5) / 512 - 0.5, dy = (y + 0.5) / 512 - 0.5;
      values[y * 512 + x] = static_cast<float>(std::pow(1000.0, -std::min(1.0, 2 * std::hypot(dx, dy))));
    }
  const kdm::gen::Density image = kdm::gen::Density::from_values(512, 512, values);
  kdm::gen::SamplerOptions on, off;
  on.n = off.n = 65536;
  on.threads = off.threads = 1;
  on.domain = off.domain = kdm::gen::Domain::kBox;
  off.count_balance = false;
  auto seconds = [&](const kdm::gen::SamplerOptions& o) {
    const auto start = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(kdm::gen::sample(o, image).points.data());
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  seconds(off), seconds(on);  // warm-up, as above
  std::vector<double> cost, with;
  for (auto _ : state) {
    const double t_off = seconds(off), t_on = seconds(on);
    cost.push_back(t_on / t_off);
    with.push_back(t_on);
    ++on.seed, ++off.seed;
  }
  state.counters["cost"] = quantile(cost, 0.5);
  state.counters["cost_q1"] = quantile(cost, 0.25);
  state.counters["cost_q3"] = quantile(cost, 0.75);
  state.counters["points_per_second"] = double(on.n) / quantile(with, 0.5);
}
BENCHMARK(BM_CountBalanceCostOnAnImage)->Iterations(7)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
