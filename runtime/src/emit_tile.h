// Internal: the loop that emits one depth-0 tile's candidates (query.cpp's driver calls it per tile), for
// each mode, kind of density and output form (query.h's QueryPoint records or compact_query.h's arrays).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "density_bounds.h"
#include "float_runs.h"
#include "image_sampler.h"
#include "kdm/runtime/compact_query.h"
#include "kdm/runtime/query.h"
#include "keyframe_lookup.h"
#include "query_counted.h"
#include "query_tables.h"
#include "signed_byte_table.h"

namespace kdm::detail {

/// What the per-point loop of one tile reads, copied out of the caller's structures: the output buffer
/// could alias them, and the compiler would reload each after every point written.
struct TileJob {
  const QueryTables* tables;
  KeyframeTable keyframes;
  const TilePoint* points;
  const float* thresholds;
  const std::int8_t* glide;     ///< smooth mode: the tile's offsets
  const std::uint32_t* starts;  ///< smooth mode: where each keyframe's begin
  std::int64_t tx, ty;
  double wx, wy, S;
  double x0, y0, x1, y1, origin_x, origin_y;
  /// Smooth mode: the stable positions (1/65536 tile sides) that can glide into the region, for points
  /// gliding up to `reach` (tile sides): cull_x0 - reach · 65536 ≤ x < cull_x1 + reach · 65536.
  double cull_x0, cull_y0, cull_x1, cull_y1, reach;
  const std::uint32_t* ranks;  ///< smooth mode, varying density: QueryTables::points_at_keyframe
  /// Smooth mode, a tile beside the region: the only ranks that can glide into it (QueryTables::edges).
  const std::uint32_t *listed, *listed_end;
  double area_scale, limit;
  const QueryDensity* density;
  const ImageSampler* sampler;
  /// Smooth mode with a varying density: whether it can be 0 where the tile's points glide (its bounds).
  bool zero_possible;
  /// Stable mode with a varying density: ranks below this are emitted wherever they lie in the tile (their
  /// thresholds lie below the density's lower bound there), without reading the density.
  std::uint32_t sure;
  /// Stable mode with a callback density that has bounds: a candidate above `sure` is first held to the
  /// bounds of the cell of the tile it lies in (kCellBits), which settle it without a call where they can.
  bool cells;
  /// Smooth mode, constant density: the grid cells whose points land inside the region however far they
  /// glide (by `reach`, with room for rounding), which skip its test: safe_x ≤ x < safe_x + safe_w (as
  /// unsigned differences; safe_w = 0 for none), the same in y.
  std::int32_t safe_x, safe_y;
  std::uint32_t safe_w, safe_h;
  /// Compact output in stable mode: the centre of the tile's first grid cell relative to the query origin
  /// and the grid's step, world units in float (CompactSink::put_stable).
  float rel_x, rel_y, rel_unit;
};

/// Smooth mode with a constant density: a tile's offsets at the two keyframes around its count (ranks
/// index pairs from o0 and o1), their weights (GlideBracket's) and, for float output, the weights times
/// the world units per position unit.
struct ConstantGlide {
  const std::int8_t *o0, *o1;
  double w0, w1;
  float w0f, w1f;
};

/// Output into QueryPoint records. put: a position relative to the query origin; put_stable: point p of
/// the tile at its stable position, computed as the query's tests compute it.
struct PointSink {
  /// Whether put_glided_run is a vector loop (emit_tile: how it writes beside the region).
  static constexpr bool kVectorRuns = false;
  QueryPoint* points;
  void put(std::size_t i, double x, double y, const PointId& id) const { points[i] = QueryPoint{x, y, id}; }
  void put_stable(std::size_t i, const TileJob& j, TilePoint p, std::uint32_t rank) const {
    const double x = j.wx + p.unit_x() * j.S, y = j.wy + p.unit_y() * j.S;
    points[i] = QueryPoint{x - j.origin_x, y - j.origin_y, PointId{j.tx, j.ty, rank}};
  }
  /// Ranks [c, c + count) into slots from i on.
  void put_stable_run(std::size_t i, const TileJob& j, std::uint32_t c, std::uint32_t count) const {
    for (std::uint32_t k = 0; k < count; ++k) put_stable(i + k, j, j.points[c + k], c + k);
  }
  /// Point c, glided by a constant density (as emit_tile's place glides it).
  void put_glided(std::size_t i, const TileJob& j, const ConstantGlide& g, std::uint32_t c) const {
    put_glided_run(i, j, g, c, 1);
  }
  /// Ranks [c, c + count) of a tile inside the region, glided by a constant density, as place does.
  void put_glided_run(std::size_t i, const TileJob& j, const ConstantGlide& g, std::uint32_t c,
                      std::uint32_t count) const;
};

/// Compact output (compact_query.h): float positions and, with kKeys, point keys. A stable position is
/// computed in float from the tile's corner (TileJob::rel_x …), so whole tiles convert as fast as a copy.
template <bool kKeys>
struct CompactSink {
  static constexpr bool kVectorRuns = true;
  float* xy;
  std::uint64_t* keys;
  void put(std::size_t i, double x, double y, const PointId& id) const {
    xy[2 * i] = static_cast<float>(x), xy[2 * i + 1] = static_cast<float>(y);
    if (kKeys) keys[i] = point_key(id);
  }
  /// The positions written from slot i on.
  const float* positions(std::size_t i) const { return xy + 2 * i; }
  /// Slots [from, from + count) into slots from `to` ≤ from on, closing up over points left out.
  void move_run(std::size_t to, std::size_t from, std::size_t count) const {
    if (to == from) return;
    std::memmove(xy + 2 * to, xy + 2 * from, count * 2 * sizeof(float));
    if (kKeys) std::memmove(keys + to, keys + from, count * sizeof(std::uint64_t));
  }
  void move(std::size_t to, std::size_t from) const {
    std::memcpy(xy + 2 * to, xy + 2 * from, 2 * sizeof(float));  // to == from at times: one 8-byte copy
    if (kKeys) keys[to] = keys[from];
  }
  void put_stable(std::size_t i, const TileJob& j, TilePoint p, std::uint32_t rank) const {
    xy[2 * i] = j.rel_x + float(p.x) * j.rel_unit, xy[2 * i + 1] = j.rel_y + float(p.y) * j.rel_unit;
    if (kKeys) keys[i] = point_key(PointId{j.tx, j.ty, rank});
  }
  /// Ranks [c, c + count) into slots from i on (float_runs.h: put_stable's formula, vectorised).
  void put_stable_run(std::size_t i, const TileJob& j, std::uint32_t c, std::uint32_t count) const {
    stable_run_xy(j.points + c, count, j.rel_x, j.rel_y, j.rel_unit, xy + 2 * i);
    if (kKeys) key_run(keys + i, count, point_key(PointId{j.tx, j.ty, c}), point_key(PointId{0, 0, 1}));
  }
  /// A glided point, also in float from the tile's corner and its offsets (put_glided_run's formula, so a
  /// point is written alike by every emitter).
  [[gnu::always_inline]] void put_glided(std::size_t i, const TileJob& j, const ConstantGlide& g,
                                         std::uint32_t c) const {
    const TilePoint p = j.points[c];
    const std::int8_t *o0 = g.o0 + 2 * std::size_t(c), *o1 = g.o1 + 2 * std::size_t(c);
    xy[2 * i] = j.rel_x + float(p.x) * j.rel_unit + (float(o0[0]) * g.w0f + float(o1[0]) * g.w1f);
    xy[2 * i + 1] = j.rel_y + float(p.y) * j.rel_unit + (float(o0[1]) * g.w0f + float(o1[1]) * g.w1f);
    if (kKeys) keys[i] = point_key(PointId{j.tx, j.ty, c});
  }
  void put_glided_run(std::size_t i, const TileJob& j, const ConstantGlide& g, std::uint32_t c,
                      std::uint32_t count) const {
    glided_run_xy(j.points + c, g.o0 + 2 * std::size_t(c), g.o1 + 2 * std::size_t(c), count, j.rel_x, j.rel_y,
                  j.rel_unit, g.w0f, g.w1f, xy + 2 * i);
    if (kKeys) key_run(keys + i, count, point_key(PointId{j.tx, j.ty, c}), point_key(PointId{0, 0, 1}));
  }
};

/// Any output (Base: PointSink or CompactSink) with each point's class, for classes of constant densities
/// (class_query.h): thresholds grow with the rank, so a depth-0 tile's classes are rank ranges, found once
/// per run by binary search. Class k holds the ranks that `counts[k]` (the first k + 1 classes' expected
/// count per tile) emits and `counts[k - 1]` does not. A point written by put (past the top level) is
/// classed by `class_of_id`.
template <class Base>
struct ClassSink {
  static constexpr bool kVectorRuns = Base::kVectorRuns;
  Base base;
  std::uint8_t* classes;
  const double* counts;  ///< cumulative expected counts per tile, classes 0 … last - 1
  std::uint32_t last;    ///< the last class, which takes every rank the others leave
  std::uint8_t (*class_of_id)(void* user, const PointId& id);
  void* user;
  void put(std::size_t i, double x, double y, const PointId& id) const {
    base.put(i, x, y, id);
    classes[i] = class_of_id(user, id);
  }
  const float* positions(std::size_t i) const { return base.positions(i); }
  void move_run(std::size_t to, std::size_t from, std::size_t count) const {
    base.move_run(to, from, count);
    if (to != from) std::memmove(classes + to, classes + from, count);
  }
  void move(std::size_t to, std::size_t from) const { base.move(to, from), classes[to] = classes[from]; }
  std::uint8_t class_of(float threshold) const {
    std::uint32_t k = 0;
    while (k < last && !TilesetShape::emits(threshold, counts[k])) ++k;
    return static_cast<std::uint8_t>(k);
  }
  /// Ranks [c, c + count) of tile j into slots from i on.
  void class_run(std::size_t i, const TileJob& j, std::uint32_t c, std::uint32_t count) const {
    const float *first = j.thresholds + c, *end = first + count;
    for (std::uint32_t k = 0; k <= last && first < end; ++k) {
      const float* upto = k == last ? end : std::lower_bound(first, end, counts[k], [](float t, double e) {
        return TilesetShape::emits(t, e);
      });
      std::fill(classes + i + (first - j.thresholds - c), classes + i + (upto - j.thresholds - c),
                static_cast<std::uint8_t>(k));
      first = upto;
    }
  }
  void put_stable(std::size_t i, const TileJob& j, TilePoint p, std::uint32_t rank) const {
    base.put_stable(i, j, p, rank);
    classes[i] = class_of(j.thresholds[rank]);
  }
  void put_stable_run(std::size_t i, const TileJob& j, std::uint32_t c, std::uint32_t count) const {
    base.put_stable_run(i, j, c, count);
    class_run(i, j, c, count);
  }
  void put_glided(std::size_t i, const TileJob& j, const ConstantGlide& g, std::uint32_t c) const {
    base.put_glided(i, j, g, c);
    classes[i] = class_of(j.thresholds[c]);
  }
  void put_glided_run(std::size_t i, const TileJob& j, const ConstantGlide& g, std::uint32_t c,
                      std::uint32_t count) const {
    base.put_glided_run(i, j, g, c, count);
    class_run(i, j, c, count);
  }
};

/// Any output (Base) with each point's class, for classes of varying densities (query_counted.h's
/// VaryingClasses): a candidate whose union density the loop has just read is classed from the classes'
/// running sums at its stable position, which that read left in the scratch, so no class density is read
/// twice; every other point by the classifier. Points are classed as they are written, in every path (a
/// stable-mode candidate is written before its emission is known, and an unkept one is overwritten).
template <class Base>
struct VaryingClassSink {
  static constexpr bool kVectorRuns = Base::kVectorRuns;
  Base base;
  const VaryingClasses* c;
  void put(std::size_t i, double x, double y, const PointId& id) const {
    base.put(i, x, y, id);
    c->classes[i] = c->class_of_id(c->user, id);
  }
  const float* positions(std::size_t i) const { return base.positions(i); }
  void move_run(std::size_t to, std::size_t from, std::size_t count) const {
    base.move_run(to, from, count);
    if (to != from) std::memmove(c->classes + to, c->classes + from, count);
  }
  void move(std::size_t to, std::size_t from) const {
    base.move(to, from), c->classes[to] = c->classes[from];
  }
  /// Candidate `rank` of tile j at its stable position (x, y), as the loop computes it: its class, from the
  /// scratch where the loop has just read the density there.
  std::uint8_t class_at(const TileJob& j, std::uint32_t rank, double x, double y) const {
    const ClassScratch& s = *c->scratch;
    if (s.x == x && s.y == y) {
      const float t = j.thresholds[rank];
      std::uint32_t k = 0;
      while (k < c->last && !TilesetShape::emits(t, s.cumulative[k] * c->area)) ++k;
      return static_cast<std::uint8_t>(k);
    }
    std::uint8_t k;
    c->class_ranks(c->user, j.tx, j.ty, rank, 1, &k);
    return k;
  }
  /// A point whose class class_at gave (smooth mode: found before the glide, written after it).
  void put_classed(std::size_t i, double x, double y, const PointId& id, std::uint8_t k) const {
    base.put(i, x, y, id);
    c->classes[i] = k;
  }
  void put_stable(std::size_t i, const TileJob& j, TilePoint p, std::uint32_t rank) const {
    base.put_stable(i, j, p, rank);
    c->classes[i] = class_at(j, rank, j.wx + p.unit_x() * j.S, j.wy + p.unit_y() * j.S);
  }
  void put_stable_run(std::size_t i, const TileJob& j, std::uint32_t first, std::uint32_t count) const {
    base.put_stable_run(i, j, first, count);
    c->class_ranks(c->user, j.tx, j.ty, first, count, c->classes + i);
  }
  void put_glided(std::size_t i, const TileJob& j, const ConstantGlide& g, std::uint32_t rank) const {
    put_glided_run(i, j, g, rank, 1);
  }
  void put_glided_run(std::size_t i, const TileJob& j, const ConstantGlide& g, std::uint32_t first,
                      std::uint32_t count) const {
    base.put_glided_run(i, j, g, first, count);
    c->class_ranks(c->user, j.tx, j.ty, first, count, c->classes + i);
  }
};

inline void PointSink::put_glided_run(std::size_t i, const TileJob& j, const ConstantGlide& g,
                                      std::uint32_t c, std::uint32_t count) const {
  const double* v = kSignedByte.value + 128;
  const double unit = j.S * (1.0 / 65536.0);
  for (std::uint32_t k = c; k < c + count; ++k) {
    const TilePoint p = j.points[k];
    const std::int8_t *o0 = g.o0 + 2 * std::size_t(k), *o1 = g.o1 + 2 * std::size_t(k);
    double x = j.wx + p.unit_x() * j.S, y = j.wy + p.unit_y() * j.S;
    x += (v[o0[0]] * g.w0 + v[o1[0]] * g.w1) * unit, y += (v[o0[1]] * g.w0 + v[o1[1]] * g.w1) * unit;
    put(i + (k - c), x - j.origin_x, y - j.origin_y, PointId{j.tx, j.ty, k});
  }
}

/// Counts without writing (detail::count_points).
struct CountSink {
  static constexpr bool kVectorRuns = false;
  void put(std::size_t, double, double, const PointId&) const {}
  void put_stable(std::size_t, const TileJob&, TilePoint, std::uint32_t) const {}
  void put_stable_run(std::size_t, const TileJob&, std::uint32_t, std::uint32_t) const {}
  void put_glided(std::size_t, const TileJob&, const ConstantGlide&, std::uint32_t) const {}
  void put_glided_run(std::size_t, const TileJob&, const ConstantGlide&, std::uint32_t, std::uint32_t) const {
  }
};

/// Whether a sink classes a candidate when its density is read (VaryingClassSink::class_at), before
/// smooth mode's batch glides and writes it (put_classed).
template <class Sink, class = void>
constexpr bool kClassesAtDensity = false;
template <class Sink>
constexpr bool kClassesAtDensity<Sink, std::void_t<decltype(&Sink::put_classed)>> = true;

/// Smooth mode, compact output beside the region: rectangles in float relative to the origin such that a
/// glided point whose float position lies inside `sure` lies inside the region by the query's test in double,
/// and one outside `may` outside it. Their margin is far beyond the float formula's error (within
/// 2^-21 · (|p| + S), CompactSink) and a double's rounding at the world's magnitudes.
struct RegionFlagBoxes {
  FloatBox sure, may;
};
inline RegionFlagBoxes region_flag_boxes(const TileJob& j) {
  const double x0 = j.x0 - j.origin_x, x1 = j.x1 - j.origin_x, y0 = j.y0 - j.origin_y, y1 = j.y1 - j.origin_y;
  const double far = std::max({std::fabs(x0), std::fabs(x1), std::fabs(y0), std::fabs(y1)}) + 2 * j.S;
  const double world = std::fabs(j.wx) + std::fabs(j.wy) + std::fabs(j.x0) + std::fabs(j.x1) +
                       std::fabs(j.y0) + std::fabs(j.y1) + std::fabs(j.origin_x) + std::fabs(j.origin_y) +
                       j.S;
  const double m = std::ldexp(far, -18) + 1e-14 * world;
  auto up = [](double v) {  // the least float ≥ v
    const float f = static_cast<float>(v);
    return double(f) < v ? std::nextafter(f, HUGE_VALF) : f;
  };
  auto down = [](double v) {  // the greatest float ≤ v
    const float f = static_cast<float>(v);
    return double(f) > v ? std::nextafter(f, -HUGE_VALF) : f;
  };
  return {{up(x0 + m), up(y0 + m), down(x1 - m), down(y1 - m)},
          {down(x0 - m), down(y0 - m), up(x1 + m), up(y1 + m)}};
}

/// Closes up slots [n, n + count) of `out` over those whose flag is 0 (flags 0 or 1); returns the slot after
/// the last one kept. A few left out: the runs between them move; many: every slot, with no branch.
template <class Sink>
std::size_t close_up(const Sink& out, std::size_t n, const std::uint8_t* flags, std::uint32_t count) {
  std::uint32_t kept = 0;
  for (std::uint32_t i = 0; i < count; ++i) kept += flags[i];
  if (kept == count) return n + count;
  std::size_t to = n;
  if (count - kept <= count / 32) {
    std::uint32_t from = 0;  // the first kept point not yet moved
    for (std::uint32_t i = next_unsettled(flags, 0, count); i < count;
         i = next_unsettled(flags, i + 1, count)) {
      out.move_run(to, n + from, i - from);
      to += i - from, from = i + 1;
    }
    out.move_run(to, n + from, count - from);
    return to + (count - from);
  }
  for (std::uint32_t i = 0; i < count; ++i) {
    out.move(to, n + i);
    to += flags[i];
  }
  return to;
}

/// Stable mode with a varying density: a tile's 2^kCellBits × 2^kCellBits cells, whose bounds settle a
/// candidate between the tile's bounds without reading the density where they can.
constexpr std::uint32_t kCellBits = 2;

/// Emits the candidates [c, end) of one tile into out[n ..) (at most `capacity` in all); returns the rank
/// it stopped at (end, or the first point that did not fit). kInside: every point the tile can emit, glided
/// or not, lies inside the region, so no point is tested against it. kListed: only the ranks of
/// job.listed are visited (the others are culled, as the full scan would).
template <class Sink, bool kSmooth, QueryDensity::Kind kKind, bool kInside, bool kListed>
std::uint32_t emit_tile(const TileJob& job, std::uint32_t c, std::uint32_t end, const Sink out,
                        std::size_t capacity, std::size_t& written) {
  const TileJob j = job;  // a local copy, which the writes into `out` cannot alias
  std::size_t n = written;
  constexpr bool kConstant = kKind == QueryDensity::Kind::kConstant;
  if constexpr (!kConstant && kInside && !kSmooth) {  // the ranks sure to be emitted, as a constant's
    if (c < j.sure) {
      const std::uint32_t count =
          static_cast<std::uint32_t>(std::min<std::size_t>(std::min(end, j.sure) - c, capacity - n));
      out.put_stable_run(n, j, c, count);
      n += count, c += count;
      if (c < std::min(end, j.sure) || c == end) {
        written = n;
        return c;
      }
    }
  }
  if constexpr (kConstant && kInside && !kSmooth) {
    // Every candidate is emitted where it stands: a plain loop the compiler can vectorise.
    const std::uint32_t count = static_cast<std::uint32_t>(std::min<std::size_t>(end - c, capacity - n));
    out.put_stable_run(n, j, c, count);
    written = n + count;
    return c + count;
  }
  const GlideBracket constant = kSmooth && kConstant ? GlideBracket(j.keyframes, j.limit) : GlideBracket();
  const double unit = j.S * (1.0 / 65536.0);  // world units per position unit
  ConstantGlide glide{};
  if (kSmooth) {
    glide.o0 = j.glide + 2 * std::size_t(j.starts[constant.g0]);
    glide.o1 = j.glide + 2 * std::size_t(j.starts[constant.g1]);
    glide.w0 = constant.w0, glide.w1 = constant.w1;
    glide.w0f = static_cast<float>(constant.w0 * unit), glide.w1f = static_cast<float>(constant.w1 * unit);
  }
  if constexpr (kConstant && kInside && kSmooth) {  // the same, glided by the tile's two keyframes
    const std::uint32_t count = static_cast<std::uint32_t>(std::min<std::size_t>(end - c, capacity - n));
    out.put_glided_run(n, j, glide, c, count);
    written = n + count;
    return c + count;
  }
  // Culling bounds; with a varying density they narrow with the rank: a point whose threshold is at least
  // K_g is emitted only above it, where it glides no farther than any point does from keyframe g on.
  const std::size_t keyframes = kSmooth ? j.keyframes.n : 0;
  std::size_t segment = 0;  // varying: the keyframes whose count the thresholds from rank c on reach
  double lo_x = 0, hi_x = 0, lo_y = 0, hi_y = 0;
  auto set_reach = [&](double reach) {
    lo_x = j.cull_x0 - reach * 65536.0, hi_x = j.cull_x1 + reach * 65536.0;
    lo_y = j.cull_y0 - reach * 65536.0, hi_y = j.cull_y1 + reach * 65536.0;
  };
  if (kSmooth && !kInside) set_reach(kConstant ? j.reach : j.tables->glide_reach_from[0]);
  // Smooth mode: places candidate c at its stable position (x, y) plus its offsets o0 and o1 weighted by
  // w0 and w1 (GlideBracket): false when the buffer is full.
  auto glide_by = [&](double& x, double& y, const std::int8_t* o0, const std::int8_t* o1, double w0,
                      double w1) {
    const double* v = kSignedByte.value + 128;
    x += (v[o0[0]] * w0 + v[o1[0]] * w1) * unit, y += (v[o0[1]] * w0 + v[o1[1]] * w1) * unit;
  };
  auto outside = [&](double x, double y) { return x < j.x0 || x >= j.x1 || y < j.y0 || y >= j.y1; };
  auto place = [&](std::uint32_t c, double x, double y, const std::int8_t* o0, const std::int8_t* o1,
                   double w0, double w1, std::uint8_t cls) -> bool {
    glide_by(x, y, o0, o1, w0, w1);
    // Where the region cuts the tile, whether a point lies inside follows no pattern: it is written at the
    // next slot, which only then it keeps.
    const bool in = kInside || ((x >= j.x0) & (x < j.x1) & (y >= j.y0) & (y < j.y1));
    // A point never shows where there is no density: one decided at its stable position could glide up
    // to a spacing past a sharp edge of the density (stray dots outside a stippled shape).
    if (!kConstant && j.zero_possible) {
      if (!in) return true;
      if (kKind == QueryDensity::Kind::kImage && !(j.sampler->at(x, y) > 0)) return true;
      if (kKind == QueryDensity::Kind::kCallback &&
          !(density_or_zero(j.density->callback(j.density->user, x, y)) > 0))
        return true;
    }
    if (n == capacity) return !in;
    if constexpr (kConstant)
      out.put_glided(n, j, glide, c);
    else if constexpr (kClassesAtDensity<Sink>)
      out.put_classed(n, x - j.origin_x, y - j.origin_y, PointId{j.tx, j.ty, c}, cls);
    else
      out.put(n, x - j.origin_x, y - j.origin_y, PointId{j.tx, j.ty, c});
    n += in;
    return true;
  };
  // Smooth mode with a varying density: the emitted candidates wait in a batch, so that the long chain from
  // a point's density to its glided position overlaps between points instead of restarting after every
  // mispredicted emission test.
  constexpr bool kBatched = kSmooth && !kConstant;
  constexpr std::uint32_t kNone = ~0u;
  constexpr int kBatch = kBatched ? 32 : 1;
  std::uint32_t pending_rank[kBatch];
  double pending_expected[kBatch], pending_x[kBatch], pending_y[kBatch];
  std::uint8_t pending_class[kBatch];
  int pending = 0;
  auto flush = [&]() -> std::uint32_t {  // the rank that did not fit, or kNone
    // Two passes, each short enough for the processor to overlap many points' latency chains.
    const std::int8_t *o0[kBatch], *o1[kBatch];
    double w0[kBatch], w1[kBatch];
    for (int i = 0; i < pending; ++i) {
      const GlideBracket b(j.keyframes, pending_expected[i]);
      o0[i] = j.glide + 2 * (std::size_t(j.starts[b.g0]) + pending_rank[i]);
      o1[i] = j.glide + 2 * (std::size_t(j.starts[b.g1]) + pending_rank[i]);
      w0[i] = b.w0, w1[i] = b.w1;
    }
    for (int i = 0; i < pending; ++i)
      if (!place(pending_rank[i], pending_x[i], pending_y[i], o0[i], o1[i], w0[i], w1[i], pending_class[i]))
        return pending = 0, pending_rank[i];
    pending = 0;
    return kNone;
  };
  // Stable mode, a density with bounds: each cell's expected counts' bounds (widened by 10^-9 for rounding,
  // as the tile's), read when a candidate first lies in it. The cell's sides are computed as positions are
  // (corner plus a fraction times the side) and rounding is monotonic, so its points lie in its rectangle.
  constexpr bool kCells = !kSmooth && !kConstant;
  constexpr std::uint32_t kCellCount = kCells ? 1u << (2 * kCellBits) : 1;
  static_assert(kCellCount <= 32, "a bit per cell in cells_read");
  double cell_lo[kCellCount], cell_hi[kCellCount];
  std::uint32_t cells_read = 0;
  auto cell_of = [&](TilePoint p) {
    const std::uint32_t cx = p.x >> (16 - kCellBits), cy = p.y >> (16 - kCellBits);
    const std::uint32_t cell = kCells ? cy << kCellBits | cx : 0;
    if (!(cells_read >> cell & 1)) {
      constexpr double kStep = 1.0 / (1 << kCellBits);
      double lo, hi;
      density_bounds(*j.density, j.wx + (cx * kStep) * j.S, j.wy + (cy * kStep) * j.S,
                     j.wx + ((cx + 1) * kStep) * j.S, j.wy + ((cy + 1) * kStep) * j.S, lo, hi);
      cell_lo[cell] = lo * j.area_scale * (1 - 1e-9), cell_hi[cell] = hi * j.area_scale * (1 + 1e-9);
      cells_read |= 1u << cell;
    }
    return cell;
  };
  // One candidate: the rank that did not fit, or kNone. Positions: the stable one (for ρ and in stable
  // mode), then the glide added to it.
  auto culled = [&](TilePoint p) {
    const double sx = p.x + 0.5, sy = p.y + 0.5;
    return sx < lo_x || sx >= hi_x || sy < lo_y || sy >= hi_y;
  };
  auto visit = [&](std::uint32_t c) -> std::uint32_t {
    const TilePoint p = j.points[c];
    if (kSmooth && !kInside) {
      if (!kConstant && segment < keyframes && j.ranks[segment] <= c) {
        while (segment < keyframes && j.ranks[segment] <= c) ++segment;
        set_reach(j.tables->glide_reach_from[segment - 1]);
      }
      if (culled(p)) return kNone;
    }
    const double x = j.wx + p.unit_x() * j.S, y = j.wy + p.unit_y() * j.S;
    if constexpr (!kSmooth) {
      const bool in = kInside || ((x >= j.x0) & (x < j.x1) & (y >= j.y0) & (y < j.y1));
      if (kConstant || c < j.sure) {  // emitted if inside: written at the next slot, which only then it keeps
        if (n == capacity) return in ? c : kNone;
        out.put_stable(n, j, p, c);
        n += in;
        return kNone;
      }
      if (!in) return kNone;
    }
    if (kConstant)
      return place(c, x, y, glide.o0 + 2 * std::size_t(c), glide.o1 + 2 * std::size_t(c), glide.w0, glide.w1,
                   0)
                 ? kNone
                 : c;
    if (kCells && j.cells) {
      const std::uint32_t cell = cell_of(p);
      if (!TilesetShape::emits(j.thresholds[c], cell_hi[cell])) return kNone;  // not even at its cell's most
      if (TilesetShape::emits(j.thresholds[c], cell_lo[cell])) {
        if (n == capacity) return c;
        out.put_stable(n++, j, p, c);
        return kNone;
      }
    }
    const double rho = kKind == QueryDensity::Kind::kImage
                           ? j.sampler->at(x, y)
                           : density_or_zero(j.density->callback(j.density->user, x, y));
    const double expected = rho * j.area_scale;
    // Whether a point is emitted follows no pattern a branch predictor could learn: each candidate is
    // written (or queued) at the next slot, which only an emitted one then keeps.
    const bool emitted = TilesetShape::emits(j.thresholds[c], expected);
    if (!kBatched) {
      if (n == capacity) return emitted ? c : kNone;
      out.put_stable(n, j, p, c);
      n += emitted;
      return kNone;
    }
    pending_rank[pending] = c, pending_expected[pending] = expected;
    pending_x[pending] = x, pending_y[pending] = y;
    if constexpr (kClassesAtDensity<Sink>) {
      if (emitted) pending_class[pending] = out.class_at(j, c, x, y);
    }
    pending += emitted;
    return pending == kBatch ? flush() : kNone;
  };
  std::uint32_t stopped = kNone;
  if constexpr (kListed) {
    const std::uint32_t* it = std::lower_bound(j.listed, j.listed_end, c);
    for (; it != j.listed_end && *it < end && stopped == kNone; ++it) stopped = visit(*it);
  } else if constexpr (kConstant && !kInside && Sink::kVectorRuns) {
    // Beside the region, compact output: candidates are written a chunk at a time as whole tiles inside
    // are; their float positions, held to the region in one vector pass, settle all but those within
    // rounding of its sides, which are tested as visit tests them; the kept ones are then closed up over
    // the rest. Point by point, whether a point lies inside is a branch the predictor misses where the
    // region cuts the tile, and runs cut at every point near a side leave the vector loop's scalar ends.
    constexpr std::size_t kChunk = 2048;  // written, then read back, while in the first-level cache
    std::uint8_t flags[kChunk];
    const RegionFlagBoxes boxes = region_flag_boxes(j);
    auto lands_inside = [&](std::uint32_t r) {
      const TilePoint p = j.points[r];
      if (kSmooth && culled(p)) return false;
      double x = j.wx + p.unit_x() * j.S, y = j.wy + p.unit_y() * j.S;
      if (kSmooth)
        glide_by(x, y, glide.o0 + 2 * std::size_t(r), glide.o1 + 2 * std::size_t(r), glide.w0, glide.w1);
      return !outside(x, y);
    };
    while (c < end && n < capacity) {
      const auto count = static_cast<std::uint32_t>(std::min<std::size_t>({end - c, capacity - n, kChunk}));
      if constexpr (kSmooth)
        out.put_glided_run(n, j, glide, c, count);
      else
        out.put_stable_run(n, j, c, count);
      box_flags(out.positions(n), count, boxes.sure, boxes.may, flags);
      for (std::uint32_t i = next_unsure(flags, 0, count); i < count; i = next_unsure(flags, i + 1, count))
        flags[i] = lands_inside(c + i);
      n = close_up(out, n, flags, count), c += count;
    }
    // The rest one by one (a full buffer: so that the call stops at the first point that does not fit).
    for (; c < end && stopped == kNone; ++c) stopped = visit(c);
  } else if constexpr (kSmooth && kConstant && !kInside) {
    // Beside the region, QueryPoint records: where the tile reaches well into the region (it has safe
    // cells), each candidate is glided, written at the next slot and kept if inside, with no branch a
    // predictor would miss where the region cuts the tile; elsewhere most are culled, predictably.
    if (j.safe_w != 0 && j.safe_h != 0) {
      for (; c < end && n < capacity; ++c) {
        const TilePoint p = j.points[c];
        double x = j.wx + p.unit_x() * j.S, y = j.wy + p.unit_y() * j.S;
        glide_by(x, y, glide.o0 + 2 * std::size_t(c), glide.o1 + 2 * std::size_t(c), glide.w0, glide.w1);
        const bool in = (x >= j.x0) & (x < j.x1) & (y >= j.y0) & (y < j.y1);
        out.put_glided(n, j, glide, c);
        n += in;
      }
    }
    for (; c < end && stopped == kNone; ++c) stopped = visit(c);
  } else {
    for (; c < end && stopped == kNone; ++c) stopped = visit(c);
  }
  if (kBatched && stopped == kNone) stopped = flush();
  written = n;
  return stopped == kNone ? end : stopped;
}

template <class Sink>
using EmitTile = std::uint32_t (*)(const TileJob&, std::uint32_t, std::uint32_t, Sink, std::size_t,
                                   std::size_t&);

/// The emitter for a mode and kind of density: beside the region (kInside false), inside it, or through
/// a list of ranks (kListed: an edge list, or the points of the cells the region meets).
template <class Sink, bool kInside, bool kListed = false>
EmitTile<Sink> pick_emitter(bool smooth, QueryDensity::Kind kind) {
  using K = QueryDensity::Kind;
  switch (kind) {
    case K::kConstant:
      return smooth ? emit_tile<Sink, true, K::kConstant, kInside, kListed>
                    : emit_tile<Sink, false, K::kConstant, kInside, kListed>;
    case K::kImage:
      return smooth ? emit_tile<Sink, true, K::kImage, kInside, kListed>
                    : emit_tile<Sink, false, K::kImage, kInside, kListed>;
    case K::kCallback:
      break;
  }
  return smooth ? emit_tile<Sink, true, K::kCallback, kInside, kListed>
                : emit_tile<Sink, false, K::kCallback, kInside, kListed>;
}

}  // namespace kdm::detail
