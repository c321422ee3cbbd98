// Trees, bushes and rocks in chunks around a moving camera, and one large region filled on two threads:
// docs/runtime.md's class and parallel examples as one program, compiled and run by the tests
// (tests/runtime/CMakeLists.txt) so that they stay true. Exit status 0 when every check holds.
#include <kdm/runtime/class_query.h>
#include <kdm/runtime/compact_query.h>
#include <kdm/runtime/density_image.h>
#include <kdm/runtime/parallel_query.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <utility>
#include <vector>

namespace {

constexpr double kChunk = 64;  // world units per chunk side

// Rocks where the ground is steep: a callback with its bounds (the query asks them once per tile).
double rockiness(void*, double x, double y) {
  return 0.25 + 0.25 * std::sin(x * 0.01) * std::cos(y * 0.013);
}
void rockiness_bounds(void*, double, double, double, double, double* lo, double* hi) {
  *lo = 0, *hi = 0.5;
}

// Bushes from a painted 256² map over a 4 km square: texels plus their block bounds, built once.
struct BushMap {
  std::vector<float> texels, mip;
  kdm::DensityImageView view;
  BushMap() : texels(256 * 256) {
    for (int j = 0; j < 256; ++j)
      for (int i = 0; i < 256; ++i) texels[j * 256 + i] = (i / 32 + j / 32) % 2 ? 0.4f : 0.05f;  // meadows
    view.width = view.height = 256;
    view.x0 = view.y0 = -2000, view.x1 = view.y1 = 2000;
    view.values = texels.data();
  }
};

/// The classes of one query: trees first (largest objects first), then bushes, then rocks.
kdm::ClassQueryParams forest(const kdm::DensityImageView& bushes) {
  kdm::ClassQueryParams q;
  q.query.scale = 1, q.query.tile_size = 32;  // a tile expects density · 32² points
  q.class_count = 3;
  q.classes[0].constant = 0.02;  // trees
  q.classes[1].kind = kdm::QueryDensity::Kind::kImage, q.classes[1].image = &bushes;
  q.classes[2].kind = kdm::QueryDensity::Kind::kCallback, q.classes[2].callback = rockiness;
  q.classes[2].bounds = rockiness_bounds, q.classes[2].callback_max = 0.5;
  return q;
}

struct Chunk {
  std::vector<kdm::QueryPoint> points;  // world positions minus the chunk's corner
  std::vector<std::uint8_t> classes;
};

/// One chunk's points and classes, its corner the query's origin (positions stay small far out).
bool load_chunk(const kdm::ClassQueryParams& base, std::int64_t cx, std::int64_t cy, Chunk& chunk) {
  kdm::ClassQueryParams q = base;
  q.query.x0 = q.query.origin_x = double(cx) * kChunk, q.query.x1 = q.query.x0 + kChunk;
  q.query.y0 = q.query.origin_y = double(cy) * kChunk, q.query.y1 = q.query.y0 + kChunk;
  chunk.points.resize(1024), chunk.classes.resize(1024);
  kdm::QueryCursor cursor;
  std::size_t total = 0, n = 0;
  kdm::Status s;
  while ((s = kdm::query_classes(kdm::Tileset::builtin(), q, chunk.points.data() + total,
                                 chunk.classes.data() + total, chunk.points.size() - total, &n, &cursor)) ==
         kdm::Status::kBufferFull) {
    total += n;
    if (total == chunk.points.size()) chunk.points.resize(2 * total), chunk.classes.resize(2 * total);
  }
  if (s != kdm::Status::kOk) return false;  // kdm::status_message(s) says why
  chunk.points.resize(total + n), chunk.classes.resize(total + n);
  return true;
}

bool same(const Chunk& a, const Chunk& b) {
  if (a.points.size() != b.points.size() || a.classes != b.classes) return false;
  for (std::size_t i = 0; i < a.points.size(); ++i)
    if (a.points[i].x != b.points[i].x || a.points[i].y != b.points[i].y ||
        !(a.points[i].id == b.points[i].id))
      return false;
  return true;
}

}  // namespace

int main() {
  BushMap bushes;
  if (kdm::make_density_max_mip(bushes.view, bushes.mip) != kdm::Status::kOk) return 1;
  const kdm::ClassQueryParams q = forest(bushes.view);

  // The camera walks east; chunks within two of it are kept, the others dropped, and a chunk that comes
  // back gives the very same points (ids, classes, positions).
  std::map<std::pair<std::int64_t, std::int64_t>, Chunk> loaded, first_seen;
  std::size_t per_class[3] = {0, 0, 0}, reloaded = 0, fewest_trees = SIZE_MAX;
  for (int step = 0; step < 40; ++step) {
    const double camera_x = 1200 + 20.0 * (step < 20 ? step : 40 - step), camera_y = -300;
    const std::int64_t ccx = std::int64_t(std::floor(camera_x / kChunk)),
                       ccy = std::int64_t(std::floor(camera_y / kChunk));
    for (auto it = loaded.begin(); it != loaded.end();)
      it = std::llabs(it->first.first - ccx) > 2 || std::llabs(it->first.second - ccy) > 2 ? loaded.erase(it)
                                                                                           : std::next(it);
    for (std::int64_t cy = ccy - 2; cy <= ccy + 2; ++cy)
      for (std::int64_t cx = ccx - 2; cx <= ccx + 2; ++cx) {
        if (loaded.count({cx, cy})) continue;
        Chunk chunk;
        if (!load_chunk(q, cx, cy, chunk)) return 1;
        auto seen = first_seen.find({cx, cy});
        if (seen == first_seen.end()) {
          for (std::uint8_t c : chunk.classes) ++per_class[c];
          fewest_trees =
              std::min<std::size_t>(fewest_trees, std::count(chunk.classes.begin(), chunk.classes.end(), 0));
          first_seen.emplace(std::make_pair(cx, cy), chunk);
        } else {
          if (!same(seen->second, chunk)) return 1;
          ++reloaded;
        }
        loaded.emplace(std::make_pair(cx, cy), std::move(chunk));
      }
  }
  std::printf("%zu chunks, %zu loaded again the same; trees %zu, bushes %zu, rocks %zu\n", first_seen.size(),
              reloaded, per_class[0], per_class[1], per_class[2]);
  // Trees expect 0.02 · 64² ≈ 82 per chunk: every chunk seen holds some, and fewer trees than bushes or
  // rocks.
  if (fewest_trees == 0 || per_class[0] < 40 * first_seen.size() || per_class[0] > per_class[2] ||
      reloaded == 0)
    return 1;

  // A large region filled at once: positions only (8 bytes a point), on two threads, the same bits as
  // one thread gives.
  kdm::ClassQueryParams region = q;
  region.query.x0 = -500, region.query.x1 = 500, region.query.y0 = -500, region.query.y1 = 500;
  kdm::ParallelQuery parallel;
  if (parallel.init(2) != kdm::Status::kOk) return 1;
  std::size_t n = 0, needed = 0;
  std::vector<float> xy;
  std::vector<std::uint8_t> classes;
  kdm::Status s = parallel.run(kdm::Tileset::builtin(), region, {nullptr, nullptr}, nullptr, 0, &n,
                               kdm::std_thread_runner(), &needed);  // capacity 0: count the points
  if (s != kdm::Status::kOk && s != kdm::Status::kBufferFull) return 1;
  xy.resize(2 * needed), classes.resize(needed);
  s = parallel.run(kdm::Tileset::builtin(), region, {xy.data(), nullptr}, classes.data(), needed, &n,
                   kdm::std_thread_runner());
  if (s != kdm::Status::kOk || n != needed) return 1;
  std::vector<float> one_xy(xy.size());
  std::vector<std::uint8_t> one_classes(classes.size());
  kdm::QueryCursor cursor;
  std::size_t one = 0;
  do {  // one call stops after 2^24 candidates (kdm::kMaxQueryCandidates), room left or not
    s = kdm::query_classes_compact(kdm::Tileset::builtin(), region, {one_xy.data() + 2 * one, nullptr},
                                   one_classes.data() + one, needed - one, &n, &cursor);
    one += n;
  } while (s == kdm::Status::kBufferFull && one < needed);
  n = needed;
  std::printf("region of %zu points on two threads, %s as one thread's\n", n,
              one == n && one_xy == xy && one_classes == classes ? "the same" : "NOT the same");
  return s == kdm::Status::kOk && one == n && one_xy == xy && one_classes == classes ? 0 : 1;
}
