// Part 5 of the generator test (verify.h): the glide track. For every keyframe, over every tile's 2×2
// torus, the points at their keyframe positions (δavg, closest pair), the same half-way to the next
// keyframe (where the points present glide between two relaxed sets), and how far the points move from
// one keyframe to the next, in mean nearest-neighbour distances of the later one.
#include <algorithm>
#include <cmath>
#include <limits>

#include "kdm/analysis/common.h"
#include "kdm/analysis/nearest_neighbour.h"
#include "kdm/generator/bake.h"
#include "kdm/verify/verify.h"
#include "tile_torus.h"

namespace kdm::verify {
namespace {

/// Where each keyframe's offsets of tile `t` start in its glide array (in offset pairs).
std::vector<std::size_t> glide_starts(const TilesetData& set, const Tile& tile) {
  std::vector<std::size_t> start(set.keyframe_nominal.size() + 1, 0);
  for (std::size_t g = 0; g < set.keyframe_nominal.size(); ++g)
    start[g + 1] = start[g] + set.offsets_at_keyframe(tile, g);
  return start;
}

/// Tile `t`'s points at expected count `count` in smooth mode between keyframes g0 and g1 (fraction s
/// from g0), in its unit coordinates: its first ranks, which are those emitted.
std::vector<double> glided(const TilesetData& set, std::size_t t, double count, std::size_t g0,
                           std::size_t g1, double s) {
  const Tile& tile = set.tiles[t];
  const std::vector<std::size_t> start = glide_starts(set, tile);
  const double e0 = set.glide_unit(g0), e1 = set.glide_unit(g1);
  std::vector<double> out;
  const std::vector<float> coarsest = coarsest_level_thresholds(set)[t];
  for (std::uint32_t k = 0, i = 0; k < set.levels; ++k)
    for (; i < tile.level_end[k]; ++i) {
      if (!TilesetShape::emits(k == 0 ? coarsest[i] : set.emission_threshold(k, tile.keys[i]), count))
        return out;
      const std::int8_t* o0 = &tile.glide[2 * (start[g0] + i)];
      const std::int8_t* o1 = &tile.glide[2 * (start[g1] + i)];
      out.insert(out.end(), {tile.points[i].unit_x() + o0[0] * e0 + s * (o1[0] * e1 - o0[0] * e0),
                             tile.points[i].unit_y() + o0[1] * e0 + s * (o1[1] * e1 - o0[1] * e0)});
    }
  return out;
}

/// The 2×2 torus around tile `t` made of the tiles' points `at`, normalised to the unit square.
std::vector<double> glide_torus(const TilesetData& set, std::size_t t, const TilePositions& at) {
  std::vector<double> all;
  for (int ty = 0; ty < 2; ++ty)
    for (int tx = 0; tx < 2; ++tx) {
      const std::vector<double>& p = at[gen::tile_around(set.colours, t, tx, ty)];
      for (std::size_t i = 0; i < p.size(); i += 2) {
        const double u = (tx + p[i]) / 2, v = (ty + p[i + 1]) / 2;
        all.insert(all.end(), {u - std::floor(u), v - std::floor(v)});
      }
    }
  return all;
}

}  // namespace

bool keyframe_judged(const TilesetData& set, const std::vector<std::uint32_t>& levels, std::size_t g) {
  std::uint32_t level = 0;
  while (level + 1 < set.levels && set.keyframe_nominal[g] > set.level_nominal[level]) ++level;
  return std::find(levels.begin(), levels.end(), level) != levels.end();
}

void judge_keyframes(const TilesetData& set, const VerifyOptions& options, Report& report,
                     const std::function<void(double)>& done) {
  const Bars& b = options.bars;
  const std::size_t keyframes = set.keyframe_nominal.size();
  for (std::size_t g = 0; g < keyframes; ++g) {
    if (!keyframe_judged(set, options.levels, g)) continue;
    for (int half = 0; half < (g + 1 < keyframes ? 2 : 1); ++half) {
      KeyframeResult row;
      const double k0 = set.keyframe_nominal[g], k1 = g + 1 < keyframes ? set.keyframe_nominal[g + 1] : k0;
      row.points_per_tile = half ? (k0 + k1) / 2 : k0;
      row.keyframe = !half;
      std::vector<double> moves;
      TorusHoles holes;
      TilePositions at(set.tiles.size());
      for (std::size_t t = 0; t < set.tiles.size(); ++t)
        at[t] = glided(set, t, row.points_per_tile, g, half ? g + 1 : g, half ? 0.5 : 0.0);
      const double row_spacing = analysis::hex_spacing(std::size_t(row.points_per_tile));
      row.closest_pair = closest_across_edges(set, at, row_spacing) / row_spacing;
      for (std::size_t t = 0; t < set.tiles.size(); ++t) {
        const std::vector<double> coords = glide_torus(set, t, at);
        const std::size_t n = coords.size() / 2;
        done(double(n));
        if (n < 2) continue;
        analysis::NearestNeighbours nn;
        add_torus_nn(coords, set.tiles.size(), options.threads, nn, row);
        if (!half && options.holes) holes.add(coords);
        if (half || g == 0) continue;
        // Motion into this keyframe, of the tile's own points present at the last one (or entering there).
        const Tile& tile = set.tiles[t];
        const std::vector<std::size_t> start = glide_starts(set, tile);
        const double spacing = analysis::hex_spacing(std::size_t(k0));  // tile sides: d_hex at K_g
        for (std::uint32_t i = 0; i < set.offsets_at_keyframe(tile, g - 1); ++i) {
          const std::int8_t* a = &tile.glide[2 * (start[g - 1] + i)];
          const std::int8_t* c = &tile.glide[2 * (start[g] + i)];
          const double ea = set.glide_unit(g - 1), ec = set.glide_unit(g);
          moves.push_back(std::hypot(c[0] * ec - a[0] * ea, c[1] * ec - a[1] * ea) / spacing);
        }
      }
      holes.measure(options.threads, row.holes);
      if (!moves.empty()) {
        double sum = 0;
        for (double& m : moves) sum += (m /= row.davg);  // in mean nearest-neighbour distances
        row.motion_mean = sum / double(moves.size());
        row.motion_p99 = analysis::quantile(moves, 0.99);
        row.checks.push_back({"motion p99", row.motion_p99, b.glide_motion, true});
      } else {
        row.motion_mean = row.motion_p99 = std::numeric_limits<double>::quiet_NaN();
      }
      row.checks.push_back({"δavg", row.davg, half ? b.glide_between_davg : b.glide_keyframe_davg, false});
      if (b.glide_closest_pair > 0)
        row.checks.push_back({"closest pair", row.closest_pair, b.glide_closest_pair, false});
      check_holes(row.holes, b, row.checks);
      report.keyframes.push_back(std::move(row));
    }
  }
}

void judge_handover(const TilesetData& set, const VerifyOptions& options, Report& report,
                    const std::function<void(double)>& done) {
  const Bars& b = options.bars;
  const std::size_t top = set.keyframe_nominal.size() - 1;
  const Subdivision sub = set.subdivision();
  const std::uint32_t m = sub.m;
  const std::size_t h = set.handover_keyframe();
  const double n_top = set.level_nominal.back(), kh = set.keyframe_nominal[h];
  const double appearing_end = set.appearing_end(), top_step = n_top / set.keyframe_nominal[top - 1];
  TilePositions start(set.tiles.size()), at_handover(set.tiles.size());
  for (std::size_t t = 0; t < set.tiles.size(); ++t) {
    start[t] = glided(set, t, std::numeric_limits<double>::infinity(), top, top, 0);
    at_handover[t] = glided(set, t, kh, h, h, 0);
  }
  // Each tile's points (rank order) as the sub-point each glides onto (subtile, rank) and the count where
  // its subtile takes it over, and its appearing sub-points.
  struct SubRef {
    std::uint32_t i, k, rank;
    std::size_t type;
    double end = 0;
  };
  std::vector<std::vector<SubRef>> target(set.tiles.size()), appearing(set.tiles.size());
  std::vector<std::vector<std::size_t>> subtiles(set.tiles.size());
  std::vector<double> ends, speeds;  // speeds: glides per top keyframe interval, in d_hex at N_top
  for (std::size_t t = 0; t < set.tiles.size(); ++t) {
    for (std::uint32_t k = 0; k < m; ++k)
      for (std::uint32_t i = 0; i < m; ++i) subtiles[t].push_back(set.subtile_index(t, i, k));
    const Tile& tile = set.tiles[t];
    for (std::size_t r = 0; r < tile.points.size(); ++r) {
      const std::uint32_t v = tile.handover[r], d = v % 25;
      SubRef q{TilesetShape::subtile_of(tile.points[r].x, m) + d % 5 - 2,
               TilesetShape::subtile_of(tile.points[r].y, m) + d / 5 - 2, v / 25, 0};
      q.type = subtiles[t][q.k * m + q.i];
      const double gx = (q.i + at_handover[q.type][2 * q.rank]) / m - start[t][2 * r],
                   gy = (q.k + at_handover[q.type][2 * q.rank + 1]) / m - start[t][2 * r + 1];
      const double glide = std::hypot(gx, gy) * std::sqrt(n_top);  // as the runtime's tables
      q.end = set.handover_end(glide);
      ends.push_back(q.end);
      speeds.push_back(glide * std::log(top_step) / std::log(q.end / n_top) /
                       (analysis::hex_spacing(std::size_t(n_top)) * std::sqrt(n_top)));
      target[t].push_back(q);
    }
    for (std::uint32_t w : tile.appearing) {
      const std::uint32_t j = w >> 16;
      appearing[t].push_back({j % m, j / m, w & 0xFFFF, subtiles[t][j], 0});
    }
  }
  // Judged at `handover_rows` even steps to where 99% of the points have arrived and every appearing
  // point has appeared.
  const double end = std::max(analysis::quantile(ends, 0.99), appearing_end);
  const int rows = std::max(1, options.handover_rows);
  for (int i = 1; i <= rows; ++i) {
    KeyframeResult row;
    row.points_per_tile = n_top + double(i) / rows * (end - n_top);
    row.keyframe = false;
    row.handover = true;
    row.motion_mean = row.motion_p99 = std::numeric_limits<double>::quiet_NaN();
    // The subtiles' points at their count, on their glide track (at keyframe h until it passes K_h).
    const double count = std::max(kh, row.points_per_tile / (double(m) * m));
    std::size_t g0 = h;
    while (g0 + 1 < top && set.keyframe_nominal[g0 + 1] <= count) ++g0;
    const double w = std::clamp(
        (count - set.keyframe_nominal[g0]) / (set.keyframe_nominal[g0 + 1] - set.keyframe_nominal[g0]), 0.0,
        1.0);
    TilePositions sub_at(set.tiles.size());
    for (std::size_t t = 0; t < set.tiles.size(); ++t) sub_at[t] = glided(set, t, count, g0, g0 + 1, w);
    const auto place = [&](const SubRef& q, double& x, double& y) {
      x = (q.i + sub_at[q.type][2 * q.rank]) / m, y = (q.k + sub_at[q.type][2 * q.rank + 1]) / m;
    };
    TilePositions at(set.tiles.size());
    for (std::size_t t = 0; t < set.tiles.size(); ++t) {
      double x, y;
      for (std::size_t i = 0; i < target[t].size(); ++i) {  // each on its straight path, by its own end
        place(target[t][i], x, y);
        const double f = std::min(1.0, (row.points_per_tile - n_top) / (target[t][i].end - n_top));
        at[t].insert(at[t].end(), {start[t][2 * i] + f * (x - start[t][2 * i]),
                                   start[t][2 * i + 1] + f * (y - start[t][2 * i + 1])});
      }
      const std::size_t n = appearing[t].size();
      for (std::size_t a = 0; a < n; ++a)  // thresholds spread evenly over (N_top, m² K_h], in table order
        if (row.points_per_tile > n_top + (double(a) + 0.5) / double(n) * (appearing_end - n_top)) {
          place(appearing[t][a], x, y);
          at[t].insert(at[t].end(), {x, y});
        }
      // The subtiles' own points past keyframe h, present once their count passes K_h.
      for (std::uint32_t j = 0; j < m * m; ++j) {
        const std::size_t type = subtiles[t][j];
        for (std::size_t q = set.points_at_keyframe(set.tiles[type], h); 2 * q < sub_at[type].size(); ++q)
          at[t].insert(at[t].end(),
                       {(j % m + sub_at[type][2 * q]) / m, (j / m + sub_at[type][2 * q + 1]) / m});
      }
    }
    const double row_spacing = analysis::hex_spacing(std::size_t(row.points_per_tile));
    row.closest_pair = closest_across_edges(set, at, row_spacing) / row_spacing;
    for (std::size_t t = 0; t < set.tiles.size(); ++t) {
      const std::vector<double> coords = glide_torus(set, t, at);
      done(double(coords.size() / 2));
      analysis::NearestNeighbours nn;
      add_torus_nn(coords, set.tiles.size(), options.threads, nn, row);
    }
    row.checks.push_back({"δavg", row.davg, b.glide_between_davg, false});
    if (b.handover_closest_pair > 0)
      row.checks.push_back({"closest pair", row.closest_pair, b.handover_closest_pair, false});
    if (i == rows) {  // each glide per top keyframe interval of the scale it spans, as keyframes' motion
      double sum = 0;
      for (double& v : speeds) sum += (v /= row.davg);
      row.motion_mean = sum / double(speeds.size());
      row.motion_p99 = analysis::quantile(speeds, 0.99);
      row.checks.push_back({"motion p99", row.motion_p99, b.glide_motion, true});
    }
    report.keyframes.push_back(std::move(row));
  }
}

}  // namespace kdm::verify
