#include "tile_torus.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "kdm/analysis/empty_circles.h"
#include "kdm/generator/bake.h"
#include "kdm/generator/sampler.h"

namespace kdm::verify {

std::vector<double> torus_points(const TilesetData& set, std::size_t t, double count,
                                 std::vector<double>* own, std::vector<double>* others) {
  std::vector<double> all;
  const std::vector<std::vector<float>> coarsest = coarsest_level_thresholds(set);
  for (int ty = 0; ty < 2; ++ty)
    for (int tx = 0; tx < 2; ++tx) {
      const std::size_t index = gen::tile_around(set.colours, t, tx, ty);
      const Tile& tile = set.tiles[index];
      for (std::uint32_t k = 0, i = 0; k < set.levels; ++k)
        for (; i < tile.level_end[k]; ++i) {
          const float threshold = k == 0 ? coarsest[index][i] : set.emission_threshold(k, tile.keys[i]);
          if (!TilesetShape::emits(threshold, count)) continue;
          const double x = (tx + tile.points[i].unit_x()) / 2, y = (ty + tile.points[i].unit_y()) / 2;
          all.insert(all.end(), {x, y});
          std::vector<double>* part = (tx == 0 && ty == 0) ? own : others;
          if (part) part->insert(part->end(), {x, y});
        }
    }
  return all;
}

TilePositions stable_positions(const TilesetData& set, double count) {
  TilePositions at(set.tiles.size());
  const std::vector<std::vector<float>> coarsest = coarsest_level_thresholds(set);
  for (std::size_t t = 0; t < set.tiles.size(); ++t) {
    const Tile& tile = set.tiles[t];
    for (std::uint32_t k = 0, i = 0; k < set.levels; ++k)
      for (; i < tile.level_end[k] &&
             TilesetShape::emits(k == 0 ? coarsest[t][i] : set.emission_threshold(k, tile.keys[i]), count);
           ++i)
        at[t].insert(at[t].end(), {tile.points[i].unit_x(), tile.points[i].unit_y()});
  }
  return at;
}

double closest_across_edges(const TilesetData& set, const TilePositions& at, double cutoff) {
  // A pair closer than the cutoff has both points within (largest glide + cutoff) of the edge: each
  // point's stable position lies on its own side. Points past the ranked ones do not move.
  double glide = 0;
  for (std::size_t t = 0; t < at.size(); ++t)
    for (std::size_t i = 0; i < std::min(at[t].size(), 2 * set.tiles[t].points.size()); i += 2) {
      const TilePoint& p = set.tiles[t].points[i / 2];
      glide = std::max({glide, std::fabs(at[t][i] - p.unit_x()), std::fabs(at[t][i + 1] - p.unit_y())});
    }
  const double band = glide + cutoff;
  const std::uint32_t C = set.colours;
  double best = cutoff;
  std::vector<std::array<double, 2>> low, high;  // (along the edge, across it), across measured from the edge
  for (std::size_t a = 0; a < set.tiles.size(); ++a) {
    const auto se = static_cast<std::uint32_t>(a / (C * C) % C), ne = static_cast<std::uint32_t>(a / C % C),
               nw = static_cast<std::uint32_t>(a % C);
    for (int axis = 0; axis < 2; ++axis)  // 0: the tile to the right, 1: the tile above
      for (std::uint32_t c1 = 0; c1 < C; ++c1)
        for (std::uint32_t c2 = 0; c2 < C; ++c2) {
          const std::size_t b = axis ? set.tile_index(nw, ne, c1, c2) : set.tile_index(se, c1, c2, ne);
          low.clear(), high.clear();
          for (std::size_t i = 0; i < at[a].size(); i += 2)
            if (at[a][i + axis] > 1 - band) low.push_back({at[a][i + 1 - axis], at[a][i + axis] - 1});
          for (std::size_t i = 0; i < at[b].size(); i += 2)
            if (at[b][i + axis] < band) high.push_back({at[b][i + 1 - axis], at[b][i + axis]});
          std::sort(high.begin(), high.end());
          for (const auto& p : low) {
            auto it = std::lower_bound(high.begin(), high.end(), std::array<double, 2>{p[0] - best, -1e300});
            for (; it != high.end() && (*it)[0] < p[0] + best; ++it)
              best = std::min(best, std::hypot((*it)[0] - p[0], (*it)[1] - p[1]));
          }
        }
  }
  return best;
}

gen::SamplerOptions torus_options(double temperature, double side, int threads) {
  gen::SamplerOptions o;
  o.temperature = temperature;
  o.extent[0] = o.extent[1] = side;
  o.threads = threads;
  // The baker's arithmetic (bake.cpp): a set's verdict, like its tiles, must not change between kdm versions.
  o.numerics = gen::Numerics::kOriginal;
  // The sampler as the baker runs it: constrained runs are never balanced, so neither is the reference.
  o.count_balance = false;
  return o;
}

Relaxed relax(const std::vector<double>& own, const std::vector<double>& others, double side,
              double temperature, double spacing, std::uint64_t seed, int threads) {
  std::vector<double> all = own;
  all.insert(all.end(), others.begin(), others.end());
  const gen::SamplerOptions model = torus_options(temperature, side, threads);
  const double before = gen::energy_per_point(model, gen::Density::constant(), all);
  // Not `o` for the energy after: with fixed points the model is scaled for n + fixed points.
  gen::SamplerOptions o = model;
  o.initial_points = own;
  o.fixed_points = others;
  o.sweeps = 15;
  o.burn_in_sweeps = 0;
  o.seed = seed;
  const gen::SampleResult r = gen::sample(o, gen::Density::constant());
  std::vector<double> after = r.points;
  after.insert(after.end(), others.begin(), others.end());
  Relaxed out;
  out.drop = 1 - gen::energy_per_point(model, gen::Density::constant(), after) / before;
  for (std::size_t i = 0; i < own.size(); i += 2) {
    double dx = std::fabs(r.points[i] - own[i]), dy = std::fabs(r.points[i + 1] - own[i + 1]);
    dx = std::min(dx, 1 - dx), dy = std::min(dy, 1 - dy);
    out.drift += std::hypot(dx, dy);
  }
  out.drift /= double(own.size() / 2) * spacing;
  return out;
}

void TorusHoles::add(const std::vector<double>& coords) {
  if (coords.size() >= 6) tori_.push_back({2, coords, {}, {}, {}});
}

void TorusHoles::measure(int threads, Holes& holes) const {
  if (tori_.empty()) return;
  analysis::EmptyCircleOptions o;
  o.threads = threads;
  const analysis::EmptyCircles e = analysis::empty_circles(tori_, o);
  holes.measured = true;
  holes.largest = std::max(holes.largest, e.largest);
  holes.over_085 += e.over_085, holes.points += e.points;
}

void check_holes(const Holes& holes, const Bars& bars, std::vector<Check>& checks) {
  if (!holes.measured) return;
  if (bars.hole_largest > 0) checks.push_back({"largest hole", holes.largest, bars.hole_largest, true});
  if (bars.holes_per_1e5 > 0) checks.push_back({"holes per 1e5", holes.per_1e5(), bars.holes_per_1e5, true});
}

std::vector<double> densities(const TilesetData& set, const std::vector<std::uint32_t>& levels) {
  std::vector<double> out;
  for (std::uint32_t k : levels) {
    const double lo = k ? set.level_nominal[k - 1] : 0.0, hi = set.level_nominal[k];
    for (int quarter = k ? 1 : 4; quarter <= 4; ++quarter) out.push_back(lo + (hi - lo) * quarter / 4);
  }
  return out;
}

}  // namespace kdm::verify
