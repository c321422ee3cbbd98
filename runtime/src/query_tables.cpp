// The tables a loaded Tileset keeps for the query loop (query_tables.h), built once per load.
#include "query_tables.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "fingerprint.h"
#include "keyframe_lookup.h"

namespace kdm::detail {

QueryTables::QueryTables(const TilesetData& set) {
  // Thresholds once per load, so the query loop compares instead of interpolating.
  thresholds.assign(set.tiles.size(), {});
  for (std::size_t t = 0; t < set.tiles.size(); ++t) thresholds[t].resize(set.tiles[t].points.size());
  coarsest_level_thresholds_into(set, thresholds);
  for (std::size_t t = 0; t < set.tiles.size(); ++t) {
    const Tile& tile = set.tiles[t];
    TilesetArray<float>& out = thresholds[t];
    for (std::uint32_t k = 1, i = tile.level_end[0]; k < set.levels; ++k)
      for (; i < tile.level_end[k]; ++i) out[i] = set.emission_threshold(k, tile.keys[i]);
  }
  // The points and glides in 8-byte words (under a millisecond for the built-in set), the thresholds.
  Fingerprint f(0x6b646d74696c6573ull);  // "kdmtiles"
  const auto add_bytes = [&f](const void* data, std::size_t size) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    f.add(size);
    for (std::size_t i = 0; i < size; i += 8) {
      std::uint64_t word = 0;
      std::memcpy(&word, bytes + i, std::min<std::size_t>(8, size - i));
      f.add(word);
    }
  };
  for (std::size_t t = 0; t < set.tiles.size(); ++t) {
    add_bytes(set.tiles[t].points.data(), set.tiles[t].points.size() * sizeof(TilePoint));
    add_bytes(set.tiles[t].glide.data(), set.tiles[t].glide.size());
    add_bytes(thresholds[t].data(), thresholds[t].size() * sizeof(float));
  }
  identity = f.value();
  min_threshold = HUGE_VAL;
  for (const TilesetArray<float>& t : thresholds) {
    if (!t.empty()) min_threshold = std::min(min_threshold, double(t.front()));
    most_points = std::max(most_points, std::uint64_t(t.size()));
  }
  // Where each keyframe's offsets start in every tile, their units, and how far any point glides.
  const std::size_t keyframes = set.keyframe_nominal.size();
  glide_start.assign(set.tiles.size(), {});
  glide_reach.assign(keyframes, 0.0);
  glide_scale.assign(keyframes, 0.0);
  for (std::size_t g = 0; g < keyframes; ++g) glide_scale[g] = 65536.0 * set.glide_unit(g);
  keyframe_guess.assign(kCountBuckets, 0);
  for (int b = 0; b < kCountBuckets; ++b) {  // the first keyframe at least the bucket's smallest count
    const double lowest =
        std::ldexp(1.0 + double(b % kBucketsPerOctave) / kBucketsPerOctave, b / kBucketsPerOctave - 32);
    const std::uint32_t* k = set.keyframe_nominal.data();
    keyframe_guess[b] = static_cast<std::uint16_t>(std::lower_bound(k, k + keyframes, lowest) - k);
  }
  keyframe_one_step = true;  // no bucket holds two keyframes (true unless they are under 3.1% apart)
  for (int b = 0; b + 1 < kCountBuckets; ++b)
    keyframe_one_step = keyframe_one_step && keyframe_guess[b + 1] <= keyframe_guess[b] + 1;
  points_at_keyframe.assign(set.tiles.size(), {});
  for (std::size_t t = 0; t < set.tiles.size() && keyframes > 0; ++t) {
    TilesetArray<std::uint32_t>& start = glide_start[t];
    start.assign(keyframes + 1, 0);
    points_at_keyframe[t].assign(keyframes, 0);
    for (std::size_t g = 0; g < keyframes; ++g) {
      start[g + 1] = start[g] + set.offsets_at_keyframe(set.tiles[t], g);
      points_at_keyframe[t][g] = set.points_at_keyframe(set.tiles[t], g);
      int largest = 0;
      for (std::size_t i = 2 * std::size_t(start[g]); i < 2 * std::size_t(start[g + 1]); ++i)
        largest = std::max(largest, std::abs(int(set.tiles[t].glide[i])));
      glide_reach[g] = std::max(glide_reach[g], largest * set.glide_unit(g));
    }
  }
  glide_reach_from.assign(keyframes, 0.0);
  for (std::size_t g = keyframes; g-- > 0;)
    glide_reach_from[g] = std::max(glide_reach[g], g + 1 < keyframes ? glide_reach_from[g + 1] : 0.0);
  keyframe_nominal.assign(keyframes + 1, HUGE_VAL);
  for (std::size_t g = 0; g < keyframes; ++g) keyframe_nominal[g] = set.keyframe_nominal[g];
  glide_spans.assign(keyframes ? keyframes + 1 : 0, {});
  for (std::size_t g = 0; g < glide_spans.size(); ++g) {
    GlideSpan& span = glide_spans[g];
    span.g0 = static_cast<std::uint32_t>(g - (g > 0)),
    span.g1 = static_cast<std::uint32_t>(g - (g == keyframes));
    span.base = keyframe_nominal[span.g0];
    if (span.g1 > span.g0) span.inverse_gap = 1.0 / (keyframe_nominal[span.g1] - keyframe_nominal[span.g0]);
    span.scale0 = glide_scale[span.g0], span.scale1 = glide_scale[span.g1];
  }
  index_edges(set);
  index_cells(set);
  index_handover(set);
}

void QueryTables::index_cells(const TilesetData& set) {
  constexpr std::uint32_t kCells = kIndexCells * kIndexCells, kShift = 16 - kIndexCellBits;
  // Tiles of fewer points than cells are scanned whole at little cost, and their index would cost more
  // than they hold (4 KB a tile: 270 MB for a 16-colour set of a few points a tile).
  if (most_points > 65536 || most_points < kCells) return;
  cell_start.assign((kCells + 1) * set.tiles.size(), 0);
  cell_ranks.assign(set.tiles.size(), {});
  for (std::size_t t = 0; t < set.tiles.size(); ++t) {
    const TilesetArray<TilePoint>& points = set.tiles[t].points;
    std::uint32_t* start = cell_start.data() + (kCells + 1) * t;
    auto cell = [&](const TilePoint& p) { return (p.y >> kShift) * kIndexCells + (p.x >> kShift); };
    for (const TilePoint& p : points) ++start[cell(p) + 1];
    for (std::uint32_t k = 0; k < kCells; ++k) start[k + 1] += start[k];
    TilesetArray<std::uint16_t>& ranks = cell_ranks[t];
    ranks.resize(points.size());
    std::uint32_t next[kCells];
    std::copy(start, start + kCells, next);
    for (std::uint32_t r = 0; r < points.size(); ++r)
      ranks[next[cell(points[r])]++] = static_cast<std::uint16_t>(r);
  }
}

void QueryTables::index_handover(const TilesetData& set) {
  const Subdivision sub = set.subdivision();
  if (set.handover_zone == 0 || sub.m == 0 || set.keyframe_nominal.size() < 2) return;
  const std::uint32_t m = subtiles = sub.m, m2 = m * m;
  const std::size_t h = handover_keyframe = static_cast<std::uint32_t>(set.handover_keyframe());
  child_type.assign(set.tiles.size() * m2, 0);
  inherited_start.assign(set.tiles.size() * (m2 + 1), 0);
  inherited.assign(set.tiles.size(), {});
  handover_end.assign(set.tiles.size(), {});
  handover_end_max.assign(set.tiles.size(), 0.0);
  const std::size_t top = set.keyframe_nominal.size() - 1;
  for (std::size_t t = 0; t < set.tiles.size(); ++t) {
    std::uint32_t* start = inherited_start.data() + t * (m2 + 1);
    for (std::uint32_t j = 0; j < m2; ++j) {
      const std::size_t c = set.subtile_index(t, j % m, j / m);
      child_type[t * m2 + j] = static_cast<std::uint32_t>(c);
      start[j + 1] = start[j] + points_at_keyframe[c][h];
    }
    TilesetArray<std::uint32_t>& from = inherited[t];
    from.assign(start[m2], kAppearing);
    const Tile& tile = set.tiles[t];
    for (std::uint32_t r = 0; r < tile.handover.size(); ++r) {  // validated: each sub-point named once
      const std::uint32_t v = tile.handover[r], d = v % 25;
      const std::uint32_t j = (TilesetShape::subtile_of(tile.points[r].y, m) + d / 5 - 2) * m +
                              TilesetShape::subtile_of(tile.points[r].x, m) + d % 5 - 2;
      if (j < m2 && start[j] + v / 25 < start[j + 1]) from[start[j] + v / 25] = r;  // validated: always
    }
    for (std::uint32_t a = 0; a < tile.appearing.size(); ++a) {
      const std::uint32_t w = tile.appearing[a], j = w >> 16, q = w & 0xFFFF;
      if (j < m2 && start[j] + q < start[j + 1]) from[start[j] + q] = kAppearing | a;  // validated: always
    }
    // Each point's glide, top-keyframe position to sub-point's position at keyframe h (tile units), in
    // spacings 1/√N_top; the expressions descent.cpp's positions use.
    handover_end[t].assign(tile.points.size(), 0.0f);
    for (std::uint32_t j = 0; j < m2; ++j) {
      const Tile& child = set.tiles[child_type[t * m2 + j]];
      for (std::uint32_t q = 0; q < start[j + 1] - start[j]; ++q) {
        const std::uint32_t r = from[start[j] + q];
        if (appearing(r)) continue;
        const std::int8_t* a = tile.glide.data() + 2 * (std::size_t(glide_start[t][top]) + r);
        const std::int8_t* b =
            child.glide.data() + 2 * (std::size_t(glide_start[child_type[t * m2 + j]][h]) + q);
        const double ax = tile.points[r].unit_x() + a[0] * (glide_scale[top] / 65536.0),
                     ay = tile.points[r].unit_y() + a[1] * (glide_scale[top] / 65536.0);
        const double bx = (j % m + child.points[q].unit_x() + b[0] * (glide_scale[h] / 65536.0)) / m,
                     by = (j / m + child.points[q].unit_y() + b[1] * (glide_scale[h] / 65536.0)) / m;
        const double glide = std::hypot(bx - ax, by - ay) * std::sqrt(double(set.level_nominal.back()));
        handover_end[t][r] = static_cast<float>(set.handover_end(glide));
        handover_end_max[t] = std::max(handover_end_max[t], double(handover_end[t][r]));
        // The path's far end: the sub-point's stable position, and its glide at any count from K_h on.
        const double sub_reach = glide_reach_from[h] / m;
        const double ex = std::fabs((j % m + child.points[q].unit_x()) / m - tile.points[r].unit_x()),
                     ey = std::fabs((j / m + child.points[q].unit_y()) / m - tile.points[r].unit_y());
        handover_reach = std::max({handover_reach, ex + sub_reach, ey + sub_reach});
      }
    }
  }
  descent_reach = std::max(glide_reach_from[0], handover_reach);
}

void QueryTables::index_edges(const TilesetData& set) {
  edge_start.assign(5 * set.tiles.size(), 0);
  edge_ranks.assign(set.tiles.size(), {});
  if (set.keyframe_nominal.empty()) return;
  for (std::size_t t = 0; t < set.tiles.size(); ++t) {
    const Tile& tile = set.tiles[t];
    const std::uint32_t* ranks = points_at_keyframe[t].data();
    TilesetArray<std::uint32_t>& out = edge_ranks[t];
    for (int side = 0; side < 4; ++side) {
      std::size_t segment = 0;  // the keyframes whose count rank c is at least: it appears after the last
      for (std::uint32_t c = 0; c < tile.points.size(); ++c) {
        while (segment < points_at_keyframe[t].size() && ranks[segment] <= c) ++segment;
        // The same reach as the query's culling (emit_tile), so a point left out would be culled there.
        const double reach = glide_reach_from[segment ? segment - 1 : 0] * 65536.0 + kEdgeSlack;
        const double u = (side < 2 ? tile.points[c].x : tile.points[c].y) + 0.5;
        if ((side % 2 == 0) ? u < reach : u > 65536.0 - reach) out.push_back(c);
      }
      edge_start[5 * t + side + 1] = static_cast<std::uint32_t>(out.size());
    }
    // To its size by a copy: shrink_to_fit may swallow the allocator's refusal (it is only a request).
    TilesetArray<std::uint32_t>(out.begin(), out.end(), out.get_allocator()).swap(out);
  }
}

bool QueryTables::edges_beyond(std::size_t index, double cull_x0, double cull_y0, double cull_x1,
                               double cull_y1, const std::uint32_t*& begin, const std::uint32_t*& end) const {
  constexpr double kNear = kEdgeSlack / 2;
  const bool beyond[4] = {cull_x1 <= kNear, cull_x0 >= 65536.0 - kNear, cull_y1 <= kNear,
                          cull_y0 >= 65536.0 - kNear};
  std::uint32_t best = ~0u;
  for (int side = 0; side < 4; ++side) {
    std::uint32_t count = 0;
    const std::uint32_t* ranks = edges(index, side, count);
    if (beyond[side] && count < best) best = count, begin = ranks, end = ranks + count;
  }
  return best != ~0u;
}

namespace {

template <class T>
std::size_t nested_bytes(const TilesetArray<TilesetArray<T>>& v) {
  std::size_t bytes = v.capacity() * sizeof(TilesetArray<T>);
  for (const TilesetArray<T>& inner : v) bytes += inner.capacity() * sizeof(T);
  return bytes;
}

template <class T>
std::size_t flat_bytes(const TilesetArray<T>& v) {
  return v.capacity() * sizeof(T);
}

}  // namespace

std::size_t QueryTables::resident_bytes() const {
  return sizeof(*this) + nested_bytes(thresholds) + nested_bytes(glide_start) + flat_bytes(glide_reach) +
         flat_bytes(glide_reach_from) + flat_bytes(glide_scale) + nested_bytes(points_at_keyframe) +
         flat_bytes(keyframe_nominal) + flat_bytes(glide_spans) + flat_bytes(keyframe_guess) +
         nested_bytes(edge_ranks) + flat_bytes(edge_start) + nested_bytes(cell_ranks) +
         flat_bytes(cell_start) + flat_bytes(child_type) + nested_bytes(inherited) +
         flat_bytes(inherited_start) + nested_bytes(handover_end) + flat_bytes(handover_end_max);
}

std::uint32_t first_keyframe_at_least(const Tileset& set, double expected) {
  return set.has_glide_track() ? keyframe_table(set).first_at_least(expected) : 0;
}

}  // namespace kdm::detail
