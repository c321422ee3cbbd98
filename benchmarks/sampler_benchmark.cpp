// Points per second of the full KDM sampler (uniform torus, default temperature) for n = 16k, 64k, 256k
// on 1 and 2 threads. Run: build/benchmarks/sampler_benchmark
#include <benchmark/benchmark.h>

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
    ->Iterations(1);

BENCHMARK_MAIN();
