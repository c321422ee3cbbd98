// Runtime queries over a baked tile set; see kdm/runtime/query.h.
#include "kdm/runtime/query.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "cell_index.h"
#include "descent.h"
#include "emit_tile.h"
#include "fingerprint.h"
#include "image_sampler.h"
#include "kdm/runtime/compact_query.h"
#include "keyframe_lookup.h"
#include "query_counted.h"
#include "query_tables.h"

namespace kdm {

using detail::density_or_zero;
using detail::GlideBracket;
using detail::ImageSampler;
using detail::keyframe_table;
using detail::KeyframeTable;
using detail::QueryTables;

namespace {

using detail::CompactSink;
using detail::PointSink;

bool finite(double v) {
  return std::isfinite(v);
}

/// Tile (tx, ty), set tile `index`, and its subtiles from `at` on into `out` (descent.h's
/// emit_descending); false when the buffer filled or the budget ran out first, with `at` where to resume.
bool emit_descending_into(const detail::DescentQuery& descent, std::int64_t tx, std::int64_t ty,
                          std::size_t index, PointSink out, std::size_t capacity, std::size_t& n,
                          std::uint64_t& budget, detail::DescentPlace& at) {
  return detail::emit_descending(descent, tx, ty, index, out.points, capacity, n, budget, at);
}

/// The same for another sink, through QueryPoint records on the stack: the descent's own loops write
/// those, and past the top level the glide, not the writing, sets the speed.
template <class Sink>
bool emit_descending_into(const detail::DescentQuery& descent, std::int64_t tx, std::int64_t ty,
                          std::size_t index, Sink out, std::size_t capacity, std::size_t& n,
                          std::uint64_t& budget, detail::DescentPlace& at) {
  constexpr std::size_t kStage = 256;
  QueryPoint stage[kStage];
  for (;;) {
    const std::size_t room = std::min(kStage, capacity - n);
    std::size_t staged = 0;
    const bool done = detail::emit_descending(descent, tx, ty, index, stage, room, staged, budget, at);
    if constexpr (detail::kPutsRecords<Sink>)
      out.put_records(n, stage, staged);
    else
      for (std::size_t i = 0; i < staged; ++i) out.put(n + i, stage[i].x, stage[i].y, stage[i].id);
    n += staged;
    if (done) return true;
    if (staged < room || n == capacity) return false;  // the budget ran out, or the caller's buffer is full
  }
}

/// query_points over the tiles of `run` into any sink (emit_tile.h); `has_room` is false for a null output
/// with room in it.
template <class Sink>
Status query_into(const Tileset& tileset, const QueryParams& q, Sink out, bool has_room, const char* out_name,
                  std::size_t capacity, std::size_t* written, QueryCursor* cursor, detail::Refusal& refuse,
                  std::uint64_t& examined, const detail::TileRun& run) {
  QueryProblem& why = refuse.problem();
  using Kind = QueryProblem::Kind;
  if (written) *written = 0;
  if (!written) return refuse(Kind::kMissingArgument, "written");
  if (!cursor) return refuse(Kind::kMissingArgument, "cursor");
  if (capacity > 0 && !has_room) return refuse(Kind::kMissingArgument, out_name);
  if (tileset.empty()) return refuse(Kind::kMissingArgument, "tileset");
  const QueryTables& tables = detail::TilesetInternals::tables(tileset);
  const std::pair<const char*, double> numbers[] = {{"x0", q.x0},
                                                    {"y0", q.y0},
                                                    {"x1", q.x1},
                                                    {"y1", q.y1},
                                                    {"origin_x", q.origin_x},
                                                    {"origin_y", q.origin_y},
                                                    {"tile_size", q.tile_size},
                                                    {"scale", q.scale}};
  for (const auto& [name, value] : numbers)
    if (!finite(value)) return refuse(Kind::kNotFinite, name, value);
  if (!(q.tile_size > 0)) return refuse(Kind::kNotPositive, "tile_size", q.tile_size);
  if (q.scale < 0) return refuse(Kind::kNegative, "scale", q.scale);
  if (q.mode != QueryMode::kStable && q.mode != QueryMode::kSmooth)
    return refuse(Kind::kBadMode, "mode", static_cast<double>(static_cast<int>(q.mode)));
  // A constant is the caller's number, not a value read at a point: one that is no density is refused.
  if (q.density.kind == QueryDensity::Kind::kConstant && !finite(q.density.constant))
    return refuse(Kind::kNotFinite, "density.constant", q.density.constant);
  if (q.density.kind == QueryDensity::Kind::kConstant && q.density.constant < 0)
    return refuse(Kind::kNegative, "density.constant", q.density.constant);
  const std::uint64_t fingerprint = query_fingerprint(q) ^ tables.identity;  // these parameters on this set
  if (cursor->started && cursor->fingerprint != fingerprint) return refuse(Kind::kCursorMismatch, "cursor");
  // Past 9e15 tiles out a region's sides round together ([x0, x0 + 64) at 1e18 is empty): too far, not empty.
  // Sides given the wrong way round are the caller's empty region, however far.
  const double far_x = std::max(std::fabs(q.x0), std::fabs(q.x1)),
               far_y = std::max(std::fabs(q.y0), std::fabs(q.y1));
  if (!cursor->finished && std::max(far_x, far_y) / q.tile_size > 9e15 && (q.x1 == q.x0 || q.y1 == q.y0))
    return refuse(Kind::kTooFarFromOrigin, far_x >= far_y ? "x0" : "y0", std::max(far_x, far_y),
                  9e15 * q.tile_size);
  if (cursor->finished || !(q.x1 > q.x0) || !(q.y1 > q.y0) || q.scale == 0) {
    *cursor = QueryCursor{cursor->tile_x, cursor->tile_y, cursor->rank, true, true, fingerprint};
    return Status::kOk;
  }
  const QueryDensity& d = q.density;
  double max_density = 0;
  switch (d.kind) {
    case QueryDensity::Kind::kConstant:
      max_density = density_or_zero(d.constant);
      break;
    case QueryDensity::Kind::kImage:
      if (!d.image || !detail::image_queryable(*d.image)) return refuse(Kind::kBadDensity, "density.image");
      max_density = d.image->max_over(q.x0, q.y0, q.x1, q.y1);
      break;
    case QueryDensity::Kind::kCallback:
      if (!d.callback == !d.batch_callback)  // neither or both: which one is meant is unclear
        return refuse(Kind::kBadDensity, d.callback ? "density.batch_callback" : "density.callback");
      if (!finite(d.callback_max)) return refuse(Kind::kNotFinite, "density.callback_max", d.callback_max);
      if (d.callback_max < 0) return refuse(Kind::kNegative, "density.callback_max", d.callback_max);
      max_density = d.callback_max;
      break;
    default:  // not a Kind: a cast, or memory the caller never set
      return refuse(Kind::kBadDensity, "density.kind", static_cast<double>(static_cast<int>(d.kind)));
  }
  const double S = q.tile_size, area_scale = S * S * q.scale;
  const ImageSampler sampler(d.kind == QueryDensity::Kind::kImage ? d.image : nullptr);
  const double top = tileset.max_points_per_tile(), most = query_density_limit(tileset, q.mode);
  if (!(max_density * area_scale <= most + 0.5)) {
    // A tile side whose square overflows is the one at fault, not the scale.
    refuse(Kind::kDensityTooHigh, std::isfinite(S * S) ? "scale" : "tile_size", max_density * area_scale,
           most);
    why.largest_valid = most / max_density / S / S;  // divided in turn: a product could overflow
    why.largest_tile_size = std::sqrt(most / max_density) / std::sqrt(q.scale);
    return Status::kInvalidArgument;
  }
  // The region's own tiles, whatever its density (a tile size in the wrong units is refused, not answered
  // with no points); the visit below adds a margin of a few tiles for glides and rounding.
  const double region_tiles =
      (std::ceil(q.x1 / S) - std::floor(q.x0 / S)) * (std::ceil(q.y1 / S) - std::floor(q.y0 / S));
  if (!std::isfinite(region_tiles))  // tiles too small to count in a double: the tile size is wrong
    return refuse(Kind::kTooManyTiles, "tile_size", region_tiles, double(kMaxQueryTiles));
  if (!(region_tiles <= double(kMaxQueryTiles)))
    return refuse(Kind::kTooManyTiles, "x0", region_tiles, double(kMaxQueryTiles));
  // Smooth mode visits the tiles whose points can glide into the region too: as far as any glides at the
  // keyframes a constant density's points sit between, or at any keyframe up to a varying one's maximum.
  // Past the top level, where tiles hand over to their subtiles, every keyframe's reach bounds the way.
  const bool glide = q.mode == QueryMode::kSmooth && tileset.has_glide_track();
  const bool descend = glide && tables.subtiles > 0 && max_density * area_scale > top;
  double reach = 0;
  if (glide) {
    const GlideBracket top(keyframe_table(tileset), max_density * area_scale);
    for (std::uint32_t g = d.kind == QueryDensity::Kind::kConstant ? top.g0 : 0; g <= top.g1; ++g)
      reach = std::max(reach, tables.glide_reach[g] * S);
    if (descend) reach = std::max(reach, tables.descent_reach * S) + S * (2.0 / 65536.0);
  }
  // Far out a position's rounding (under 1.5 ulp of the coordinate, less than 2^-50 of it) can carry a
  // point across its tile's side, at most S/131072 from it: onto a region's side that is a tile's, where a
  // chunk beyond it would not visit the tile. Where that can happen, the tiles that near are visited too.
  // (A region too thin to span a tile column or row, its side rounded onto the other, stays empty.)
  const double coordinate = std::max({std::fabs(q.x0), std::fabs(q.x1), std::fabs(q.y0), std::fabs(q.y1)});
  const bool spans = std::ceil((q.x1 + reach) / S) > std::floor((q.x0 - reach) / S) &&
                     std::ceil((q.y1 + reach) / S) > std::floor((q.y0 - reach) / S);
  const double rounding =
      spans && std::ldexp(coordinate, -50) >= S * 0x1p-18 ? std::ldexp(coordinate, -50) : 0.0;
  const double tx0d = std::floor((q.x0 - reach - rounding) / S),
               tx1d = std::ceil((q.x1 + reach + rounding) / S);
  const double ty0d = std::floor((q.y0 - reach - rounding) / S),
               ty1d = std::ceil((q.y1 + reach + rounding) / S);
  if (!(max_density * area_scale > tables.min_threshold)) {  // no tile can emit even its first point
    *cursor = QueryCursor{cursor->tile_x, cursor->tile_y, cursor->rank, true, true, fingerprint};
    return Status::kOk;
  }
  // Depth-0 positions are summed in world units and a point's place in the region is decided in them: a
  // double's step there (at most 2^-52 of the distance) must stay below a 16th of the spacing at depth 0,
  // or positions fall together, and below a quarter of the region's side where the region is wider than
  // the spacing at the density's depth, or regions lose their points. A region narrower than that spacing
  // (a sliver a chunk loop's rounding leaves) holds its points, if any, by the same test as any other.
  const double far = std::max({std::fabs(q.x0), std::fabs(q.x1), std::fabs(q.y0), std::fabs(q.y1)});
  const double spacing = S / std::sqrt(std::min(max_density * area_scale, top));
  const double deepest_spacing = S / std::sqrt(max_density * area_scale);
  const double side = std::max(std::min(q.x1 - q.x0, q.y1 - q.y0), deepest_spacing);
  const double farthest = std::ldexp(std::min(spacing / 16, side / 4), 52);
  // Tile coordinates must fit an int64 exactly, and past the top level so must the subtiles' (m^depth
  // times the tile's): farther out is too far from the world origin, whatever the spacing. The limit
  // stated is the nearer of the two, so that a region moved within it is served.
  const double most_tiles =
      descend ? std::min(9e15, std::ldexp(1.0, 62) / std::pow(double(tables.subtiles), kMaxQueryDepth))
              : 9e15;
  if (std::fabs(tx0d) > most_tiles || std::fabs(tx1d) > most_tiles)
    return refuse(Kind::kTooFarFromOrigin, "x0", std::max(std::fabs(q.x0), std::fabs(q.x1)),
                  std::min(most_tiles * S, farthest));
  if (std::fabs(ty0d) > most_tiles || std::fabs(ty1d) > most_tiles)
    return refuse(Kind::kTooFarFromOrigin, "y0", std::max(std::fabs(q.y0), std::fabs(q.y1)),
                  std::min(most_tiles * S, farthest));
  const std::int64_t tx0 = static_cast<std::int64_t>(tx0d), tx1 = static_cast<std::int64_t>(tx1d);
  const std::int64_t ty0 = static_cast<std::int64_t>(ty0d), ty1 = static_cast<std::int64_t>(ty1d);
  if (tx1 <= tx0 || ty1 <= ty0) {  // x1 / S rounded onto x0 / S: no tile column (or row) to visit at all
    *cursor = QueryCursor{cursor->tile_x, cursor->tile_y, cursor->rank, true, true, fingerprint};
    return Status::kOk;
  }
  if (far > farthest)
    return refuse(Kind::kTooFarFromOrigin, far == std::fabs(q.x0) || far == std::fabs(q.x1) ? "x0" : "y0",
                  far, farthest);
  // The output is relative to the query's origin, exactly past the top level too (integer tile paths),
  // but it is written in doubles or floats: the origin must lie near enough for their steps to keep the
  // densest points apart.
  const double out_x = std::max(std::fabs(q.x0 - q.origin_x), std::fabs(q.x1 - q.origin_x)),
               out_y = std::max(std::fabs(q.y0 - q.origin_y), std::fabs(q.y1 - q.origin_y));
  // A float output also loses a tile's points where its step reaches a tile, whatever the density, and
  // ends at 3.4e38: one limit, the smaller, so that a caller moving the origin within it is served.
  const double out_farthest =
      Sink::kOriginSpanBits < 48
          ? std::min({std::ldexp(deepest_spacing, Sink::kOriginSpanBits), 1e38, std::ldexp(S, 23)})
          : std::ldexp(deepest_spacing, Sink::kOriginSpanBits);
  if (std::max(out_x, out_y) > out_farthest)
    return refuse(Kind::kTooFarFromOrigin, out_x >= out_y ? "origin_x" : "origin_y", std::max(out_x, out_y),
                  out_farthest);
  if (!cursor->started) {  // at the first tile of the run the query visits
    std::int64_t sx = tx0, sy = ty0;
    if (run.from_y > ty0 || (run.from_y == ty0 && run.from_x > tx0)) {
      sy = run.from_y, sx = std::max(run.from_x, tx0);
      if (sx >= tx1) ++sy, sx = tx0;
    }
    *cursor = QueryCursor{sx, sy, 0, true, false, fingerprint};
  } else {
    // A saved cursor stopped in a tile of the region and the run: a damaged one is refused, not walked
    // from afar (a call ran for seconds) nor taken past tiles it never visited (their points lost).
    const std::int64_t x = cursor->tile_x, y = cursor->tile_y;
    const bool in_run = (y > run.from_y || (y == run.from_y && x >= run.from_x)) &&
                        (y < run.to_y || (y == run.to_y && x < run.to_x));
    if (x < tx0 || x >= tx1 || y < ty0 || y >= ty1 || !in_run) return refuse(Kind::kCursorMismatch, "cursor");
  }
  // A cursor inside a tile's subtiles names them by a path of subtile indices: a damaged one is refused.
  if (cursor->depth > (descend ? kMaxQueryDepth : 0)) return refuse(Kind::kCursorMismatch, "cursor");
  for (std::uint32_t k = 0; k < cursor->depth; ++k)
    if ((cursor->path >> (16 * k) & 0xFFFF) >= std::uint64_t(tables.subtiles) * tables.subtiles)
      return refuse(Kind::kCursorMismatch, "cursor");
  std::optional<detail::DescentQuery> descent;
  if (descend) descent.emplace(tileset, q, sampler);

  std::size_t n = 0;
  const detail::EmitTile<Sink> emit_edge = detail::pick_emitter<Sink, false>(glide, d.kind),
                               emit_inside = detail::pick_emitter<Sink, true>(glide, d.kind),
                               emit_listed = detail::pick_emitter<Sink, false, true>(glide, d.kind);
  detail::TileJob job{};
  job.tables = &tables;
  job.keyframes = keyframe_table(tileset);
  job.S = S, job.x0 = q.x0, job.y0 = q.y0, job.x1 = q.x1, job.y1 = q.y1;
  job.origin_x = q.origin_x, job.origin_y = q.origin_y, job.area_scale = area_scale;
  job.density = &d, job.sampler = &sampler;
  job.glide_together = q.glide_together;
  for (std::int64_t ty = cursor->tile_y; ty < ty1 && ty <= run.to_y; ++ty) {
    const double wy = double(ty) * S;
    const std::int64_t row_end = ty == run.to_y ? std::min(tx1, run.to_x) : tx1;
    for (std::int64_t tx = (ty == cursor->tile_y ? cursor->tile_x : tx0); tx < row_end; ++tx) {
      const bool resumed = tx == cursor->tile_x && ty == cursor->tile_y;
      // A tile visited counts as kTileCandidates candidates examined (about what it costs), so that a call
      // over many tiles with few candidates or none (a sparse density) is bounded too.
      if (!resumed && examined >= kMaxQueryCandidates) {
        *cursor = QueryCursor{tx, ty, 0, true, false, fingerprint};
        *written = n;
        return Status::kBufferFull;
      }
      examined = std::min(examined + kTileCandidates, kMaxQueryCandidates);
      const std::size_t index = tileset.tile_index_at(tx, ty);
      const Tile& tile = tileset.data().tiles[index];
      const float* thresholds = tables.thresholds[index].data();
      const double wx = double(tx) * S;
      // Bounds of the density over the tile (in smooth mode widened by the glide, where a point's density
      // is read a second time): below lo a point is emitted wherever it lies, above the bound never.
      double bound = max_density, lo = 0;
      if (d.kind == QueryDensity::Kind::kImage) {
        bound = d.image->max_over(wx, wy, wx + S, wy + S);
        lo = glide ? d.image->min_over(wx - reach, wy - reach, wx + S + reach, wy + S + reach)
                   : d.image->min_over(wx, wy, wx + S, wy + S);
      } else if (d.kind == QueryDensity::Kind::kCallback && d.bounds) {
        const double r = glide ? reach : 0;
        detail::density_bounds(d, wx - r, wy - r, wx + S + r, wy + S + r, lo, bound);
      }
      // Thresholds are sorted: the points below bound · A · scale are a prefix; none beyond can be emitted.
      const double limit = bound * area_scale;
      const std::uint32_t candidates = static_cast<std::uint32_t>(
          std::lower_bound(thresholds, thresholds + tile.points.size(), limit,
                           [](float t, double l) { return TilesetShape::emits(t, l); }) -
          thresholds);
      if (descend && limit > top) {  // the tile hands over to its subtiles somewhere: descent.h
        detail::DescentPlace at;
        if (resumed) at = detail::DescentPlace{cursor->depth, cursor->path, cursor->rank};
        std::uint64_t budget = kMaxQueryCandidates - examined;
        const std::uint64_t before = budget;
        const bool done = emit_descending_into(*descent, tx, ty, index, out, capacity, n, budget, at);
        examined += before - budget;
        if (!done) {
          *cursor = QueryCursor{tx, ty, at.rank, true, false, fingerprint, at.depth, at.path};
          *written = n;
          return Status::kBufferFull;
        }
        continue;
      }
      if (resumed && (cursor->depth != 0 || cursor->rank > tile.points.size()))
        return refuse(Kind::kCursorMismatch, "cursor");
      const std::uint32_t c = resumed ? cursor->rank : 0;
      if (c >= candidates) continue;
      // Bounded work per call, whatever the region and density.
      const std::uint64_t budget = kMaxQueryCandidates - examined;
      const std::uint32_t end = candidates - c > budget ? static_cast<std::uint32_t>(c + budget) : candidates;
      job.points = tile.points.data(), job.thresholds = thresholds, job.tx = tx, job.ty = ty;
      job.wx = wx, job.wy = wy, job.limit = limit;
      // Stable mode: the ranks emitted wherever they lie, less a margin for a bilinear or callback value
      // that equals lo rounding below it.
      job.sure = 0;
      // A callback's cells (emit_tile.h): an image's texel is read faster than its cell tested.
      job.cells = !glide && d.kind == QueryDensity::Kind::kCallback && d.bounds;
      if (!glide && lo > 0)
        job.sure = static_cast<std::uint32_t>(
            std::lower_bound(thresholds, thresholds + candidates, lo * area_scale * (1 - 1e-9),
                             [](float t, double l) { return TilesetShape::emits(t, l); }) -
            thresholds);
      job.rel_unit = static_cast<float>(S / 65536.0);
      job.rel_x = static_cast<float>((wx - q.origin_x) + S * (0.5 / 65536.0));
      job.rel_y = static_cast<float>((wy - q.origin_y) + S * (0.5 / 65536.0));
      if (glide) {
        job.glide = tile.glide.data(), job.starts = tables.glide_start[index].data();
        job.ranks = tables.points_at_keyframe[index].data();
        // The region in the tile's 1/65536 units, widened by a unit so that the culling is never stricter
        // than the exact test after the glide; a constant density's points glide as far as the two
        // keyframes around it let them.
        job.cull_x0 = (q.x0 - wx) / S * 65536.0 - 1, job.cull_x1 = (q.x1 - wx) / S * 65536.0 + 1;
        job.cull_y0 = (q.y0 - wy) / S * 65536.0 - 1, job.cull_y1 = (q.y1 - wy) / S * 65536.0 + 1;
        if (d.kind == QueryDensity::Kind::kConstant) {
          const GlideBracket b(job.keyframes, limit);
          job.reach = std::max(tables.glide_reach[b.g0], tables.glide_reach[b.g1]);
          // Rounding of world coordinates, in position units: two, and a few ulps of the largest involved.
          const double units = 65536.0 / S;
          const double slack = 2 + 1e-15 * units *
                                       (std::fabs(wx) + std::fabs(wy) + std::fabs(q.x0) + std::fabs(q.x1) +
                                        std::fabs(q.y0) + std::fabs(q.y1) + S);
          const double r = job.reach * 65536.0 + slack + 0.5;  // a cell's centre is half a unit in
          auto cells = [&](double lo, double hi, std::int32_t& first, std::uint32_t& count) {
            lo = std::max(std::ceil(lo + r), 0.0), hi = std::min(std::floor(hi - r), 65536.0);
            first = hi > lo ? std::int32_t(lo) : 0, count = hi > lo ? std::uint32_t(hi - lo) : 0;
          };
          cells((q.x0 - wx) * units, (q.x1 - wx) * units, job.safe_x, job.safe_w);
          cells((q.y0 - wy) * units, (q.y1 - wy) * units, job.safe_y, job.safe_h);
        }
        // Beside the region only the points that can glide across the side it lies beyond can be emitted.
        job.listed = job.listed_end = nullptr;
        tables.edges_beyond(index, job.cull_x0, job.cull_y0, job.cull_x1, job.cull_y1, job.listed,
                            job.listed_end);
        job.zero_possible = !(lo > 0);
      }
      // Inside: the tile widened by the farthest any of its points can glide (and two position units, for
      // rounding) lies in the region. Such tiles skip every test, and the positions are computed as
      // elsewhere. Without a glide the test is exact: a position rounds monotonically in its grid cell, so
      // the tile's first and last cells bound every point (a region of whole tiles has no edge tiles).
      const double margin = reach + S * (2.0 / 65536.0);
      const TilePoint first{0, 0}, last{65535, 65535};
      const bool inside = glide ? wx - margin >= q.x0 && wx + S + margin < q.x1 && wy - margin >= q.y0 &&
                                      wy + S + margin < q.y1
                                : wx + first.unit_x() * S >= q.x0 && wx + last.unit_x() * S < q.x1 &&
                                      wy + first.unit_y() * S >= q.y0 && wy + last.unit_y() * S < q.y1;
      // A region meeting few of a tile's cells (QueryTables::cell_ranks) visits only their points: those
      // whose stable position lies within the glide's reach (and rounding) of it; beside the region, where
      // they are fewer than the edge list's (a region shorter than the tile's side).
      detail::CellSpan span{0, detail::kIndexCells - 1, 0, detail::kIndexCells - 1};
      if (!inside && !tables.cell_ranks.empty()) {
        const double units = 65536.0 / S;
        const double r =
            (glide ? (d.kind == QueryDensity::Kind::kConstant ? job.reach : tables.glide_reach_from[0]) : 0) *
                65536.0 +
            2 +
            1e-15 * units *
                (std::fabs(wx) + std::fabs(wy) + std::fabs(q.x0) + std::fabs(q.x1) + std::fabs(q.y0) +
                 std::fabs(q.y1) + S);
        span = detail::cells_met((q.x0 - wx) * units - r, (q.y0 - wy) * units - r, (q.x1 - wx) * units + r,
                                 (q.y1 - wy) * units + r);
      }
      constexpr double kCells = detail::kIndexCells * detail::kIndexCells;
      const double share = span.count() / kCells;  // of the tile's points the cells hold, about
      // A listed candidate costs a few times what a scanned one does in records, a tenth of that again in
      // the compact output's vector passes; both outputs take one path, so that a cursor serves both.
      if (share <= 0.5 &&
          (!job.listed || share * double(tile.points.size()) < double(job.listed_end - job.listed))) {
        // Cell by cell (QueryCursor::path names the cell a stop left off in, plus one).
        detail::CellPlace at{0, c};
        if (resumed && cursor->path != 0) {
          if (cursor->path > span.count()) return refuse(Kind::kCursorMismatch, "cursor");
          at.cell = static_cast<std::uint32_t>(cursor->path - 1);
        }
        std::uint64_t left = budget;
        const bool done =
            detail::emit_cells(tables, index, span, job, at, candidates, left, emit_listed, out, capacity, n);
        examined += budget - left;
        if (!done) {
          *cursor = QueryCursor{tx, ty, at.rank, true, false, fingerprint, 0, std::uint64_t(at.cell) + 1};
          *written = n;
          return Status::kBufferFull;
        }
        continue;
      }
      if (resumed && cursor->path != 0) return refuse(Kind::kCursorMismatch, "cursor");
      const std::uint32_t stopped = (inside       ? emit_inside
                                     : job.listed ? emit_listed
                                                  : emit_edge)(job, c, end, out, capacity, n);
      examined += stopped - c;
      if (stopped < candidates) {  // the buffer is full, or the budget spent
        *cursor = QueryCursor{tx, ty, stopped, true, false, fingerprint};
        *written = n;
        return Status::kBufferFull;
      }
    }
  }
  cursor->finished = true;
  *written = n;
  return Status::kOk;
}

}  // namespace

Status query_points(const Tileset& tileset, const QueryParams& q, QueryPoint* out, std::size_t capacity,
                    std::size_t* written, QueryCursor* cursor, QueryProblem* problem) {
  std::uint64_t examined = detail::first_examined(q, false, 0);
  return detail::query_points_counted(tileset, q, out, capacity, written, cursor, problem, examined);
}

Status detail::query_points_counted(const Tileset& tileset, const QueryParams& q, QueryPoint* out,
                                    std::size_t capacity, std::size_t* written, QueryCursor* cursor,
                                    QueryProblem* problem, std::uint64_t& examined,
                                    const detail::TileRun& run) {
  detail::Refusal refuse(problem);
  return query_into(tileset, q, PointSink{out}, out != nullptr, "out", capacity, written, cursor, refuse,
                    examined, run);
}

Status count_points(const Tileset& tileset, const QueryParams& q, std::size_t* count, QueryCursor* cursor,
                    QueryProblem* problem) {
  detail::Refusal refuse(problem);
  if (!count) return refuse(QueryProblem::Kind::kMissingArgument, "count");
  // A counting cursor's fingerprint differs from a query's, so that one is never resumed as the other.
  constexpr std::uint64_t kCounting = 0x636f756e74696e67;  // "counting"
  const bool started = cursor && cursor->started;
  if (started) cursor->fingerprint ^= kCounting;
  std::uint64_t examined = 0;
  const Status s = query_into(tileset, q, detail::CountSink{}, true, "out",
                              std::numeric_limits<std::size_t>::max(), count, cursor, refuse, examined, {});
  if (cursor && cursor->started) cursor->fingerprint ^= kCounting;
  return s;
}

Status detail::count_points(const Tileset& tileset, const QueryParams& q, std::size_t* count,
                            QueryCursor* cursor, const TileRun& run) {
  detail::Refusal refuse(nullptr);
  std::uint64_t examined = 0;
  return query_into(tileset, q, detail::CountSink{}, true, "out", std::numeric_limits<std::size_t>::max(),
                    count, cursor, refuse, examined, run);
}

Status detail::compact_refusal(const Tileset& tileset, bool keys, Refusal& refuse) {
  if (keys && !tileset.empty()) {
    const std::uint64_t most = detail::TilesetInternals::tables(tileset).most_points;
    if (most > (std::uint64_t(1) << kKeyRankBits))
      return refuse(QueryProblem::Kind::kKeysUnsupported, "out.keys", double(most),
                    double(std::uint64_t(1) << kKeyRankBits));
  }
  return Status::kOk;
}

namespace {

/// The sink that classes points into `c.classes` as it writes them into `base`.
template <class Base>
detail::ClassSink<Base> class_sink(Base base, const detail::ConstantClasses& c) {
  return detail::ClassSink<Base>{base, c.classes, c.counts, c.last, c.class_of_id, c.user};
}
template <class Base>
detail::VaryingClassSink<Base> class_sink(Base base, const detail::VaryingClasses& c) {
  return detail::VaryingClassSink<Base>{base, &c};
}

}  // namespace

template <class Classes>
Status detail::query_classes_counted(const Tileset& tileset, const QueryParams& q, QueryPoint* out,
                                     const Classes& classes, std::size_t capacity, std::size_t* written,
                                     QueryCursor* cursor, QueryProblem* problem, std::uint64_t& examined,
                                     const TileRun& run) {
  detail::Refusal refuse(problem);
  return query_into(tileset, q, class_sink(PointSink{out}, classes), out && classes.classes, "out", capacity,
                    written, cursor, refuse, examined, run);
}

template <class Classes>
Status detail::query_classes_counted(const Tileset& tileset, const QueryParams& q,
                                     const CompactPoints& compact, const Classes& classes,
                                     std::size_t capacity, std::size_t* written, QueryCursor* cursor,
                                     QueryProblem* problem, std::uint64_t& examined, const TileRun& run) {
  detail::Refusal refuse(problem);
  if (written) *written = 0;
  if (compact_refusal(tileset, compact.keys != nullptr, refuse) != Status::kOk)
    return Status::kInvalidArgument;
  const bool room = compact.xy && classes.classes;
  if (compact.keys)
    return query_into(tileset, q, class_sink(CompactSink<true>{compact.xy, compact.keys}, classes), room,
                      "out.xy", capacity, written, cursor, refuse, examined, run);
  return query_into(tileset, q, class_sink(CompactSink<false>{compact.xy, nullptr}, classes), room, "out.xy",
                    capacity, written, cursor, refuse, examined, run);
}

// The two kinds of classes class_query.cpp runs.
template Status detail::query_classes_counted(const Tileset&, const QueryParams&, QueryPoint*,
                                              const ConstantClasses&, std::size_t, std::size_t*, QueryCursor*,
                                              QueryProblem*, std::uint64_t&, const TileRun&);
template Status detail::query_classes_counted(const Tileset&, const QueryParams&, const CompactPoints&,
                                              const ConstantClasses&, std::size_t, std::size_t*, QueryCursor*,
                                              QueryProblem*, std::uint64_t&, const TileRun&);
template Status detail::query_classes_counted(const Tileset&, const QueryParams&, QueryPoint*,
                                              const VaryingClasses&, std::size_t, std::size_t*, QueryCursor*,
                                              QueryProblem*, std::uint64_t&, const TileRun&);
template Status detail::query_classes_counted(const Tileset&, const QueryParams&, const CompactPoints&,
                                              const VaryingClasses&, std::size_t, std::size_t*, QueryCursor*,
                                              QueryProblem*, std::uint64_t&, const TileRun&);

Status query_points_compact(const Tileset& tileset, const QueryParams& q, const CompactPoints& out,
                            std::size_t capacity, std::size_t* written, QueryCursor* cursor,
                            QueryProblem* problem) {
  return detail::query_compact_run(tileset, q, out, capacity, written, cursor, problem, {});
}

Status detail::query_compact_run(const Tileset& tileset, const QueryParams& q, const CompactPoints& out,
                                 std::size_t capacity, std::size_t* written, QueryCursor* cursor,
                                 QueryProblem* problem, const TileRun& run) {
  detail::Refusal refuse(problem);
  std::uint64_t examined = detail::first_examined(q, false, 0);
  if (written) *written = 0;
  if (detail::compact_refusal(tileset, out.keys != nullptr, refuse) != Status::kOk)
    return Status::kInvalidArgument;
  if (!out.keys)
    return query_into(tileset, q, CompactSink<false>{out.xy, nullptr}, out.xy != nullptr, "out.xy", capacity,
                      written, cursor, refuse, examined, run);
  return query_into(tileset, q, CompactSink<true>{out.xy, out.keys}, out.xy != nullptr, "out.xy", capacity,
                    written, cursor, refuse, examined, run);
}

double query_density_limit(const Tileset& tileset, QueryMode mode) {
  const double top = tileset.max_points_per_tile();
  const std::uint32_t m = tileset.empty() ? 0 : detail::TilesetInternals::tables(tileset).subtiles;
  if (mode != QueryMode::kSmooth || m == 0) return top;
  return top * std::pow(double(m), 2.0 * kMaxQueryDepth);
}

TileSizeAdvice tile_size_advice(const Tileset& tileset, double max_density, double scale, double tile_size) {
  TileSizeAdvice advice;
  const auto positive = [](double v) { return v > 0 && v < HUGE_VAL; };
  if (tileset.empty() || !positive(max_density) || !positive(scale) || !positive(tile_size)) return advice;
  advice.points_per_tile = max_density * scale * tile_size * tile_size;
  advice.coarsest = tileset.data().level_nominal.empty() ? 0 : tileset.data().level_nominal.front();
  advice.tiles = tileset.data().tiles.size();
  advice.tile_size = std::sqrt(advice.coarsest / max_density) / std::sqrt(scale);  // apart: no overflow
  if (advice.points_per_tile < 1)
    advice.kind = TileSizeAdvice::Kind::kUnderOnePoint;
  else if (advice.points_per_tile < advice.coarsest * (1 - 1e-9))  // the advised size itself, rounded, fits
    advice.kind = TileSizeAdvice::Kind::kUnderCoarsestLevel;
  return advice;
}

namespace {

/// The index in data().tiles of the tile point `id` belongs to, at any depth; kNoTile for a depth the set
/// does not have.
constexpr std::size_t kNoTile = ~std::size_t(0);
std::size_t tile_type_of(const Tileset& tileset, const PointId& id) {
  // No query reaches tiles this far out, and the corner colours' tx + 1 must not overflow.
  constexpr std::int64_t kFarthestTile = std::int64_t(1) << 62;
  if (tileset.empty() || id.tile_x < -kFarthestTile || id.tile_x > kFarthestTile ||
      id.tile_y < -kFarthestTile || id.tile_y > kFarthestTile)
    return kNoTile;
  if (id.depth == 0) return tileset.tile_index_at(id.tile_x, id.tile_y);
  const QueryTables& tables = detail::TilesetInternals::tables(tileset);
  const std::int64_t m = tables.subtiles;
  if (m == 0 || id.depth > kMaxQueryDepth) return kNoTile;
  // The depth-0 tile and the subtile path down from it: the digits of the coordinates in base m.
  std::int64_t x = id.tile_x, y = id.tile_y, digits[kMaxQueryDepth];
  for (std::uint32_t d = id.depth; d-- > 0;) {
    const std::int64_t cx = ((x % m) + m) % m, cy = ((y % m) + m) % m;
    digits[d] = cy * m + cx;
    x = (x - cx) / m, y = (y - cy) / m;
  }
  std::size_t type = tileset.tile_index_at(x, y);
  for (std::uint32_t d = 0; d < id.depth; ++d)
    type = tables.child_type[type * std::size_t(m * m) + std::size_t(digits[d])];
  return type;
}

}  // namespace

const Tile* tile_of(const Tileset& tileset, const PointId& id) {
  const std::size_t type = tile_type_of(tileset, id);
  return type == kNoTile ? nullptr : &tileset.data().tiles[type];
}

double emission_threshold(const Tileset& tileset, const PointId& id) {
  const std::size_t type = tile_type_of(tileset, id);
  if (type == kNoTile) return -1;
  const auto& thresholds = detail::TilesetInternals::tables(tileset).thresholds[type];
  if (id.rank >= thresholds.size()) return -1;
  const double own = thresholds[id.rank];
  // Only ranks a subtile inherits (those present at the hand-over keyframe) come from its parent: later
  // ones are its own, emitted by their own thresholds.
  const QueryTables& tables = detail::TilesetInternals::tables(tileset);
  if (id.depth == 0 || id.rank >= tables.points_at_keyframe[type][tables.handover_keyframe]) return own;
  // A sub-point that no point of its parent glides onto appears in the parent's hand-over, at the count
  // its place in the parent's appearing list gives (descent.cpp), whatever its own threshold (mostly far
  // below): found by a scan of that list (m² K_h − N_top entries, about 900 in the built-in set).
  const TilesetData& set = tileset.data();
  const std::int64_t m = set.subtiles_per_side();
  const std::int64_t cx = ((id.tile_x % m) + m) % m, cy = ((id.tile_y % m) + m) % m;
  const std::size_t parent =
      tile_type_of(tileset, PointId{(id.tile_x - cx) / m, (id.tile_y - cy) / m, 0, id.depth - 1});
  if (parent == kNoTile || id.rank > 0xFFFF) return own;
  const auto& listed = set.tiles[parent].appearing;
  const std::uint32_t wanted = std::uint32_t(cy * m + cx) << 16 | id.rank;
  const auto at = std::find(listed.begin(), listed.end(), wanted);
  if (at == listed.end()) return own;
  const double top = set.keyframe_nominal.back(), a = double(at - listed.begin());
  const double appears = top + (a + 0.5) / double(listed.size()) * (set.appearing_end() - top);
  return appears / double(m * m);  // in the sub-point's own tile's count
}

bool stable_position(const Tileset& tileset, const PointId& id, double tile_size, double origin_x,
                     double origin_y, double* x, double* y) {
  const Tile* tile = tile_of(tileset, id);
  if (!tile || !x || !y || id.rank >= tile->points.size() || !(tile_size > 0 && tile_size < HUGE_VAL))
    return false;
  const double side = tile_size / std::pow(double(tileset.data().subtiles_per_side()), id.depth);
  const TilePoint& p = tile->points[id.rank];
  // The tile's corner less the origin first: far from the world's origin the tile's own digits survive.
  *x = (double(id.tile_x) * side - origin_x) + p.unit_x() * side;
  *y = (double(id.tile_y) * side - origin_y) + p.unit_y() * side;
  return true;
}

std::uint64_t query_fingerprint(const QueryParams& q) {
  detail::Fingerprint f(0x6b646d71756572ull);  // "kdmquer"
  for (double v : {q.x0, q.y0, q.x1, q.y1, q.origin_x, q.origin_y, q.tile_size, q.scale, q.density.constant,
                   q.density.callback_max})
    f.add_double(v);
  f.add(static_cast<std::uint64_t>(q.density.kind));
  f.add(static_cast<std::uint64_t>(q.mode));
  f.add(q.glide_together ? 1 : 0);
  f.add_pointer(q.density.image);
  f.add_pointer(reinterpret_cast<const void*>(q.density.callback));
  f.add_pointer(reinterpret_cast<const void*>(q.density.batch_callback));
  f.add_pointer(q.density.user);
  f.add_pointer(reinterpret_cast<const void*>(q.density.bounds));
  return f.value();
}

}  // namespace kdm
