// The longest single call of a query: each call stops after kMaxQueryCandidates candidates (a tile visited
// counting as kTileCandidates), so a program with a frame budget knows what one call can take. Each case
// runs a whole large query call after call; `worst_call_ms` is the longest call seen, `calls` how many
// one query took. Figures: docs/limits.md ("The longest call").
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <vector>

#include "kdm/runtime/class_query.h"
#include "kdm/runtime/query.h"

namespace {

double zero(void*, double, double) {
  return 0;
}
void zero_bounds(void*, double, double, double, double, double* lo, double* hi) {
  *lo = *hi = 0;
}

double eighth(void*, double, double) {
  return 0.125;
}

enum Case { kConstantDense, kCallbackDense, kCallbackManyTiles, kEmptyTiles };

/// The query of each case: dense tiles (64 × 64 at 32,768 points each, over 2^27 points) or many tiles
/// (4,096 × 4,096 at 32 points each), read at every candidate or bounded to nothing.
kdm::QueryParams query_for(Case c, kdm::QueryMode mode) {
  kdm::QueryParams q;
  q.mode = mode;
  q.x1 = q.y1 = c == kConstantDense || c == kCallbackDense ? 64 : 4096;
  q.scale = c == kConstantDense || c == kCallbackDense ? 32768 : 32;
  if (c != kConstantDense) {
    q.density.kind = kdm::QueryDensity::Kind::kCallback;
    q.density.callback = zero;
    q.density.callback_max = 1;
    if (c == kEmptyTiles) q.density.bounds = zero_bounds;
  }
  return q;
}

/// Runs a whole query call after call (`call(cursor, written)` one call) for each benchmark iteration, and
/// records the longest call and how many one query took. A call that fills the buffer (`room` points) is
/// an error: the buffer must hold more than a call examines, so that calls stop at their bound.
template <class Call>
void longest_calls(benchmark::State& state, std::size_t room, Call&& call) {
  kdm::Tileset::builtin();  // loaded untimed, at its first use
  double worst = 0;
  int calls = 0;
  for (auto _ : state) {
    kdm::QueryCursor cursor;
    std::size_t written = 0;
    calls = 0;
    kdm::Status status;
    do {
      const auto t0 = std::chrono::steady_clock::now();
      status = call(cursor, written);
      worst = std::max(
          worst, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      ++calls;
      if (written == room) state.SkipWithError("a call filled the buffer before its bound");
    } while (status == kdm::Status::kBufferFull);
    if (status != kdm::Status::kOk) state.SkipWithError(kdm::status_message(status));
  }
  state.counters["worst_call_ms"] = worst;
  state.counters["calls"] = calls;
}

void BM_LongestCall(benchmark::State& state) {
  const kdm::QueryParams q =
      query_for(Case(state.range(0)), state.range(1) ? kdm::QueryMode::kSmooth : kdm::QueryMode::kStable);
  // Past the candidates one call examines (640 MB), so that a call stops at its bound, not a full buffer.
  std::vector<kdm::QueryPoint> out((std::size_t(1) << 24) + 1);
  std::fill(out.begin(), out.end(), kdm::QueryPoint{});  // its pages touched once, untimed
  longest_calls(state, out.size(), [&](kdm::QueryCursor& cursor, std::size_t& written) {
    const kdm::Status s =
        kdm::query_points(kdm::Tileset::builtin(), q, out.data(), out.size(), &written, &cursor);
    benchmark::DoNotOptimize(out.data());
    return s;
  });
}

/// Calls that read more than once per candidate: `classes` callback classes of 1/8 each over 1,000 × 1,000
/// units (tiles of 32, scale 30: 30 million points, every candidate emitted), smooth mode with
/// glide_together or stable; the whole query call after call, into a buffer larger than a call examines.
void BM_LongestClassCall(benchmark::State& state) {
  kdm::ClassQueryParams q;
  q.query.x1 = q.query.y1 = 1000, q.query.tile_size = 32, q.query.scale = 30;
  q.query.mode = state.range(1) ? kdm::QueryMode::kSmooth : kdm::QueryMode::kStable;
  q.query.glide_together = state.range(1) != 0;
  q.class_count = static_cast<std::uint32_t>(state.range(0));
  for (std::uint32_t k = 0; k < q.class_count; ++k) {
    q.classes[k].kind = kdm::QueryDensity::Kind::kCallback;
    q.classes[k].callback = eighth, q.classes[k].callback_max = 0.125;
  }
  const std::size_t room = (std::size_t(1) << 24) + 1;
  std::vector<float> xy(2 * room);
  std::vector<std::uint8_t> classes(room);
  std::fill(xy.begin(), xy.end(), 0.f), std::fill(classes.begin(), classes.end(), 0);
  longest_calls(state, room, [&](kdm::QueryCursor& cursor, std::size_t& written) {
    const kdm::Status s = kdm::query_classes_compact(kdm::Tileset::builtin(), q, {xy.data(), nullptr},
                                                     classes.data(), room, &written, &cursor);
    benchmark::DoNotOptimize(xy.data());
    return s;
  });
}

}  // namespace

// Args: the case (0 constant and dense, 1 a callback at every candidate of dense tiles, 2 the same over
// 2^24 tiles of 32 points, 3 a callback bounded to nothing over 2^24 tiles), then smooth mode (0 or 1).
BENCHMARK(BM_LongestCall)
    ->ArgNames({"case", "smooth"})
    ->Args({kConstantDense, 0})
    ->Args({kConstantDense, 1})
    ->Args({kCallbackDense, 0})
    ->Args({kCallbackManyTiles, 0})
    ->Args({kEmptyTiles, 1})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);
// Args: the class count, then smooth mode with glide_together (0 or 1).
BENCHMARK(BM_LongestClassCall)
    ->ArgNames({"classes", "together"})
    ->Args({1, 0})
    ->Args({8, 0})
    ->Args({1, 1})
    ->Args({8, 1})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
