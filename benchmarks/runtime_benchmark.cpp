// Points per second of runtime queries on one thread (the built-in tile set), against a baseline that
// writes the same number of points into the same buffer with no logic (the practical limit).
// Run: build/benchmarks/runtime_benchmark
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "kdm/runtime/query.h"

namespace {

constexpr double kSide = 8;       // world units; tile_size 1 -> 64 tiles
constexpr double kScale = 15000;  // points per unit area at density 1: ~960k points at density 1

kdm::QueryParams params() {
  kdm::QueryParams q;
  q.x1 = q.y1 = kSide;
  q.scale = kScale;
  return q;
}

std::size_t run_query(const kdm::QueryParams& q, std::vector<kdm::QueryPoint>& buffer) {
  kdm::QueryCursor cursor;
  std::size_t written = 0, total = 0;
  while (kdm::query_points(kdm::Tileset::builtin(), q, buffer.data(), buffer.size(), &written, &cursor) ==
         kdm::Status::kBufferFull)
    total += written;
  return total + written;
}

void report(benchmark::State& state, std::size_t points) {
  state.SetItemsProcessed(static_cast<std::int64_t>(points) * state.iterations());
  state.counters["points"] = static_cast<double>(points);
}

void BM_QueryConstant(benchmark::State& state) {
  std::vector<kdm::QueryPoint> buffer(1 << 20);
  std::size_t n = 0;
  for (auto _ : state) benchmark::DoNotOptimize(n = run_query(params(), buffer));
  report(state, n);
}

void BM_QueryDensityImage(benchmark::State& state) {
  // A 256×256 radial image over the region, dense in the middle.
  std::vector<float> values(256 * 256), mip;
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x)
      values[y * 256 + x] = static_cast<float>(std::exp(-std::hypot(x - 128, y - 128) / 90.0));
  kdm::DensityImage image;
  image.width = image.height = 256;
  image.x1 = image.y1 = kSide;
  image.values = values.data();
  kdm::make_density_max_mip(image, mip);
  kdm::QueryParams q = params();
  q.density.kind = kdm::QueryDensity::Kind::kImage;
  q.density.image = &image;
  std::vector<kdm::QueryPoint> buffer(1 << 20);
  std::size_t n = 0;
  for (auto _ : state) benchmark::DoNotOptimize(n = run_query(q, buffer));
  report(state, n);
}

double ramp(void*, double x, double) {
  return 0.2 + 0.8 * x / kSide;
}

void BM_QueryDensityCallback(benchmark::State& state) {
  kdm::QueryParams q = params();
  q.density.kind = kdm::QueryDensity::Kind::kCallback;
  q.density.callback = ramp;
  q.density.callback_max = 1;
  std::vector<kdm::QueryPoint> buffer(1 << 20);
  std::size_t n = 0;
  for (auto _ : state) benchmark::DoNotOptimize(n = run_query(q, buffer));
  report(state, n);
}

void BM_BaselineWriteSamePoints(benchmark::State& state) {
  std::vector<kdm::QueryPoint> buffer(1 << 20);
  const std::size_t n = run_query(params(), buffer);
  for (auto _ : state) {
    for (std::size_t i = 0; i < n; ++i) {
      kdm::QueryPoint& p = buffer[i & (buffer.size() - 1)];
      p.x = double(i), p.y = double(i), p.id = kdm::PointId{0, 0, static_cast<std::uint32_t>(i)};
    }
    benchmark::ClobberMemory();
  }
  report(state, n);
}

}  // namespace

BENCHMARK(BM_QueryConstant)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QueryDensityImage)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QueryDensityCallback)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BaselineWriteSamePoints)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
