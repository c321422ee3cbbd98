// Fuzz target: query_points on the built-in tile set, with every parameter taken from the input: per
// parameter a selector bit picks a raw double (NaN, infinities and extremes included) or a small value
// from one byte; the density is a constant, a 4×4 image (raw or byte texels) or a callback; the mode
// stable or smooth, gliding together or not (past the top level smooth queries descend into subtiles). The
// work per input is bounded: when the region would hold more than kBudget candidate points it is cut to a few
// tiles and then the scale lowered, or past the top level the region shrunk (huge regions and scales are the
// unit tests' business). Checks:
//  - every point, origin added back, lies in [x0, x1) × [y0, y1) and in the tile its id names (in smooth
//    mode within a side of that tile, at the id's depth: points glide);
//  - points come in the documented order (depth-0 tiles row by row), and ids are unique;
//  - collecting with a buffer of 1-8 points, resuming from the cursor, gives exactly the points of one
//    call with a large buffer, in the same order; kBufferFull only with a full buffer; a finished cursor
//    gives no more points;
//  - splitting the region at some x gives the same points (query(A ∪ B) = query(A) ⊎ query(B));
//  - query_classes with the density and an empty class (two halves of a constant) gives the same points,
//    and a callback's two classes read in batches or from one joint function (of one position or many) the
//    same points and classes;
//  - query_points_compact gives the same points as floats, with their keys;
//  - a callback read through batch_callback gives the same points, in batches of 1 to kDensityBatch;
//  - an image class beside an empty one, by their running sums (ClassImageSums), gives the same points;
//  - ParallelQuery (two workers run in turn) gives the same points, and the same classes.
// A failed check aborts.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <tuple>
#include <utility>
#include <vector>

#include "kdm/runtime/class_image_sums.h"
#include "kdm/runtime/class_query.h"
#include "kdm/runtime/compact_query.h"
#include "kdm/runtime/parallel_query.h"
#include "kdm/runtime/query.h"

namespace {

// Candidate points per input, about (a call examines them all): small, so that runs reach 10^4 inputs/s.
constexpr double kBudget = 256;
constexpr std::size_t kBigCapacity = 4096;  // far above kBudget: the thresholds are only about c + ½

struct Reader {
  const std::uint8_t* data;
  std::size_t size;
  std::uint32_t raw_bits = 0;  // selector: bit i set = the i-th number is a raw double
  int index = 0;
  std::uint8_t byte() {
    if (size == 0) return 0;
    --size;
    return *data++;
  }
  double raw() {
    double v = 0;
    if (size >= sizeof v) {
      std::memcpy(&v, data, sizeof v);
      data += sizeof v, size -= sizeof v;
    }
    return v;
  }
  // The next number: raw, or `small(byte)`.
  template <class Small>
  double next(Small small) {
    return (raw_bits >> index++) & 1 ? raw() : small(byte());
  }
};

double coordinate(std::uint8_t b) {
  return static_cast<std::int8_t>(b) / 8.0;
}

double callback(void* user, double x, double y) {
  const double v = *static_cast<const double*>(user);
  return v * (x - y);  // any value, hostile ones included
}

// The callback at n positions (QueryDensity::batch_callback); a batch out of its bounds fails.
void batch_callback(void* user, std::size_t n, const double* x, const double* y, double* out) {
  if (n < 1 || n > kdm::kDensityBatch) std::abort();
  for (std::size_t i = 0; i < n; ++i) out[i] = callback(user, x[i], y[i]);
}

// Two classes from one call (ClassQueryParams::joint): the callback's value and nothing.
void joint_callback(void* user, double x, double y, double* values) {
  values[0] = callback(user, x, y), values[1] = 0;
}

// The same at n positions (JointClassDensity::batch_densities); a batch out of its bounds fails.
void joint_batch_callback(void* user, std::size_t n, const double* x, const double* y, double* values) {
  if (n < 1 || n > kdm::kDensityBatch) std::abort();
  for (std::size_t i = 0; i < n; ++i) values[i] = callback(user, x[i], y[i]), values[n + i] = 0;
}

// The check that failed, by its line: a crash input then says which guarantee it breaks.
[[noreturn]] void fail_at(int line) {
  std::fprintf(stderr, "fuzz_query: the check at fuzz_query.cpp:%d failed\n", line);
  std::abort();
}
#define fail() fail_at(__LINE__)

// A ParallelQuery of two workers, which in_turn() runs one after the other on this thread.
kdm::ParallelQuery& two_workers() {
  static kdm::ParallelQuery parallel;
  static const kdm::Status ready = parallel.init(2);
  if (ready != kdm::Status::kOk) fail();
  return parallel;
}
kdm::TaskRunner in_turn() {
  kdm::TaskRunner r;
  r.run = [](void*, void (*task)(void*, std::size_t), void* context, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) task(context, i);
  };
  return r;
}

// `out` (a query output) plus `origin` lies in [lo, hi): exact when there is no origin, else up to the
// rounding of subtracting and adding it back.
bool inside(double out, double origin, double lo, double hi) {
  const double w = out + origin;
  const double tol = origin == 0 ? 0 : 4 * DBL_EPSILON * std::max(std::fabs(out), std::fabs(origin));
  return w >= lo - tol && w < hi + tol;
}

// Within `margin` tile sides of tile t (of side `size`).
bool in_tile(double out, double origin, std::int64_t t, double size, double margin) {
  const double w = out + origin, lo = (double(t) - margin) * size, hi = (double(t + 1) + margin) * size;
  const double tol = 4 * DBL_EPSILON * (std::fabs(out) + std::fabs(origin) + std::fabs(lo) + std::fabs(hi));
  return w >= lo - tol && w <= hi + tol;
}

// Subtiles per side of the built-in set's tiles past the top level: limit / top = m^(2 · kMaxQueryDepth).
const double kSubtiles =
    std::round(std::pow(kdm::query_density_limit(kdm::Tileset::builtin(), kdm::QueryMode::kSmooth) /
                            kdm::Tileset::builtin().max_points_per_tile(),
                        1.0 / (2 * kdm::kMaxQueryDepth)));

// Tile coordinate t at `depth` as a depth-0 tile's (floor division by m, depth times).
std::int64_t at_depth_zero(std::int64_t t, std::uint32_t depth) {
  const auto m = static_cast<std::int64_t>(kSubtiles);
  for (std::uint32_t d = 0; d < depth; ++d) t = t >= 0 ? t / m : -((-t + m - 1) / m);
  return t;
}

auto order_key(const kdm::QueryPoint& p) {
  return std::make_tuple(p.id.depth, p.id.tile_y, p.id.tile_x, p.id.rank);
}

bool same(const kdm::QueryPoint& a, const kdm::QueryPoint& b) {
  return std::memcmp(&a.x, &b.x, sizeof a.x) == 0 && std::memcmp(&a.y, &b.y, sizeof a.y) == 0 && a.id == b.id;
}

// A query's points from one call with a large buffer (reused: nothing is cleared per input).
struct Points {
  kdm::QueryPoint data[kBigCapacity];
  std::size_t size = 0;
  kdm::Status status = kdm::Status::kOk;
  kdm::QueryProblem problem;
  // False if they do not fit (the input is then over budget).
  bool query(const kdm::QueryParams& q) {
    kdm::QueryCursor cursor;
    status = kdm::query_points(kdm::Tileset::builtin(), q, data, kBigCapacity, &size, &cursor, &problem);
    return status != kdm::Status::kBufferFull;
  }
  const kdm::QueryPoint& operator[](std::size_t i) const { return data[i]; }
};

// Whether a query descends past the top level (smooth mode over the top level's count).
bool descends(const kdm::QueryParams& q, double peak) {
  return q.mode == kdm::QueryMode::kSmooth &&
         peak * q.tile_size * q.tile_size * q.scale > kdm::Tileset::builtin().max_points_per_tile();
}

// Expected candidate points of a query, about: per tile, the overhead and every rank whose threshold
// (~ c + ½) is below the tile's density bound, at most `peak` (the density's maximum anywhere); past the
// top level the points the region holds (the ancestors' ranks outside it are passed over, cheaply). 0
// when the query is refused or empty before any work (with a margin: the rounding may differ from the
// query's).
double work(const kdm::QueryParams& q, double peak) {
  const double S = q.tile_size, limit = kdm::query_density_limit(kdm::Tileset::builtin(), q.mode);
  if (!(std::isfinite(q.x0) && std::isfinite(q.x1) && std::isfinite(q.y0) && std::isfinite(q.y1) &&
        std::isfinite(S) && std::isfinite(q.scale) && S > 0 && q.scale > 0 && q.x1 > q.x0 && q.y1 > q.y0))
    return 0;
  double density = peak;  // the bound the query checks against its limit
  if (q.density.kind == kdm::QueryDensity::Kind::kImage)
    density = q.density.image->max_over(q.x0, q.y0, q.x1, q.y1);
  const double area_scale = S * S * q.scale;
  if (!(density * area_scale <= limit * 1.000001 + 1)) return 0;  // refused: density too high
  const double tiles =
      (std::ceil(q.x1 / S) - std::floor(q.x0 / S)) * (std::ceil(q.y1 / S) - std::floor(q.y0 / S));
  if (!(tiles <= double(kdm::kMaxQueryTiles) * 1.000001)) return 0;  // refused: too many tiles
  if (descends(q, peak)) return tiles * 8 + (q.x1 - q.x0) * (q.y1 - q.y0) * peak * q.scale;
  return tiles * (8 + std::min(peak * area_scale, limit));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 3) return 0;
  const int kind = data[0] % 3;
  const std::size_t capacity = 1 + (data[0] >> 2) % 8;
  const bool smooth = (data[0] >> 5) & 1;
  Reader r{data + 3, size - 3, std::uint32_t(data[1]) | std::uint32_t(data[2]) << 8};
  kdm::QueryParams q;
  q.mode = smooth ? kdm::QueryMode::kSmooth : kdm::QueryMode::kStable;
  q.glide_together = (data[0] >> 6) & 1;
  q.x0 = r.next(coordinate), q.y0 = r.next(coordinate), q.x1 = r.next(coordinate), q.y1 = r.next(coordinate);
  q.origin_x = r.next(coordinate), q.origin_y = r.next(coordinate);
  q.tile_size = r.next([](std::uint8_t b) { return b / 64.0; });
  q.scale = r.next([](std::uint8_t b) { return b ? std::exp2((b - 128) / 8.0) : 0.0; });
  double value = r.next([](std::uint8_t b) { return static_cast<std::int8_t>(b) / 16.0; });
  const double callback_max = r.next([](std::uint8_t b) { return b / 16.0; });
  kdm::DensityImageView image;
  image.x0 = r.next(coordinate), image.y0 = r.next(coordinate);
  image.x1 = r.next(coordinate), image.y1 = r.next(coordinate);
  const bool raw_texels = (r.raw_bits >> 14) & 1;
  const double split = r.byte() / 256.0;
  float texels[4 * 4];
  for (float& t : texels) {
    if (raw_texels) {
      t = 0;
      if (r.size >= sizeof t) std::memcpy(&t, r.data, sizeof t), r.data += sizeof t, r.size -= sizeof t;
    } else {
      t = r.byte() / 64.0f;
    }
  }
  image.width = image.height = 4;
  image.values = texels;
  static std::vector<float> mip;  // reused: no allocation per input
  double peak = 0;                // the density's maximum anywhere (as the query bounds it)
  switch (kind) {
    case 0:
      q.density.constant = value;
      peak = value > 0 ? value : 0;
      break;
    case 1:
      if (kdm::make_density_max_mip(image, mip) != kdm::Status::kOk) return 0;
      q.density.kind = kdm::QueryDensity::Kind::kImage;
      q.density.image = &image;
      peak = *std::max_element(mip.begin(), mip.end());
      break;
    default:
      q.density.kind = kdm::QueryDensity::Kind::kCallback;
      q.density.callback = callback;
      q.density.user = &value;
      q.density.callback_max = peak = callback_max;
  }

  // Bound the work: a few tiles at most, then a lower scale (past the top level a smaller region).
  if (work(q, peak) > kBudget) {
    q.x1 = std::min(q.x1, q.x0 + 2 * q.tile_size);
    q.y1 = std::min(q.y1, q.y0 + 2 * q.tile_size);
    if (const double w = work(q, peak); w > kBudget) {
      if (descends(q, peak)) {
        const double f = std::sqrt(kBudget / w);
        q.x1 = q.x0 + (q.x1 - q.x0) * f, q.y1 = q.y0 + (q.y1 - q.y0) * f;
      } else {
        q.scale *= kBudget / w;
      }
    }
    if (work(q, peak) > kBudget) return 0;
  }

  static Points all, a, b;
  if (!all.query(q) || all.status != kdm::Status::kOk) return 0;  // over budget, or refused

  for (std::size_t i = 0; i < all.size; ++i) {
    const kdm::QueryPoint& p = all[i];
    if (!inside(p.x, q.origin_x, q.x0, q.x1) || !inside(p.y, q.origin_y, q.y0, q.y1)) fail();
    if (p.id.depth > (smooth ? kdm::kMaxQueryDepth : 0)) fail();
    const double side = q.tile_size / std::pow(kSubtiles, double(p.id.depth)), margin = smooth ? 1 : 0;
    if (!in_tile(p.x, q.origin_x, p.id.tile_x, side, margin) ||
        !in_tile(p.y, q.origin_y, p.id.tile_y, side, margin))
      fail();
    const kdm::Tile* tile = kdm::tile_of(kdm::Tileset::builtin(), p.id);
    if (!tile || p.id.rank >= tile->points.size()) fail();
    // Documented order: depth-0 tiles row by row (within a tile, ranks ascending or cell by cell, and
    // past the top level subtile by subtile).
    const auto tile_row = [](const kdm::PointId& id) {
      return std::make_pair(at_depth_zero(id.tile_y, id.depth), at_depth_zero(id.tile_x, id.depth));
    };
    if (i > 0 && tile_row(p.id) < tile_row(all[i - 1].id)) fail();
  }
  {  // every id once
    static std::tuple<std::uint32_t, std::int64_t, std::int64_t, std::uint32_t> ids[kBigCapacity];
    for (std::size_t i = 0; i < all.size; ++i) ids[i] = order_key(all[i]);
    std::sort(ids, ids + all.size);
    if (std::adjacent_find(ids, ids + all.size) != ids + all.size) fail();
  }

  // Resumed with a small buffer: the same points in the same order.
  kdm::QueryPoint small[8];
  kdm::QueryCursor cursor;
  std::size_t at = 0, written = 0;
  for (std::size_t calls = 0;; ++calls) {
    if (calls > all.size / capacity + 1) fail();  // no progress
    const kdm::Status status =
        kdm::query_points(kdm::Tileset::builtin(), q, small, capacity, &written, &cursor);
    if (status != kdm::Status::kOk && status != kdm::Status::kBufferFull) fail();
    if (status == kdm::Status::kBufferFull && written != capacity) fail();  // under kMaxQueryCandidates
    if (at + written > all.size) fail();
    for (std::size_t i = 0; i < written; ++i)
      if (!same(small[i], all[at + i])) fail();
    at += written;
    if (status == kdm::Status::kOk) break;
  }
  if (at != all.size) fail();
  if (kdm::query_points(kdm::Tileset::builtin(), q, small, capacity, &written, &cursor) != kdm::Status::kOk ||
      written != 0)
    fail();

  // The callback read in batches: the same points in the same order.
  if (kind == 2) {
    kdm::QueryParams batched = q;
    batched.density.callback = nullptr, batched.density.batch_callback = batch_callback;
    static Points through_batches;
    if (!through_batches.query(batched) || through_batches.status != all.status ||
        through_batches.size != all.size)
      fail();
    for (std::size_t i = 0; i < all.size; ++i)
      if (!same(through_batches[i], all[i])) fail();
  }

  // Two classes: the density and nothing (a constant density: two halves) give the same points, each
  // with a class that exists.
  {
    kdm::ClassQueryParams cq;
    cq.query = q;
    cq.class_count = 2;
    cq.classes[0] = q.density;
    cq.classes[1].constant = 0;
    if (kind == 0 && value / 2 + value / 2 == value)  // exact halves
      cq.classes[0].constant = cq.classes[1].constant = value / 2;
    static Points classed;
    static std::uint8_t classes[kBigCapacity];
    kdm::QueryCursor class_cursor;
    classed.status = kdm::query_classes(kdm::Tileset::builtin(), cq, classed.data, classes, kBigCapacity,
                                        &classed.size, &class_cursor);
    // Accepted as the one-class query was, except that an empty region, which query_points answers with
    // no points before it looks at the density, still has its classes' densities checked.
    const bool empty = !(q.x1 > q.x0 && q.y1 > q.y0 && q.scale > 0);
    if (classed.status == kdm::Status::kInvalidArgument && !empty) fail();
    if (classed.status == kdm::Status::kOk) {
      if (classed.size != all.size) fail();
      for (std::size_t i = 0; i < all.size; ++i)
        if (!same(classed[i], all[i]) || classes[i] > (kind == 0 ? 1 : 0)) fail();
    }
    // Over two workers: the same points (in the units' order) with the same classes.
    if (classed.status == kdm::Status::kOk) {
      static kdm::QueryPoint units[kBigCapacity];
      static std::uint8_t unit_classes[kBigCapacity];
      static std::pair<std::tuple<std::uint32_t, std::int64_t, std::int64_t, std::uint32_t>, std::uint8_t>
          expected[kBigCapacity], got[kBigCapacity];
      std::size_t n = 0;
      if (two_workers().run(kdm::Tileset::builtin(), cq, units, unit_classes, kBigCapacity, &n, in_turn()) !=
              kdm::Status::kOk ||
          n != classed.size)
        fail();
      for (std::size_t i = 0; i < n; ++i)
        expected[i] = {order_key(classed[i]), classes[i]}, got[i] = {order_key(units[i]), unit_classes[i]};
      std::sort(expected, expected + n), std::sort(got, got + n);
      if (!std::equal(expected, expected + n, got)) fail();
    }
    // The same two classes, the callback read in batches: the same status, points and classes.
    if (kind == 2) {
      kdm::ClassQueryParams batched = cq;
      batched.classes[0].callback = nullptr, batched.classes[0].batch_callback = batch_callback;
      static Points through_batches;
      static std::uint8_t batch_classes[kBigCapacity];
      kdm::QueryCursor batch_cursor;
      through_batches.status =
          kdm::query_classes(kdm::Tileset::builtin(), batched, through_batches.data, batch_classes,
                             kBigCapacity, &through_batches.size, &batch_cursor);
      if (through_batches.status != classed.status || through_batches.size != classed.size) fail();
      for (std::size_t i = 0; i < classed.size; ++i)
        if (!same(through_batches[i], classed[i]) || batch_classes[i] != classes[i]) fail();
    }
    // The same two classes from one joint callback: the same status, points and classes.
    if (kind == 2) {
      cq.joint.densities = joint_callback, cq.joint.user = &value;
      cq.joint.max[0] = callback_max, cq.joint.max[1] = 0;
      static Points joint;
      static std::uint8_t joint_classes[kBigCapacity];
      for (const bool batch : {false, true}) {  // then from one joint function of many positions
        if (batch) cq.joint.densities = nullptr, cq.joint.batch_densities = joint_batch_callback;
        kdm::QueryCursor joint_cursor;
        joint.status = kdm::query_classes(kdm::Tileset::builtin(), cq, joint.data, joint_classes,
                                          kBigCapacity, &joint.size, &joint_cursor);
        if (callback_max == 0) {  // every class bounded by 0: refused as bounds left unset
          if (joint.status != kdm::Status::kInvalidArgument) fail();
          continue;
        }
        if (joint.status != classed.status || joint.size != classed.size) fail();
        for (std::size_t i = 0; i < joint.size; ++i)
          if (!same(joint[i], classed[i]) || joint_classes[i] != classes[i]) fail();
      }
    }
    // An image and an empty one by their running sums (ClassImageSums): the same status and points, all
    // of class 0, one worker or two.
    if (kind == 1) {
      static float zeros[4 * 4] = {};
      static kdm::ClassImageSums sums;
      kdm::DensityImageView empty = image;
      empty.values = zeros;
      const kdm::DensityImageView* images[2] = {&image, &empty};
      if (sums.build(images, 2) != kdm::Status::kOk) fail();  // make_density_max_mip took the image
      kdm::ClassQueryParams by_sums = cq;
      by_sums.image_sums = &sums;
      static Points summed;
      static std::uint8_t summed_classes[kBigCapacity];
      kdm::QueryCursor sums_cursor;
      summed.status = kdm::query_classes(kdm::Tileset::builtin(), by_sums, summed.data, summed_classes,
                                         kBigCapacity, &summed.size, &sums_cursor);
      if (summed.status != kdm::Status::kOk || summed.size != all.size) fail();  // exactly `all`'s query
      for (std::size_t i = 0; i < summed.size; ++i)
        if (!same(summed[i], all[i]) || summed_classes[i] != 0) fail();
      std::size_t n = 0;
      if (two_workers().run(kdm::Tileset::builtin(), by_sums, summed.data, summed_classes, kBigCapacity, &n,
                            in_turn()) != kdm::Status::kOk ||
          n != all.size || std::count(summed_classes, summed_classes + n, 0) != std::ptrdiff_t(n))
        fail();
    }
  }

  // The compact output: the same points, as floats within 2^-21 · (|position| + tile size) + 2^-50 ·
  // |world coordinate| (the double's own rounding far out), with their keys.
  {
    static float xy[2 * kBigCapacity];
    static std::uint64_t keys[kBigCapacity];
    kdm::QueryCursor compact_cursor;
    std::size_t size = 0;
    const kdm::Status status = kdm::query_points_compact(
        kdm::Tileset::builtin(), q, kdm::CompactPoints{xy, keys}, kBigCapacity, &size, &compact_cursor);
    // Refused by name, and only where a float's step reaches a tile (2^23 tiles), beyond a float, or past
    // a quarter of the densest points' spacing (2^21 spacings, within rounding of the limit). Refused
    // surely where the region holds points; a region with none (empty, a sliver rounded onto no tile
    // column, too sparse for any tile) may be answered before the check, so either answer passes there.
    const double far = std::max({std::fabs(q.x0 - q.origin_x), std::fabs(q.x1 - q.origin_x),
                                 std::fabs(q.y0 - q.origin_y), std::fabs(q.y1 - q.origin_y)});
    double density = peak;
    if (q.density.kind == kdm::QueryDensity::Kind::kImage)
      density = q.density.image->max_over(q.x0, q.y0, q.x1, q.y1);
    const double per_tile = density * q.tile_size * q.tile_size * q.scale;
    const double spacings = std::ldexp(q.tile_size / std::sqrt(per_tile), 21);
    const bool past_tiles = far > 1e38 || (q.tile_size > 0 && far > std::ldexp(q.tile_size, 23));
    const bool must = all.size > 0 && (past_tiles || far > spacings * 1.000001);
    const bool too_far = status == kdm::Status::kInvalidArgument;
    if ((must && !too_far) || (too_far && !past_tiles && !(far > spacings * 0.999999))) fail();
    if (!too_far && (status != all.status || size != all.size)) fail();
    for (std::size_t i = 0; i < (too_far ? 0 : size); ++i) {
      const kdm::QueryPoint& p = all[i];
      if (keys[i] != kdm::point_key(p.id)) fail();
      const double wx = std::ldexp(std::fabs(p.x + q.origin_x), -50),
                   wy = std::ldexp(std::fabs(p.y + q.origin_y), -50);
      if (!(std::fabs(xy[2 * i] - p.x) <= std::ldexp(std::fabs(p.x) + q.tile_size, -21) + wx)) fail();
      if (!(std::fabs(xy[2 * i + 1] - p.y) <= std::ldexp(std::fabs(p.y) + q.tile_size, -21) + wy)) fail();
    }
  }

  // Over two workers run in turn (ParallelQuery, its units planned from the parameters): the region's
  // points, in the units' order, and the whole count.
  {
    static Points units;
    static kdm::QueryPoint sorted[kBigCapacity];
    std::size_t needed = 0;
    units.status = two_workers().run(kdm::Tileset::builtin(), q, units.data, kBigCapacity, &units.size,
                                     in_turn(), &needed, &units.problem);
    if (units.status != kdm::Status::kOk || units.size != all.size || needed != all.size) fail();
    auto id_order = [](const kdm::QueryPoint& u, const kdm::QueryPoint& v) {
      return order_key(u) < order_key(v);
    };
    std::copy(all.data, all.data + all.size, sorted);
    std::sort(sorted, sorted + all.size, id_order);
    std::sort(units.data, units.data + units.size, id_order);
    for (std::size_t i = 0; i < all.size; ++i)
      if (!same(units[i], sorted[i])) fail();
  }

  // Split at x = xm: both halves are accepted (their density bounds are no higher), unless a half is too
  // narrow for its distance from the world origin (refused by name), and together they hold exactly the
  // region's points.
  const double xm = q.x0 + split * (q.x1 - q.x0);
  if (!(xm > q.x0 && xm < q.x1)) return 0;
  kdm::QueryParams qa = q, qb = q;
  qa.x1 = xm, qb.x0 = xm;
  const bool a_fits = a.query(qa), b_fits = b.query(qb);
  for (const Points* half : {&a, &b})
    if (half->status == kdm::Status::kInvalidArgument &&
        half->problem.kind == kdm::QueryProblem::Kind::kTooFarFromOrigin)
      return 0;
  if (!a_fits || a.status != kdm::Status::kOk || !b_fits || b.status != kdm::Status::kOk) fail();
  if (a.size + b.size != all.size) fail();
  auto by_id = [](Points& p) {  // in id order (a tile a part meets only in part comes cell by cell)
    std::sort(p.data, p.data + p.size,
              [](const kdm::QueryPoint& u, const kdm::QueryPoint& v) { return order_key(u) < order_key(v); });
  };
  by_id(all), by_id(a), by_id(b);
  std::size_t ia = 0, ib = 0;
  for (std::size_t i = 0; i < all.size; ++i) {
    const bool from_a = ia < a.size && (ib == b.size || order_key(a[ia]) < order_key(b[ib]));
    if (!same(all[i], from_a ? a[ia++] : b[ib++])) fail();
  }
  return 0;
}
