// Points per second of runtime queries on one thread (the built-in tile set), against a baseline that
// writes the same number of points into the same buffer with no logic (the practical limit): each query
// benchmark reports `of_baseline`, its speed as a fraction of the baseline's on the same count, and
// `resident_MB`, the loaded tile set's heap size (Tileset::resident_bytes).
// Run: build/benchmarks/runtime_benchmark
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <utility>
#include <vector>

#include "kdm/runtime/class_image_sums.h"
#include "kdm/runtime/class_query.h"
#include "kdm/runtime/compact_query.h"
#include "kdm/runtime/parallel_query.h"
#include "kdm/runtime/query.h"

// The built-in set's bytes, compiled into the runtime library (generated from tilesets/default.kdmt).
extern const unsigned char kdm_builtin_tileset[];
extern const std::size_t kdm_builtin_tileset_size;

namespace {

constexpr double kSide = 8;       // world units; tile_size 1 -> 64 tiles
constexpr double kScale = 15000;  // points per unit area at density 1: ~960k points at density 1
// The built-in set, loaded before any benchmark runs, so that no benchmark's first round times its loading.
[[maybe_unused]] const kdm::Tileset& kLoadedFirst = kdm::Tileset::builtin();

kdm::QueryParams params() {
  kdm::QueryParams q;
  q.x1 = q.y1 = kSide;
  q.scale = kScale;
  return q;
}

// The query benchmarks take the mode as their argument: smooth:0 stable, smooth:1 smooth (gliding).
kdm::QueryParams params(const benchmark::State& state) {
  kdm::QueryParams q = params();
  q.mode = state.range(0) ? kdm::QueryMode::kSmooth : kdm::QueryMode::kStable;
  return q;
}

std::size_t run_query(const kdm::Tileset& tiles, const kdm::QueryParams& q,
                      std::vector<kdm::QueryPoint>& buffer) {
  kdm::QueryCursor cursor;
  std::size_t written = 0, total = 0;
  while (kdm::query_points(tiles, q, buffer.data(), buffer.size(), &written, &cursor) ==
         kdm::Status::kBufferFull)
    total += written;
  return total + written;
}

std::size_t run_query(const kdm::QueryParams& q, std::vector<kdm::QueryPoint>& buffer) {
  return run_query(kdm::Tileset::builtin(), q, buffer);
}

// Writes `n` points into `buffer` the way a query does, with no logic: the practical limit.
void write_baseline(std::vector<kdm::QueryPoint>& buffer, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    kdm::QueryPoint& p = buffer[i & (buffer.size() - 1)];
    p.x = double(i), p.y = double(i), p.id = kdm::PointId{0, 0, static_cast<std::uint32_t>(i)};
  }
  benchmark::ClobberMemory();
}

// Seconds the baseline takes for `n` points: the fastest of a few runs.
double baseline_seconds(std::size_t n) {
  std::vector<kdm::QueryPoint> buffer(1 << 20);
  double best = HUGE_VAL;
  for (int run = 0; run < 7; ++run) {
    const auto t0 = std::chrono::steady_clock::now();
    write_baseline(buffer, n);
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

void report(benchmark::State& state, std::size_t points) {
  state.SetItemsProcessed(static_cast<std::int64_t>(points) * state.iterations());
  state.counters["points"] = static_cast<double>(points);
  state.counters["resident_MB"] = double(kdm::Tileset::builtin().resident_bytes()) / (1 << 20);
}

// Runs `query` (returning its point count) as the benchmark loop and reports its speed against the baseline.
template <class Query>
void run_against_baseline(benchmark::State& state, Query&& query) {
  std::size_t n = 0;
  double seconds = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(n = query());
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  report(state, n);
  state.counters["of_baseline"] = baseline_seconds(n) / (seconds / double(state.iterations()));
}

// Rounds of `timed` (returning its point count, which `n` receives; its time is the benchmark's) alternating
// with `reference`: the reference's time over the timed query's.
template <class Timed, class Reference>
double alternate(benchmark::State& state, std::size_t& n, Timed&& timed, Reference&& reference) {
  double seconds = 0, reference_seconds = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(n = timed());
    const auto t1 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(reference());
    const auto t2 = std::chrono::steady_clock::now();
    seconds += std::chrono::duration<double>(t1 - t0).count();
    reference_seconds += std::chrono::duration<double>(t2 - t1).count();
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
  }
  return reference_seconds / seconds;
}

void BM_QueryConstant(benchmark::State& state) {
  std::vector<kdm::QueryPoint> buffer(1 << 20);
  run_against_baseline(state, [&] { return run_query(params(state), buffer); });
}

void BM_QueryDensityImage(benchmark::State& state) {
  // A 256×256 radial image over the region, dense in the middle.
  std::vector<float> values(256 * 256), mip;
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x)
      values[y * 256 + x] = static_cast<float>(std::exp(-std::hypot(x - 128, y - 128) / 90.0));
  kdm::DensityImageView image;
  image.width = image.height = 256;
  image.x1 = image.y1 = kSide;
  image.values = values.data();
  kdm::make_density_max_mip(image, mip);
  kdm::QueryParams q = params(state);
  q.density.kind = kdm::QueryDensity::Kind::kImage;
  q.density.image = &image;
  std::vector<kdm::QueryPoint> buffer(1 << 20);
  run_against_baseline(state, [&] { return run_query(q, buffer); });
}

double ramp(void*, double x, double) {
  return 0.2 + 0.8 * x / kSide;
}

// The ramp's bounds over a rectangle (QueryDensity::bounds).
void ramp_bounds(void*, double x0, double, double x1, double, double* lo, double* hi) {
  *lo = ramp(nullptr, std::max(x0, 0.0), 0), *hi = ramp(nullptr, std::min(x1, kSide), 0);
}

// The ramp at n positions (QueryDensity::batch_callback), in a loop the compiler vectorises.
void ramp_batch(void*, std::size_t n, const double* x, const double*, double* out) {
  for (std::size_t i = 0; i < n; ++i) out[i] = 0.2 + 0.8 * x[i] / kSide;
}

// The benchmark's query with the ramp by callback (args: smooth; bounds, 1 to give its bounds too).
kdm::QueryParams ramp_params(benchmark::State& state) {
  kdm::QueryParams q = params(state);
  q.density.kind = kdm::QueryDensity::Kind::kCallback;
  q.density.callback = ramp;
  q.density.callback_max = 1;
  if (state.range(1)) q.density.bounds = ramp_bounds;
  return q;
}

// Args: smooth; bounds.
void BM_QueryDensityCallback(benchmark::State& state) {
  const kdm::QueryParams q = ramp_params(state);
  std::vector<kdm::QueryPoint> buffer(1 << 20);
  run_against_baseline(state, [&] { return run_query(q, buffer); });
}

// Smooth mode gliding together (QueryParams::glide_together) against gliding by each point's own density,
// rounds alternating (args: density, 0 the ramp by callback, 1 with its bounds, 2 a 256² image of it):
// `of_own` is the own-density query's time over this one's.
void BM_QueryGlideTogether(benchmark::State& state) {
  kdm::QueryParams q = params();
  q.mode = kdm::QueryMode::kSmooth;
  q.density.kind = kdm::QueryDensity::Kind::kCallback, q.density.callback = ramp, q.density.callback_max = 1;
  if (state.range(0) == 1) q.density.bounds = ramp_bounds;
  std::vector<float> values(256 * 256), mip;
  kdm::DensityImageView image;
  if (state.range(0) == 2) {
    for (int y = 0; y < 256; ++y)
      for (int x = 0; x < 256; ++x)
        values[y * 256 + x] = static_cast<float>(ramp(nullptr, (x + 0.5) / 256 * kSide, 0));
    image.width = image.height = 256, image.x1 = image.y1 = kSide, image.values = values.data();
    kdm::make_density_max_mip(image, mip);
    q.density = kdm::QueryDensity{};
    q.density.kind = kdm::QueryDensity::Kind::kImage, q.density.image = &image;
  }
  kdm::QueryParams own = q;
  q.glide_together = true;
  std::vector<kdm::QueryPoint> buffer(1 << 20), other(1 << 20);
  std::size_t n = 0;
  const double ratio = alternate(
      state, n, [&] { return run_query(q, buffer); }, [&] { return run_query(own, other); });
  report(state, n);
  state.counters["of_own"] = ratio;
}

// Three classes at 1 : 2 : 4 of the constant density (args: smooth; ramp: 0 constants, 1 three ramps by
// callback, 2 the same with their bounds (and the sum's), 3 the ramps and bounds from one joint call
// (ClassQueryParams::joint), 4 and 5 as 2 and 3 with a texture over the ramps, 6 the ramps as images against
// an image of their sum, 7 and 8 as 4 and 5 by batch functions against a batch callback of the sum;
// compact, 1 for both queries
// into float positions) against one class at their sum, which emits the same points (its callback computes
// the three ramps, as a caller's sum would): rounds alternate between the two, and `of_one_class` is the
// one-class query's time over the three-class query's.
struct RampClass {
  int k;          // the class: its ramp is (0.2 … 1) · 2^k / 7
  bool textured;  // times texture()
};
// Eight octaves of sines, a factor in [0.95, 1.05]: about as costly as a lookup in a caller's biome map,
// which a joint density computes once for all classes.
double texture(double x, double y) {
  double t = 0;
  for (int i = 0; i < 8; ++i) t += std::sin(x * double(1 << i) * 1.7 + y * (i + 1));
  return 1 + 0.05 * t / 8;
}
// How many times a class's ramp was evaluated, by either query, counted in an untimed round only: a count
// in memory, incremented call after call, is a chain of dependent stores that would slow the three calls a
// point of the class query makes more than the one call of the one-class query.
bool counting_reads = false;
std::uint64_t ramp_class_reads = 0;
double plain_ramp(int k, double x) {
  if (counting_reads) ++ramp_class_reads;
  return (0.2 + 0.8 * x / kSide) * double(1 << k) / 7;
}
double ramp_class(void* user, double x, double y) {
  const auto& c = *static_cast<const RampClass*>(user);
  return c.textured ? plain_ramp(c.k, x) * texture(x, y) : plain_ramp(c.k, x);
}
// The one-class query's density is the classes' sum, evaluated as a caller would: the texture once, then
// each class's value (the same products, added in the same order, as the class query's).
double ramp_sum(void* user, double x, double y) {
  const auto* c = static_cast<const RampClass*>(user);
  const double t = c->textured ? texture(x, y) : 1;
  return plain_ramp(0, x) * t + plain_ramp(1, x) * t + plain_ramp(2, x) * t;
}
void ramp_class_batch(void* user, std::size_t n, const double* x, const double* y, double* out) {
  for (std::size_t i = 0; i < n; ++i) out[i] = ramp_class(user, x[i], y[i]);
}
void ramp_sum_batch(void* user, std::size_t n, const double* x, const double* y, double* out) {
  for (std::size_t i = 0; i < n; ++i) out[i] = ramp_sum(user, x[i], y[i]);
}
void ramp_class_bounds(void* user, double x0, double, double x1, double, double* lo, double* hi) {
  const auto& c = *static_cast<const RampClass*>(user);
  *lo = plain_ramp(c.k, x0) * (c.textured ? 0.95 : 1), *hi = plain_ramp(c.k, x1) * (c.textured ? 1.05 : 1);
}
void ramp_sum_bounds(void* user, double x0, double, double x1, double, double* lo, double* hi) {
  const auto* c = static_cast<const RampClass*>(user);
  *lo = (plain_ramp(0, x0) + plain_ramp(1, x0) + plain_ramp(2, x0)) * (c->textured ? 0.95 : 1);
  *hi = (plain_ramp(0, x1) + plain_ramp(1, x1) + plain_ramp(2, x1)) * (c->textured ? 1.05 : 1);
}
// The three ramps from one call (ClassQueryParams::joint), the texture once, and their bounds.
void ramp_classes(void* user, double x, double y, double* values) {
  const auto* c = static_cast<const RampClass*>(user);
  const double t = c->textured ? texture(x, y) : 1;
  for (int k = 0; k < 3; ++k) values[k] = plain_ramp(k, x) * t;
}
void ramp_classes_batch(void* user, std::size_t n, const double* x, const double* y, double* values) {
  double v[3];
  for (std::size_t i = 0; i < n; ++i) {
    ramp_classes(user, x[i], y[i], v);
    for (int k = 0; k < 3; ++k) values[k * n + i] = v[k];
  }
}
void ramp_classes_bounds(void* user, double x0, double y0, double x1, double y1, double* lo, double* hi) {
  const auto* c = static_cast<const RampClass*>(user);
  for (int k = 0; k < 3; ++k)
    ramp_class_bounds(const_cast<RampClass*>(c + k), x0, y0, x1, y1, lo + k, hi + k);
}

void BM_QueryThreeClasses(benchmark::State& state) {
  static const RampClass kPlain[3] = {{0, false}, {1, false}, {2, false}},
                         kTextured[3] = {{0, true}, {1, true}, {2, true}};
  const int ramp = static_cast<int>(state.range(1));
  const bool by_callback = (ramp >= 1 && ramp <= 5) || ramp == 7 || ramp == 8;
  const RampClass* user = ramp >= 4 ? kTextured : kPlain;
  const double most = by_callback && ramp >= 4 ? 1.05 : 1;  // the ramp's maximum, times the texture's
  kdm::ClassQueryParams cq;
  cq.query = params(state);
  cq.class_count = 3;
  kdm::QueryParams one = params(state);
  for (int k = 0; k < 3; ++k) {
    kdm::QueryDensity& d = cq.classes[k];
    d.constant = double(1 << k) / 7;
    if (by_callback) {
      d.kind = kdm::QueryDensity::Kind::kCallback, d.callback = ramp_class;
      d.user = const_cast<RampClass*>(user + k), d.callback_max = d.constant * most;
      if (ramp >= 2) d.bounds = ramp_class_bounds;
      if (ramp == 7) d.callback = nullptr, d.batch_callback = ramp_class_batch;
    }
  }
  if (ramp == 3 || ramp == 5 || ramp == 8) {
    cq.joint.densities = ramp_classes, cq.joint.bounds = ramp_classes_bounds;
    if (ramp == 8) cq.joint.densities = nullptr, cq.joint.batch_densities = ramp_classes_batch;
    cq.joint.user = const_cast<RampClass*>(user);
    for (int k = 0; k < 3; ++k) cq.joint.max[k] = cq.classes[k].callback_max;
  }
  // ramp 6: each class the ramp as a 256² image, against one image of their sum; 9 the same images by
  // their running sums (ClassImageSums).
  std::vector<float> values[4], mips[4];
  kdm::DensityImageView images[4];
  kdm::ClassImageSums sums;
  if (ramp == 6 || ramp == 9) {
    for (int k = 0; k < 4; ++k) {
      values[k].resize(256 * 256);
      for (int x = 0; x < 256; ++x) {
        const double r = 0.2 + 0.8 * (x + 0.5) / 256;
        for (int y = 0; y < 256; ++y)
          values[k][y * 256 + x] = static_cast<float>(k < 3 ? r * (1 << k) / 7 : r);
      }
      images[k].width = images[k].height = 256, images[k].x1 = images[k].y1 = kSide;
      images[k].values = values[k].data();
      kdm::make_density_max_mip(images[k], mips[k]);
      kdm::QueryDensity& d = k < 3 ? cq.classes[k] : one.density;
      d.kind = kdm::QueryDensity::Kind::kImage, d.image = &images[k];
    }
    const kdm::DensityImageView* classes[3] = {&images[0], &images[1], &images[2]};
    if (ramp == 9 && sums.build(classes, 3) == kdm::Status::kOk) cq.image_sums = &sums;
  }
  if (by_callback) {
    one.density.kind = kdm::QueryDensity::Kind::kCallback, one.density.callback = ramp_sum;
    one.density.user = const_cast<RampClass*>(user);
    one.density.callback_max = most;
    if (ramp >= 2) one.density.bounds = ramp_sum_bounds;
    if (ramp == 7 || ramp == 8) one.density.callback = nullptr, one.density.batch_callback = ramp_sum_batch;
  }
  std::vector<kdm::QueryPoint> buffer(1 << 20);
  std::vector<std::uint8_t> classes(buffer.size());
  std::vector<float> xy(2 * buffer.size());
  const kdm::CompactPoints compact{xy.data(), nullptr};
  const bool is_compact = state.range(2) != 0;
  // Runs the query to its end (resumed while the buffer fills); the points emitted.
  auto run = [&](auto&& call) {
    kdm::QueryCursor cursor;
    std::size_t written = 0, total = 0;
    while (call(&written, &cursor) == kdm::Status::kBufferFull) total += written;
    return total + written;
  };
  auto run_class = [&] {
    return run([&](std::size_t* written, kdm::QueryCursor* cursor) {
      return is_compact ? kdm::query_classes_compact(kdm::Tileset::builtin(), cq, compact, classes.data(),
                                                     buffer.size(), written, cursor)
                        : kdm::query_classes(kdm::Tileset::builtin(), cq, buffer.data(), classes.data(),
                                             buffer.size(), written, cursor);
    });
  };
  auto run_one = [&] {
    return run([&](std::size_t* written, kdm::QueryCursor* cursor) {
      return is_compact ? kdm::query_points_compact(kdm::Tileset::builtin(), one, compact, buffer.size(),
                                                    written, cursor)
                        : kdm::query_points(kdm::Tileset::builtin(), one, buffer.data(), buffer.size(),
                                            written, cursor);
    });
  };
  counting_reads = true, ramp_class_reads = 0;
  const std::size_t n = run_class();
  const std::uint64_t reads = ramp_class_reads;
  run_one();
  const std::uint64_t one_reads = ramp_class_reads - reads;
  counting_reads = false;
  double seconds = 0, one_seconds = 0;
  for (auto _ : state) {
    auto t0 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(run_class());
    benchmark::DoNotOptimize(classes.data());
    const auto t1 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(run_one());
    const auto t2 = std::chrono::steady_clock::now();
    seconds += std::chrono::duration<double>(t1 - t0).count();
    one_seconds += std::chrono::duration<double>(t2 - t1).count();
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());  // the class query's
  }
  report(state, n);
  state.counters["of_one_class"] = one_seconds / seconds;
  // Class densities read per point emitted (ramps only), by the class query and by the one-class query.
  if (by_callback) {
    state.counters["reads_per_point"] = double(reads) / double(n);
    state.counters["one_class_reads_per_point"] = double(one_reads) / double(n);
  }
}

// Smooth mode past the top level: a constant density whose depth-d subtiles hold 15,000 expected points
// each (as depth 0's tiles do in BM_QueryConstant), over 8 × 8 of them: the same ~960k points, emitted
// by tiles m^d times smaller, with the hand-over's ancestors above them. BM_QueryRampAtDepth: the same
// with BM_QueryDensityCallback's ramp over the region (0.2 to 1, ~576k points).
// KDM_BENCHMARK_TILESET names another set (one with a hand-over) to measure instead of the built-in one.
double ramp_side = kSide;
double ramp_at_depth(void*, double x, double) {
  return 0.2 + 0.8 * x / ramp_side;
}
void ramp_batch_at_depth(void*, std::size_t n, const double* x, const double*, double* out) {
  for (std::size_t i = 0; i < n; ++i) out[i] = 0.2 + 0.8 * x[i] / ramp_side;
}

// The query at depth state.range(0) into `q`, from `tiles`; false (the state told) if the set has no
// hand-over.
bool at_depth(benchmark::State& state, bool ramp, const kdm::Tileset*& tiles, kdm::QueryParams& q) {
  static kdm::Tileset loaded;
  const char* path = std::getenv("KDM_BENCHMARK_TILESET");
  if (path && loaded.empty() && kdm::Tileset::load_file(path, loaded) != kdm::Status::kOk)
    return state.SkipWithError("KDM_BENCHMARK_TILESET does not load"), false;
  tiles = path ? &loaded : &kdm::Tileset::builtin();
  const double m = std::sqrt(kdm::query_density_limit(*tiles, kdm::QueryMode::kSmooth) /
                             tiles->max_points_per_tile());  // m^4
  if (!(m > 1)) return state.SkipWithError("the tile set has no hand-over"), false;
  const double zoom = std::pow(std::sqrt(std::sqrt(m)), double(state.range(0)));  // m^d
  q = params();
  q.mode = kdm::QueryMode::kSmooth;
  q.x1 = q.y1 = kSide / zoom;
  q.scale = kScale * zoom * zoom;
  if (ramp) {
    ramp_side = q.x1;
    q.density.kind = kdm::QueryDensity::Kind::kCallback;
    q.density.callback = ramp_at_depth;
    q.density.callback_max = 1;
  }
  return true;
}

void query_at_depth(benchmark::State& state, bool ramp) {
  const kdm::Tileset* tiles = nullptr;
  kdm::QueryParams q;
  if (!at_depth(state, ramp, tiles, q)) return;
  std::vector<kdm::QueryPoint> buffer(1 << 20);
  run_against_baseline(state, [&] { return run_query(*tiles, q, buffer); });
}

void BM_QuerySmoothAtDepth(benchmark::State& state) {
  query_at_depth(state, false);
}

void BM_QueryRampAtDepth(benchmark::State& state) {
  query_at_depth(state, true);
}

// BM_QueryRampAtDepth's ramp read through batch_callback, in rounds alternating with the scalar callback;
// `of_scalar` as BM_QueryBatchCallback's.
void BM_QueryBatchRampAtDepth(benchmark::State& state) {
  const kdm::Tileset* tiles = nullptr;
  kdm::QueryParams scalar;
  if (!at_depth(state, true, tiles, scalar)) return;
  kdm::QueryParams batch = scalar;
  batch.density.callback = nullptr, batch.density.batch_callback = ramp_batch_at_depth;
  std::vector<kdm::QueryPoint> buffer(1 << 20);
  std::size_t n = 0;
  const double of_scalar = alternate(
      state, n, [&] { return run_query(*tiles, batch, buffer); },
      [&] { return run_query(*tiles, scalar, buffer); });
  report(state, n);
  state.counters["of_scalar"] = of_scalar;
}

void BM_BaselineWriteSamePoints(benchmark::State& state) {
  std::vector<kdm::QueryPoint> buffer(1 << 20);
  const std::size_t n = run_query(params(), buffer);
  for (auto _ : state) write_baseline(buffer, n);
  report(state, n);
}

// The compact output (compact_query.h) into reused 65,536-point arrays (args: smooth; keys, 1 to write
// them too; ramp, 1 for BM_QueryDensityCallback's ramp instead of the constant density, 2 with its bounds),
// in rounds that alternate with a plain copy of as many points into the same arrays (memcpy): `of_plain_copy`
// is the copy's time over the query's. BM_QueryConstantReusedBuffer: QueryPoint records into a reused
// 65,536-point buffer. Copies n points into `out` from arrays of as many (`from`, 65,536 points), 65,536 at a
// time, as memcpy does: the bytes the query writes, with no logic.
void plain_copy(const kdm::CompactPoints& from, const kdm::CompactPoints& out, std::size_t n) {
  for (std::size_t done = 0; done < n; done += 1 << 16) {
    const std::size_t count = std::min<std::size_t>(n - done, 1 << 16);
    std::memcpy(out.xy, from.xy, count * 2 * sizeof(float));
    if (out.keys) std::memcpy(out.keys, from.keys, count * sizeof(std::uint64_t));
    benchmark::ClobberMemory();
  }
}

void BM_QueryCompact(benchmark::State& state) {
  kdm::QueryParams q = params(state);
  q.x1 = q.y1 = double(state.range(3));  // tile_size 1: the region's side in tiles
  if (state.range(2)) {
    q.density.kind = kdm::QueryDensity::Kind::kCallback;
    q.density.callback = ramp;
    q.density.callback_max = 1;
    if (state.range(2) == 2) q.density.bounds = ramp_bounds;
  }
  std::vector<float> xy(2 << 16), source_xy(2 << 16, 1.0f);
  std::vector<std::uint64_t> keys(1 << 16), source_keys(1 << 16, 1);
  const kdm::CompactPoints out{xy.data(), state.range(1) ? keys.data() : nullptr};
  const kdm::CompactPoints source{source_xy.data(), source_keys.data()};
  std::size_t n = 0;
  double seconds = 0, copy_seconds = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    kdm::QueryCursor cursor;
    std::size_t written = 0;
    n = 0;
    while (kdm::query_points_compact(kdm::Tileset::builtin(), q, out, keys.size(), &written, &cursor) ==
           kdm::Status::kBufferFull)
      n += written;
    n += written;
    benchmark::ClobberMemory();
    const auto t1 = std::chrono::steady_clock::now();
    plain_copy(source, out, n);
    const auto t2 = std::chrono::steady_clock::now();
    seconds += std::chrono::duration<double>(t1 - t0).count();
    copy_seconds += std::chrono::duration<double>(t2 - t1).count();
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());  // the query's, not the copy's
  }
  report(state, n);
  state.counters["of_plain_copy"] = copy_seconds / seconds;
}

// BM_QueryParallel's rounds: plain(), one query on this thread into output 0, then run(query, k, &n[k]) with
// one worker into output 0 and two into output 1 (false if the query did not fit), and same(n) comparing
// the two outputs' n points. Two workers' time is the iteration's; `speedup` is one worker's time over
// two's, `of_one_query` the plain query's over two workers'.
template <class Plain, class Run, class Same>
void parallel_rounds(benchmark::State& state, Plain&& plain, Run&& run, Same&& same) {
  kdm::ParallelQuery workers[2];
  workers[0].init(1), workers[1].init(2);
  std::size_t n[2] = {0, 0};
  double seconds[2] = {0, 0}, plain_seconds = 0;
  auto timed = [](double& total, auto&& f) {
    const auto t0 = std::chrono::steady_clock::now();
    const bool ok = f();
    total += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return ok;
  };
  for (auto _ : state) {
    timed(plain_seconds, [&] { return plain(), true; });
    const double before = seconds[1];
    for (int k = 0; k < 2; ++k)
      if (!timed(seconds[k], [&] { return run(workers[k], k, &n[k]); }))
        return state.SkipWithError("the query did not fit");
    state.SetIterationTime(seconds[1] - before);
    if (n[0] != n[1] || !same(n[0])) return state.SkipWithError("one and two workers gave different bits");
  }
  report(state, n[1]);
  state.counters["speedup"] = seconds[0] / seconds[1];
  state.counters["of_one_query"] = plain_seconds / seconds[1];
  state.counters["two_workers_Mps"] = double(n[1]) * double(state.iterations()) / seconds[1] / 1e6;
}

// One query of about 4 million points (16 × 16 tiles at 15,000 points each, BM_QueryConstant's density)
// filled at once by ParallelQuery (args: smooth; compact, 1 for float positions and keys instead of
// QueryPoint records; ramp, 1 for BM_QueryDensityCallback's ramp), on two workers in rounds alternating
// with one worker and with one plain query into the same memory: `speedup` is one worker's time over two's,
// `of_one_query` the plain query's over two workers'. Every round checks one and two workers' bits agree.
void BM_QueryParallel(benchmark::State& state) {
  kdm::QueryParams q = params(state);
  q.x1 = q.y1 = 2 * kSide;
  if (state.range(2)) {
    q.density.kind = kdm::QueryDensity::Kind::kCallback;
    q.density.callback = ramp;
    q.density.callback_max = 1;
  }
  const bool compact = state.range(1) != 0;
  const std::size_t capacity = std::size_t(1) << 22;
  std::vector<kdm::QueryPoint> points[2];
  std::vector<float> xy[2];
  std::vector<std::uint64_t> keys[2];
  for (int k = 0; k < 2; ++k) {
    if (compact)
      xy[k].resize(2 * capacity), keys[k].resize(capacity);
    else
      points[k].resize(capacity);
  }
  auto plain = [&] {  // query_points / query_points_compact into the same memory
    kdm::QueryCursor cursor;
    std::size_t written = 0, total = 0;
    kdm::Status s;
    do {
      s = compact ? kdm::query_points_compact(
                        kdm::Tileset::builtin(), q,
                        kdm::CompactPoints{xy[0].data() + 2 * total, keys[0].data() + total},
                        capacity - total, &written, &cursor)
                  : kdm::query_points(kdm::Tileset::builtin(), q, points[0].data() + total, capacity - total,
                                      &written, &cursor);
      total += written;
    } while (s == kdm::Status::kBufferFull && total < capacity);
  };
  auto run = [&](kdm::ParallelQuery& pq, int k, std::size_t* n) {
    const kdm::TaskRunner threads = kdm::std_thread_runner();
    return (compact ? pq.run(kdm::Tileset::builtin(), q, kdm::CompactPoints{xy[k].data(), keys[k].data()},
                             capacity, n, threads)
                    : pq.run(kdm::Tileset::builtin(), q, points[k].data(), capacity, n, threads)) ==
           kdm::Status::kOk;
  };
  auto same = [&](std::size_t n) {
    return compact ? std::memcmp(xy[0].data(), xy[1].data(), 2 * n * sizeof(float)) == 0 &&
                         std::memcmp(keys[0].data(), keys[1].data(), n * 8) == 0
                   : std::memcmp(points[0].data(), points[1].data(), n * sizeof(kdm::QueryPoint)) == 0;
  };
  parallel_rounds(state, plain, run, same);
}

// BM_QueryParallel's region as three classes at 1 : 2 : 4 of its density (args: smooth; ramp, 1 for the
// plain ramps by callback with their bounds, as BM_QueryThreeClasses' ramp 2), into the compact output with
// each point's class: two workers in rounds alternating with one worker and with one query_classes_compact.
void BM_QueryParallelClasses(benchmark::State& state) {
  static const RampClass kPlain[3] = {{0, false}, {1, false}, {2, false}};
  kdm::ClassQueryParams q;
  q.query = params(state);
  q.query.x1 = q.query.y1 = 2 * kSide;
  q.class_count = 3;
  for (int k = 0; k < 3; ++k) {
    kdm::QueryDensity& d = q.classes[k];
    d.constant = double(1 << k) / 7;
    if (state.range(1)) {
      d.kind = kdm::QueryDensity::Kind::kCallback, d.callback = ramp_class, d.bounds = ramp_class_bounds;
      d.user = const_cast<RampClass*>(kPlain + k), d.callback_max = d.constant;
    }
  }
  const std::size_t capacity = std::size_t(1) << 22;
  std::vector<float> xy[2] = {std::vector<float>(2 * capacity), std::vector<float>(2 * capacity)};
  std::vector<std::uint8_t> classes[2] = {std::vector<std::uint8_t>(capacity),
                                          std::vector<std::uint8_t>(capacity)};
  auto plain = [&] {  // query_classes_compact into the same memory
    kdm::QueryCursor cursor;
    std::size_t written = 0, total = 0;
    kdm::Status s;
    do {
      s = kdm::query_classes_compact(kdm::Tileset::builtin(), q,
                                     kdm::CompactPoints{xy[0].data() + 2 * total, nullptr},
                                     classes[0].data() + total, capacity - total, &written, &cursor);
      total += written;
    } while (s == kdm::Status::kBufferFull && total < capacity);
  };
  auto run = [&](kdm::ParallelQuery& pq, int k, std::size_t* n) {
    return pq.run(kdm::Tileset::builtin(), q, kdm::CompactPoints{xy[k].data(), nullptr}, classes[k].data(),
                  capacity, n, kdm::std_thread_runner()) == kdm::Status::kOk;
  };
  auto same = [&](std::size_t n) {
    return std::memcmp(xy[0].data(), xy[1].data(), 2 * n * sizeof(float)) == 0 &&
           std::memcmp(classes[0].data(), classes[1].data(), n) == 0;
  };
  parallel_rounds(state, plain, run, same);
}

// The benchmark's region moved by half a tile in x and y, so that its sides cut 32 of the 81 tiles it meets,
// as a view or a chunk that ignores the tiling does (args: smooth; compact, 1 for float positions instead of
// QueryPoint records), both into reused 65,536-point buffers, in rounds alternating with the aligned region:
// `of_aligned` is the aligned query's time over this one's.
void BM_QueryUnaligned(benchmark::State& state) {
  const kdm::QueryParams aligned = params(state);
  kdm::QueryParams moved = aligned;
  moved.x0 += 0.5, moved.x1 += 0.5, moved.y0 += 0.5, moved.y1 += 0.5;
  const bool compact = state.range(1) != 0;
  std::vector<kdm::QueryPoint> buffer(1 << 16);
  std::vector<float> xy(2 * buffer.size());
  auto run = [&](const kdm::QueryParams& q) {
    if (!compact) return run_query(q, buffer);
    kdm::QueryCursor cursor;
    std::size_t written = 0, total = 0;
    while (kdm::query_points_compact(kdm::Tileset::builtin(), q, kdm::CompactPoints{xy.data(), nullptr},
                                     buffer.size(), &written, &cursor) == kdm::Status::kBufferFull)
      total += written;
    return total + written;
  };
  std::size_t n = 0;
  const double of_aligned = alternate(
      state, n, [&] { return run(moved); }, [&] { return run(aligned); });
  report(state, n);
  state.counters["of_aligned"] = of_aligned;
}

// The ramp read through batch_callback (args: smooth; bounds), in rounds alternating with the same query
// through callback; `of_scalar`: the scalar query's time over the batch query's (the same points).
void BM_QueryBatchCallback(benchmark::State& state) {
  const kdm::QueryParams scalar = ramp_params(state);
  kdm::QueryParams batch = scalar;
  batch.density.callback = nullptr, batch.density.batch_callback = ramp_batch;
  std::vector<kdm::QueryPoint> buffer(1 << 20);
  std::size_t n = 0;
  const double of_scalar = alternate(
      state, n, [&] { return run_query(batch, buffer); }, [&] { return run_query(scalar, buffer); });
  report(state, n);
  state.counters["of_scalar"] = of_scalar;
}

// The benchmark's 8 × 8-tile region queried as a grid of square chunks (args: smooth; chunk, the chunk's side
// in hundredths of a tile), from a corner 0.3 tiles off the tiling, into a reused 65,536-point buffer, as an
// engine streams chunks that ignore the tiles; chunks of 0.1 tile cover 8 × 8 tiles' worth of area at 32 × 32
// chunks. `of_one_query`: one query over the chunks' whole area, timed in the same rounds, over the chunks'.
void BM_QueryChunks(benchmark::State& state) {
  const double side = double(state.range(1)) / 100;
  const int per_side = std::min(32, int(std::lround(kSide / side)));
  kdm::QueryParams whole = params(state);
  whole.x0 = whole.y0 = 0.3, whole.x1 = whole.y1 = 0.3 + per_side * side;
  std::vector<kdm::QueryPoint> buffer(1 << 16);
  std::size_t n = 0;
  double one_seconds = 0, seconds = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    n = 0;
    for (int cy = 0; cy < per_side; ++cy)
      for (int cx = 0; cx < per_side; ++cx) {
        kdm::QueryParams q = whole;
        q.x0 = whole.x0 + cx * side, q.x1 = q.x0 + side, q.y0 = whole.y0 + cy * side, q.y1 = q.y0 + side;
        n += run_query(q, buffer);
      }
    const auto t1 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(run_query(whole, buffer));
    const auto t2 = std::chrono::steady_clock::now();
    seconds += std::chrono::duration<double>(t1 - t0).count();
    one_seconds += std::chrono::duration<double>(t2 - t1).count();
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
  }
  report(state, n);
  state.counters["chunks"] = double(per_side) * per_side;
  state.counters["of_one_query"] = one_seconds / seconds;
}

// What one call costs on its own (args: smooth; side, the region's side in hundredths of a tile, 0 for a
// point-sized region): calls over 35 places inside the first tiles, off the tiling, into a reused buffer.
void BM_QueryPerCall(benchmark::State& state) {
  const double side = state.range(1) ? double(state.range(1)) / 100 : 1e-6;
  kdm::QueryParams q = params(state);
  std::vector<kdm::QueryPoint> buffer(1 << 12);
  std::size_t n = 0, calls = 0;
  for (auto _ : state) {
    q.x0 = 0.3 + double(calls % 7) * 0.11, q.y0 = 0.35 + double(calls % 5) * 0.13;
    q.x1 = q.x0 + side, q.y1 = q.y0 + side;
    n += run_query(q, buffer), ++calls;
  }
  state.counters["points_per_call"] = double(n) / double(calls);
}

void BM_QueryConstantReusedBuffer(benchmark::State& state) {
  std::vector<kdm::QueryPoint> buffer(1 << 16);
  std::size_t n = 0;
  for (auto _ : state) benchmark::DoNotOptimize(n = run_query(params(), buffer));
  report(state, n);
}

// What the first Tileset::builtin() costs: decoding the built-in set's bytes (checksums, zstd, parsing,
// validation, emission thresholds). Each iteration loads them afresh.
void BM_LoadBuiltinSet(benchmark::State& state) {
  for (auto _ : state) {
    kdm::Tileset loaded;
    const kdm::Status s = kdm::Tileset::load_memory(kdm_builtin_tileset, kdm_builtin_tileset_size, loaded);
    if (s != kdm::Status::kOk) state.SkipWithError(kdm::status_message(s));
    benchmark::DoNotOptimize(loaded.resident_bytes());
  }
}

}  // namespace

BENCHMARK(BM_QueryConstant)->ArgName("smooth")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QueryDensityImage)->ArgName("smooth")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QueryDensityCallback)
    ->ArgNames({"smooth", "bounds"})
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QueryGlideTogether)
    ->ArgName("density")
    ->DenseRange(0, 2)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QueryThreeClasses)
    ->ArgNames({"smooth", "ramp", "compact"})
    ->ArgsProduct({{0, 1}, {0, 1, 2, 3, 4, 5, 6, 7, 8, 9}, {0, 1}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QuerySmoothAtDepth)->ArgName("depth")->DenseRange(0, 4)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QueryRampAtDepth)->ArgName("depth")->DenseRange(0, 4)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BaselineWriteSamePoints)->Unit(benchmark::kMillisecond);
// Both modes of: the second argument off and on at a constant density, then on with the ramp.
void modes_output_density(benchmark::internal::Benchmark* b) {
  for (const auto& [output, ramp] : {std::pair{0, 0}, std::pair{1, 0}, std::pair{1, 1}})
    for (int smooth : {0, 1}) b->Args({smooth, output, ramp});
}
void compact_cases(benchmark::internal::Benchmark* b) {
  for (const auto& [keys, ramp] : {std::pair{0, 0}, std::pair{1, 0}, std::pair{1, 1}, std::pair{1, 2}})
    for (int smooth : {0, 1}) b->Args({smooth, keys, ramp, std::int64_t(kSide)});
  // Four times the side: an eighth of the tiles where a sixteenth lie on the border, where smooth mode's
  // points are tested one by one (the inside's speed, nearly).
  for (int smooth : {0, 1}) b->Args({smooth, 0, 0, 4 * std::int64_t(kSide)});
}
BENCHMARK(BM_QueryCompact)
    ->ArgNames({"smooth", "keys", "ramp", "tiles"})
    ->Apply(compact_cases)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QueryParallel)
    ->ArgNames({"smooth", "compact", "ramp"})
    ->Apply(modes_output_density)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QueryParallelClasses)
    ->ArgNames({"smooth", "ramp"})
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QueryChunks)
    ->ArgNames({"smooth", "chunk"})
    ->ArgsProduct({{0, 1}, {100, 25, 10}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QueryPerCall)
    ->ArgNames({"smooth", "side"})
    ->ArgsProduct({{0, 1}, {0, 10}})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_QueryUnaligned)
    ->ArgNames({"smooth", "compact"})
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QueryBatchCallback)
    ->ArgNames({"smooth", "bounds"})
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QueryBatchRampAtDepth)
    ->ArgName("depth")
    ->DenseRange(1, 2)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QueryConstantReusedBuffer)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LoadBuiltinSet)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
