// Internal: the loops that emit a subtile's own points past the top level (descent.cpp), as query.cpp's
// emit_tile does at depth 0: a constant density's by one glide bracket (emit_own), a varying one's each by
// its count, in batches (emit_varying); beside the region both visit only the points that can glide into
// it (SubtileCull). Positions and tests are Descent::write_unit's, bit for bit.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "descent.h"
#include "glide_runs.h"
#include "signed_byte_table.h"

namespace kdm::detail {

/// What emit_descending's loops return when a tile's points are all emitted.
inline constexpr std::uint32_t kDescentDone = ~0u;

/// A tile of a descent: the depth-0 tile or one of its subtiles.
struct DescentNode {
  std::size_t type = 0;
  std::uint32_t depth = 0;
  std::int64_t gx = 0, gy = 0;      ///< its tile coordinates at its depth
  double wx = 0, wy = 0;            ///< its south-west corner, world units
  double rx = 0, ry = 0;            ///< the same relative to the query origin
  double rho_max = 0, rho_min = 0;  ///< bounds of the density over it
  std::uint32_t next_child = 0;
  bool points_done = false;
};

/// Where the loops write and what they may spend: the caller's buffer, its fill, the candidate budget.
struct DescentSink {
  QueryPoint* out;
  std::size_t capacity;
  std::size_t& written;
  std::uint64_t& budget;
};

/// The region in a subtile's position units (1/65536 sides), widened by one unit and by as many more as
/// the rounding of world coordinates this far out can take, so that a culling by it (less the reach of
/// the points culled) is never stricter than write_unit's test; and, where the region lies beyond one of
/// the subtile's sides, that side's edge list (QueryTables::edges_beyond), else listed is null.
struct SubtileCull {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  const std::uint32_t *listed = nullptr, *listed_end = nullptr;
  /// The region narrowed by the same rounding: a position at least in_x0 and below in_x1 (and so in y)
  /// passes write_unit's test.
  double in_x0 = 0, in_y0 = 0, in_x1 = 0, in_y1 = 0;
};

/// Node n's SubtileCull for the query.
inline SubtileCull subtile_cull(const DescentQuery& q, const DescentNode& n) {
  const QueryParams& p = *q.params;
  const double s = q.side[n.depth], scale = 65536.0 / s;
  // A few ulps of the largest coordinate involved, in position units.
  const double slack = 1 + 1e-15 * scale *
                               (std::fabs(n.wx) + std::fabs(n.wy) + std::fabs(p.x0) + std::fabs(p.x1) +
                                std::fabs(p.y0) + std::fabs(p.y1) + s);
  SubtileCull c;
  c.x0 = (p.x0 - n.wx) * scale - slack, c.x1 = (p.x1 - n.wx) * scale + slack;
  c.y0 = (p.y0 - n.wy) * scale - slack, c.y1 = (p.y1 - n.wy) * scale + slack;
  c.in_x0 = c.x0 + 2 * slack, c.in_x1 = c.x1 - 2 * slack;
  c.in_y0 = c.y0 + 2 * slack, c.in_y1 = c.y1 - 2 * slack;
  q.tables->edges_beyond(n.type, c.x0, c.y0, c.x1, c.y1, c.listed, c.listed_end);
  return c;
}

/// Points from[0 .. count) of a subtile (ranks from id.rank on) glided by offsets a and b weighted w0 and
/// w1, as QueryPoint records relative to the origin (rx, ry: the subtile's corner; s: its side) into
/// to[0 .. count): emit_own's expressions, bit for bit. Its own function, so that every caller runs the
/// same compiled loop (offsets read as doubles from a table: the values of conversions, without their
/// false dependency).
[[gnu::noinline]] inline void glided_records(QueryPoint* to, const TilePoint* from, const std::int8_t* a,
                                             const std::int8_t* b, std::uint32_t count, double w0, double w1,
                                             double rx, double ry, double s, PointId id) {
  const double* v = kSignedByte.value + 128;
  for (std::uint32_t k = 0; k < count; ++k) {
    const TilePoint q = from[k];
    const double dx = v[a[2 * k]] * w0 + v[b[2 * k]] * w1, dy = v[a[2 * k + 1]] * w0 + v[b[2 * k + 1]] * w1;
    const double ux = q.unit_x() + dx * (1.0 / 65536.0), uy = q.unit_y() + dy * (1.0 / 65536.0);
    to[k] = QueryPoint{rx + ux * s, ry + uy * s, PointId{id.tile_x, id.tile_y, id.rank + k, id.depth}};
  }
}

/// Emits ranks [from, end) of tile n (depth > 0), every one emitted and gliding by bracket g, none
/// farther than `reach` (sides). kClip: only those inside the region, visiting only those whose stable
/// position lies within `c` widened by the reach; kListed: only c's listed ranks. Positions and the
/// region's test as write_unit's, bit for bit. kDescentDone, or where the buffer or the budget ran out.
template <bool kClip, bool kListed>
std::uint32_t emit_own(const DescentQuery& q, const DescentNode& n, DescentSink& sink, std::uint32_t from,
                       std::uint32_t end, const GlideBracket& g, double reach, const SubtileCull& c) {
  const TilesetData& set = *q.set;
  const QueryTables& t = *q.tables;
  const Tile& tile = set.tiles[n.type];
  const std::uint32_t* start = t.glide_start[n.type].data();
  const std::int8_t* o0 = tile.glide.data() + 2 * std::size_t(start[g.g0]);
  const std::int8_t* o1 = tile.glide.data() + 2 * std::size_t(start[g.g1]);
  const double s = q.side[n.depth], rx = n.rx, ry = n.ry, wx = n.wx, wy = n.wy, w0 = g.w0, w1 = g.w1;
  const std::int64_t gx = n.gx, gy = n.gy;
  const std::uint32_t depth = n.depth;
  const QueryParams& p = *q.params;
  const double x0 = p.x0, y0 = p.y0, x1 = p.x1, y1 = p.y1;
  const SubtileCull cut = c;
  const double lo_x = cut.x0 - reach * 65536.0, hi_x = cut.x1 + reach * 65536.0;
  const double lo_y = cut.y0 - reach * 65536.0, hi_y = cut.y1 + reach * 65536.0;
  // Stable positions this far inside the narrowed region land in it however far they glide (2 units for
  // the offsets' blend): runs of them are written with no test, as inside subtiles' points are. As cells:
  // x + 0.5 in [lo, hi) is x in [ceil(lo − 0.5), ceil(hi − 0.5)), an unsigned range test.
  auto cells = [](double lo, double hi, std::uint32_t& first, std::uint32_t& width) {
    const double a = std::clamp(std::ceil(lo - 0.5), 0.0, 65536.0),
                 b = std::clamp(std::ceil(hi - 0.5), 0.0, 65536.0);
    first = static_cast<std::uint32_t>(a), width = b > a ? static_cast<std::uint32_t>(b - a) : 0;
  };
  std::uint32_t safe_x, safe_w, safe_y, safe_h;
  cells(cut.in_x0 + reach * 65536.0 + 2, cut.in_x1 - reach * 65536.0 - 2, safe_x, safe_w);
  cells(cut.in_y0 + reach * 65536.0 + 2, cut.in_y1 - reach * 65536.0 - 2, safe_y, safe_h);
  // Locals, which the writes into the caller's buffer cannot alias.
  const TilePoint* points = tile.points.data();
  QueryPoint* const out = sink.out;
  const std::size_t capacity = sink.capacity;
  std::size_t written = sink.written;
  std::uint64_t budget = sink.budget;
  // Ranks [r, r + count) into out[written ..), every one kept: one plain loop.
  // Ranks [r, r + count) into out[written ..), every one kept.
  auto run = [&](std::uint32_t r, std::uint32_t count) {
    glided_records(out + written, points + r, o0 + 2 * std::size_t(r), o1 + 2 * std::size_t(r), count, w0, w1,
                   rx, ry, s, PointId{gx, gy, r, depth});
    written += count, budget -= count;
  };
  if constexpr (!kClip && !kListed) {  // inside the region: as many as the buffer and the budget allow
    const auto count = static_cast<std::uint32_t>(
        std::min<std::uint64_t>({std::uint64_t(end - from), std::uint64_t(capacity - written), budget}));
    run(from, count);
    sink.written = written, sink.budget = budget;
    return from + count >= end ? kDescentDone : from + count;
  }
  auto safe = [&](std::uint32_t r) {
    return std::uint32_t(points[r].x - safe_x) < safe_w && std::uint32_t(points[r].y - safe_y) < safe_h;
  };
  const std::uint32_t* it = kListed ? std::lower_bound(cut.listed, cut.listed_end, from) : nullptr;
  std::uint32_t r = kListed ? (it != cut.listed_end ? std::min(*it, end) : end) : from;
  const double safe_share = double(safe_w) * double(safe_h) / (65536.0 * 65536.0);
  if (kClip && !kListed && safe_share > 0 && safe_share < 0.9) {
    // The region's side cuts the subtile: every candidate is glided and written, kept if inside, with no
    // branch on where it lies, which follows no pattern. Below, runs where nearly all are safe (the region's
    // side near the subtile's) and culling where none is (most of the subtile lies outside).
    for (; r < end && written < capacity && budget != 0; ++r, --budget) {
      const TilePoint q = points[r];
      const double dx = double(o0[2 * r]) * w0 + double(o1[2 * r]) * w1,
                   dy = double(o0[2 * r + 1]) * w0 + double(o1[2 * r + 1]) * w1;
      const double ux = q.unit_x() + dx * (1.0 / 65536.0), uy = q.unit_y() + dy * (1.0 / 65536.0);
      const double x = wx + ux * s, y = wy + uy * s;
      out[written] = QueryPoint{rx + ux * s, ry + uy * s, PointId{gx, gy, r, depth}};
      written += (x >= x0) & (x < x1) & (y >= y0) & (y < y1);
    }
  }
  while (r < end) {
    if (kClip && !kListed && safe(r)) {
      std::uint32_t stop = r + 1;
      while (stop < end && safe(stop)) ++stop;
      const auto count = static_cast<std::uint32_t>(
          std::min<std::uint64_t>({std::uint64_t(stop - r), std::uint64_t(capacity - written), budget}));
      run(r, count);
      r += count;
      if (r < stop) break;  // the buffer or the budget ran out
      continue;
    }
    if (budget == 0) break;
    --budget;
    const TilePoint q = points[r];
    bool visit = true;
    if (kClip) {  // a point that cannot glide into the region is passed over before anything is computed
      const double sx = q.x + 0.5, sy = q.y + 0.5;
      visit = sx >= lo_x && sx < hi_x && sy >= lo_y && sy < hi_y;
    }
    if (visit) {
      const double dx = double(o0[2 * r]) * w0 + double(o1[2 * r]) * w1,
                   dy = double(o0[2 * r + 1]) * w0 + double(o1[2 * r + 1]) * w1;
      const double ux = q.unit_x() + dx * (1.0 / 65536.0), uy = q.unit_y() + dy * (1.0 / 65536.0);
      // Whether a point lies in the region follows no pattern a branch predictor could learn near its
      // border: each is written at the next slot, which only one inside keeps.
      bool kept = true;
      if (kClip) {
        const double x = wx + ux * s, y = wy + uy * s;
        kept = x >= x0 && x < x1 && y >= y0 && y < y1;
      }
      if (written == capacity) {
        if (kept) {
          ++budget;
          break;
        }
      } else {
        out[written] = QueryPoint{rx + ux * s, ry + uy * s, PointId{gx, gy, r, depth}};
        written += kept;
      }
    }
    if (kListed) {
      ++it;
      r = it != cut.listed_end ? std::min(*it, end) : end;
    } else {
      ++r;
    }
  }
  sink.written = written, sink.budget = budget;
  return r >= end ? kDescentDone : r;
}

/// Emits ranks [from, end) of tile n (depth > 0) under a varying density, none of which hands over:
/// each where its count at its stable position passes its threshold, gliding by that count. Emitted
/// ranks wait in a batch, as emit_tile's do, so that the chains from a point's density to its position
/// overlap instead of restarting after every mispredicted emission test. kClip and kListed as
/// emit_own's, each rank culled by the reach from the keyframe it appears after. Positions and tests
/// as the general loop's, bit for bit. kDescentDone, or where the buffer or the budget ran out.
template <QueryDensity::Kind kKind, bool kClip, bool kListed, bool kBatchReads = false>
std::uint32_t emit_varying(const DescentQuery& q, const DescentNode& n, DescentSink& sink, std::uint32_t from,
                           std::uint32_t end, const SubtileCull& c) {
  const TilesetData& set = *q.set;
  const QueryTables& t = *q.tables;
  static_assert(kKind != QueryDensity::Kind::kConstant);
  // Locals, which the writes into the caller's buffer cannot alias.
  const ImageSampler sampler = *q.sampler;
  double (*const callback)(void*, double, double) = q.params->density.callback;  // set unless kBatchReads
  void* const user = q.params->density.user;
  // A batch callback reads n positions at once (set if kBatchReads).
  auto read_many = [&](std::size_t n, const double* x, const double* y, double* rho) {
    q.params->density.batch_callback(user, n, x, y, rho);
  };
  auto density_at = [&](double x, double y) {  // DescentQuery::density_at, its kind known
    return kKind == QueryDensity::Kind::kImage ? sampler.at(x, y) : density_or_zero(callback(user, x, y));
  };
  QueryPoint* const out = sink.out;
  const std::size_t capacity = sink.capacity;
  std::size_t written = sink.written;
  std::uint64_t budget = sink.budget;
  const QueryParams& p = *q.params;
  const double x0 = p.x0, y0 = p.y0, x1 = p.x1, y1 = p.y1;
  const Tile& tile = set.tiles[n.type];
  const TilePoint* points = tile.points.data();
  const float* thresholds = t.thresholds[n.type].data();
  const std::uint32_t* start = t.glide_start[n.type].data();
  const std::uint32_t* present = t.points_at_keyframe[n.type].data();
  const std::int8_t* glide = tile.glide.data();
  const double s = q.side[n.depth], area = q.area[n.depth], wx = n.wx, wy = n.wy, rx = n.rx, ry = n.ry;
  const std::int64_t gx = n.gx, gy = n.gy;
  const std::uint32_t depth = n.depth, keyframes = q.keyframes.n;
  const SubtileCull cut = c;
  std::uint32_t segment = 0;  // the keyframes whose count the ranks from here on are present at
  double lo_x = 0, hi_x = 0, lo_y = 0, hi_y = 0;
  auto set_reach = [&](double reach) {
    lo_x = cut.x0 - reach * 65536.0, hi_x = cut.x1 + reach * 65536.0;
    lo_y = cut.y0 - reach * 65536.0, hi_y = cut.y1 + reach * 65536.0;
  };
  if (kClip) set_reach(t.glide_reach_from[0]);
  // A batch callback reads up to kDensityBatch positions a call: the visited ranks' stable positions
  // (gathered below), and the emitted ones' glided positions (a batch of as many).
  static_assert(!kBatchReads || kKind == QueryDensity::Kind::kCallback);
  constexpr int kBatch = kBatchReads ? int(kDensityBatch) : 32;
  constexpr std::size_t kGather = kBatchReads ? kDensityBatch : 1;
  double read_x[kGather], read_y[kGather];  // the gathered ranks' stable positions
  std::uint32_t read_at[kGather];           // and the ranks
  double glided_x[kGather], glided_y[kGather], glided_rho[kGather];
  std::uint32_t rank[kBatch];
  double count[kBatch];
  int pending = 0;
  const bool together = p.glide_together;  // a varying density: glide_count.h, as emit_tile.h does
  auto flush = [&]() -> std::uint32_t {    // kDescentDone, or the rank that did not fit
    const std::int8_t *o0[kBatch], *o1[kBatch];
    double w0[kBatch], w1[kBatch];
    if (together && pending > 0) {
      double sx[kBatch], sy[kBatch], own[kBatch];
      std::copy(count, count + pending, own);
      for (int i = 0; i < pending; ++i)
        sx[i] = wx + points[rank[i]].unit_x() * s, sy[i] = wy + points[rank[i]].unit_y() * s;
      glide_counts(
          own, sx, sy, std::size_t(pending), s, area,
          [&](std::size_t reads, const double* cx, const double* cy, double* value) {
            if constexpr (kBatchReads) {
              read_many(reads, cx, cy, value);
              for (std::size_t r = 0; r < reads; ++r) value[r] = density_or_zero(value[r]);
            } else {
              for (std::size_t r = 0; r < reads; ++r) value[r] = density_at(cx[r], cy[r]);
            }
          },
          count);
    }
    for (int i = 0; i < pending; ++i) {
      const GlideBracket g(q.keyframes, count[i]);
      o0[i] = glide + 2 * (std::size_t(start[g.g0]) + rank[i]);
      o1[i] = glide + 2 * (std::size_t(start[g.g1]) + rank[i]);
      w0[i] = g.w0, w1[i] = g.w1;
    }
    if constexpr (kBatchReads) {  // the glided positions in the region, read in one call
      std::size_t reads = 0;
      for (int i = 0; i < pending; ++i) {
        const TilePoint& p = points[rank[i]];
        const double dx = double(o0[i][0]) * w0[i] + double(o1[i][0]) * w1[i],
                     dy = double(o0[i][1]) * w0[i] + double(o1[i][1]) * w1[i];
        const double x = wx + (p.unit_x() + dx * (1.0 / 65536.0)) * s,
                     y = wy + (p.unit_y() + dy * (1.0 / 65536.0)) * s;
        if (!(kClip && (x < x0 || x >= x1 || y < y0 || y >= y1))) glided_x[reads] = x, glided_y[reads++] = y;
      }
      if (reads > 0) read_many(reads, glided_x, glided_y, glided_rho);
    }
    for (int i = 0, k = 0; i < pending; ++i) {
      const TilePoint& p = points[rank[i]];
      const double dx = double(o0[i][0]) * w0[i] + double(o1[i][0]) * w1[i],
                   dy = double(o0[i][1]) * w0[i] + double(o1[i][1]) * w1[i];
      const double ux = p.unit_x() + dx * (1.0 / 65536.0), uy = p.unit_y() + dy * (1.0 / 65536.0);
      // write's tests: in the region (a subtile inside it needs none), and where the density is not 0.
      const double x = wx + ux * s, y = wy + uy * s;
      if (kClip && (x < x0 || x >= x1 || y < y0 || y >= y1)) continue;
      if (!((kBatchReads ? density_or_zero(glided_rho[k++]) : density_at(x, y)) > 0)) continue;
      if (written == capacity) return pending = 0, rank[i];
      out[written++] = QueryPoint{rx + ux * s, ry + uy * s, PointId{gx, gy, rank[i], depth}};
    }
    pending = 0;
    return kDescentDone;
  };
  // A gathered rank r, emitted by its count at its stable position: queued as the loop below queues one.
  // kDescentDone, or the rank that did not fit.
  auto decide = [&](std::uint32_t r, double rho) -> std::uint32_t {
    const double expected = rho * area;
    rank[pending] = r, count[pending] = expected;
    pending += TilesetShape::emits(thresholds[r], expected);
    return pending == kBatch ? flush() : kDescentDone;
  };
  const std::uint32_t* it = kListed ? std::lower_bound(cut.listed, cut.listed_end, from) : nullptr;
  std::uint32_t r = kListed ? (it != cut.listed_end ? std::min(*it, end) : end) : from;
  // A batch callback's visited ranks wait in read_at with their positions until kGather are gathered.
  std::size_t gathered = 0;
  double visited_rho[kGather];
  auto decide_gathered = [&]() -> std::uint32_t {
    read_many(gathered, read_x, read_y, visited_rho);
    const std::size_t m = gathered;
    gathered = 0;
    for (std::size_t i = 0; i < m; ++i) {
      const std::uint32_t stopped = decide(read_at[i], density_or_zero(visited_rho[i]));
      if (stopped != kDescentDone) return stopped;
    }
    return kDescentDone;
  };
  while (r < end) {
    if (budget == 0) {
      std::uint32_t stopped = kBatchReads && gathered > 0 ? decide_gathered() : kDescentDone;
      if (stopped == kDescentDone) stopped = flush();
      sink.written = written, sink.budget = budget;
      return stopped != kDescentDone ? stopped : r;
    }
    --budget;
    const TilePoint q = points[r];
    bool visit = true;
    if (kClip) {
      if (segment < keyframes && present[segment] <= r) {
        while (segment < keyframes && present[segment] <= r) ++segment;
        set_reach(t.glide_reach_from[segment - 1]);
      }
      const double sx = q.x + 0.5, sy = q.y + 0.5;
      visit = sx >= lo_x && sx < hi_x && sy >= lo_y && sy < hi_y;
    }
    if (visit) {
      const double x = wx + q.unit_x() * s, y = wy + q.unit_y() * s;
      if constexpr (kBatchReads) {
        read_x[gathered] = x, read_y[gathered] = y, read_at[gathered++] = r;
      } else {
        const double expected = density_at(x, y) * area;
        // Queued at the next slot, which only an emitted rank keeps (no branch to mispredict).
        rank[pending] = r, count[pending] = expected;
        pending += TilesetShape::emits(thresholds[r], expected);
        if (pending == kBatch) {
          const std::uint32_t stopped = flush();
          if (stopped != kDescentDone) return sink.written = written, sink.budget = budget, stopped;
        }
      }
    }
    if (kListed) {
      ++it;
      r = it != cut.listed_end ? std::min(*it, end) : end;
    } else {
      ++r;
    }
    if (kBatchReads && (gathered == kGather || (gathered > 0 && r >= end))) {
      const std::uint32_t stopped = decide_gathered();
      if (stopped != kDescentDone) return sink.written = written, sink.budget = budget, stopped;
    }
  }
  if (kBatchReads && gathered > 0) {
    const std::uint32_t stopped = decide_gathered();
    if (stopped != kDescentDone) return sink.written = written, sink.budget = budget, stopped;
  }
  const std::uint32_t stopped = flush();
  sink.written = written, sink.budget = budget;
  return stopped;
}

/// emit_varying for the query's kind of density (not a constant).
template <bool kClip, bool kListed>
std::uint32_t emit_varying_any(const DescentQuery& q, const DescentNode& n, DescentSink& sink,
                               std::uint32_t from, std::uint32_t end, const SubtileCull& c) {
  using K = QueryDensity::Kind;
  if (q.params->density.kind == K::kImage)
    return emit_varying<K::kImage, kClip, kListed>(q, n, sink, from, end, c);
  return q.params->density.batch_callback
             ? emit_varying<K::kCallback, kClip, kListed, true>(q, n, sink, from, end, c)
             : emit_varying<K::kCallback, kClip, kListed>(q, n, sink, from, end, c);
}

}  // namespace kdm::detail
