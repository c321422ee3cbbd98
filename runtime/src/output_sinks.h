// Internal: what emit_tile.h's loop reads for one tile (TileJob) and where it writes (the sinks: QueryPoint
// records, compact_query.h's arrays, either with classes, or a count), each writing a point by the one
// expression every path of a query uses for it.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

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
  /// The only ranks that can land in the region, when listed: a smooth tile's edge list beside it
  /// (QueryTables::edges), ascending, or the ranks of the cells it meets (cell_index.h), ascending in each
  /// cell, the cells in turn; else null.
  const std::uint32_t *listed, *listed_end;
  double area_scale, limit;
  const QueryDensity* density;
  const ImageSampler* sampler;
  /// Smooth mode with a varying density: whether it can be 0 where the tile's points glide (its bounds).
  bool zero_possible;
  /// Smooth mode with a varying density: points glide by glide_count.h's count (QueryParams::glide_together).
  bool glide_together;
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
  /// Positions lie at most 2^kOriginSpanBits point spacings from the query's origin, where a double's
  /// step is a 16th of a spacing: farther, points fall together (query_into refuses).
  static constexpr int kOriginSpanBits = 48;
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
  static constexpr int kOriginSpanBits = 21;  ///< a float's step at most a quarter of a spacing
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
  static constexpr int kOriginSpanBits = Base::kOriginSpanBits;
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
  static constexpr int kOriginSpanBits = Base::kOriginSpanBits;
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
  [[gnu::always_inline]] std::uint8_t class_at(const TileJob& j, std::uint32_t rank, double x,
                                               double y) const {
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
  /// Candidates ranks[0 … n) of tile j at their stable positions (x[i], y[i]), whose densities one batch
  /// read has just given: their classes into out[0 … n), from the running sums that read left in the
  /// scratch (class_at's rule; class_at itself for a position the scratch does not hold).
  void classes_of_reads(const TileJob& j, const std::uint32_t* ranks, std::size_t n, const double* x,
                        const double* y, std::uint8_t* out) const {
    const ClassScratch& s = *c->scratch;
    const double area = c->area;
    for (std::size_t i = 0; i < n; ++i) {
      if (s.batch_count != n || s.batch_x[i] != x[i] || s.batch_y[i] != y[i]) {
        out[i] = class_at(j, ranks[i], x[i], y[i]);
        continue;
      }
      const float t = j.thresholds[ranks[i]];
      std::uint32_t k = 0;
      for (std::uint32_t m = 0; m < c->last; ++m)
        k += !TilesetShape::emits(t, s.batch_cumulative[m][i] * area);
      out[i] = static_cast<std::uint8_t>(k);
    }
  }
  /// Candidates ranks[0 … n) of tile j at their stable positions, emitted without their densities
  /// read: their classes into out[0 … n), the classes' densities read in batches where the bounds leave
  /// a class open.
  void classes_of_unread(const TileJob& j, const std::uint32_t* ranks, std::size_t n, const double* x,
                         const double* y, std::uint8_t* out) const {
    c->class_points(c->user, j.tx, j.ty, ranks, n, x, y, out);
  }
  /// Records p[0 … count) into slots i … i + count - 1, classed together (past the top level).
  void put_records(std::size_t i, const QueryPoint* p, std::size_t count) const {
    for (std::size_t k = 0; k < count; ++k) base.put(i + k, p[k].x, p[k].y, p[k].id);
    c->class_records(c->user, p, count, c->classes + i);
  }
  /// Classes all images on one grid (ClassImages), else null.
  const ClassImages* images() const { return c->images; }
  /// A depth-0 tile's area times the scale, which the classes' densities multiply.
  double class_area() const { return c->area; }
  /// Ranks [first, first + count) of tile j from their classes' running sums at their stable positions
  /// (sums[k · stride + i] for rank first + i, image_sums_run's), into out[0 … count): class_at's rule, in a
  /// loop the compiler vectorises.
  void classes_of_sums(const TileJob& j, std::uint32_t first, std::uint32_t count, const double* sums,
                       std::size_t stride, std::uint8_t* out) const {
    const float* t = j.thresholds + first;
    const double area = c->area;
    for (std::uint32_t i = 0; i < count; ++i) {
      std::uint32_t k = 0;
      for (std::uint32_t m = 0; m < c->last; ++m)
        k += !TilesetShape::emits(t[i], sums[m * stride + i] * area);
      out[i] = static_cast<std::uint8_t>(k);
    }
  }
  /// put_stable of a point whose class is known.
  [[gnu::always_inline]] void put_stable_classed(std::size_t i, const TileJob& j, TilePoint p,
                                                 std::uint32_t rank, std::uint8_t k) const {
    base.put_stable(i, j, p, rank);
    c->classes[i] = k;
  }
  /// put_stable of a point whose class is written apart (put_classes).
  [[gnu::always_inline]] void put_stable_unclassed(std::size_t i, const TileJob& j, TilePoint p,
                                                   std::uint32_t rank) const {
    base.put_stable(i, j, p, rank);
  }
  /// The classes of slots i … i + count - 1.
  void put_classes(std::size_t i, const std::uint8_t* classes, std::size_t count) const {
    std::memcpy(c->classes + i, classes, count);
  }
  /// A point whose class class_at gave (smooth mode: found before the glide, written after it).
  void put_classed(std::size_t i, double x, double y, const PointId& id, std::uint8_t k) const {
    base.put(i, x, y, id);
    c->classes[i] = k;
  }
  [[gnu::always_inline]] void put_stable(std::size_t i, const TileJob& j, TilePoint p,
                                         std::uint32_t rank) const {
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
  static constexpr int kOriginSpanBits = 48;  ///< writes nothing: the query that writes refuses for itself
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

/// Whether a sink takes a run of QueryPoint records at once (VaryingClassSink::put_records).
template <class Sink, class = void>
constexpr bool kPutsRecords = false;
template <class Sink>
constexpr bool kPutsRecords<Sink, std::void_t<decltype(&Sink::put_records)>> = true;

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

}  // namespace kdm::detail
