#include "tile_torus.h"

#include <algorithm>
#include <cmath>

#include "kdm/analysis/empty_circles.h"
#include "kdm/generator/bake.h"
#include "kdm/generator/sampler.h"

namespace kdm::verify {

std::vector<double> torus_points(const TilesetData& set, std::size_t t, double count,
                                 std::vector<double>* own, std::vector<double>* others) {
  std::vector<double> all;
  for (int ty = 0; ty < 2; ++ty)
    for (int tx = 0; tx < 2; ++tx) {
      const Tile& tile = set.tiles[gen::tile_around(set.colours, t, tx, ty)];
      for (std::uint32_t k = 0, i = 0; k < set.levels; ++k)
        for (; i < tile.level_end[k]; ++i) {
          if (!TilesetShape::emits(set.emission_threshold(k, tile.keys[i]), count)) continue;
          const double x = (tx + tile.points[i].unit_x()) / 2, y = (ty + tile.points[i].unit_y()) / 2;
          all.insert(all.end(), {x, y});
          std::vector<double>* part = (tx == 0 && ty == 0) ? own : others;
          if (part) part->insert(part->end(), {x, y});
        }
    }
  return all;
}

gen::SamplerOptions torus_options(double temperature, double side, int threads) {
  gen::SamplerOptions o;
  o.temperature = temperature;
  o.extent[0] = o.extent[1] = side;
  o.threads = threads;
  // The baker's arithmetic (bake.cpp): a set's verdict, like its tiles, must not change between kdm versions.
  o.numerics = gen::Numerics::kOriginal;
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
  if (coords.size() >= 6) tori_.push_back({2, coords});
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
