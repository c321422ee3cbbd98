// The generator test: every tile and level of the shipped default tile set against the full sampler.
// For each level, 16 unconstrained full-sampler runs on the same torus with the same n and T (default
// options: what a user running the sampler gets) give the reference; the tile must match it in energy per
// point, δavg, NN1%, lowP and RAPS (tolerances below).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "kdm/analysis/nearest_neighbor.h"
#include "kdm/analysis/periodogram.h"
#include "kdm/generator/bake.h"
#include "kdm/generator/sampler.h"
#include "kdm/runtime/tileset.h"

namespace kdm::gen {
namespace {

constexpr int kReferenceRuns = 16;

// The first n points of a tile (a pyramid prefix) as unit-square coordinates.
std::vector<double> prefix_coords(const Tile& tile, std::size_t n) {
  std::vector<double> coords;
  for (std::size_t i = 0; i < n; ++i)
    coords.insert(coords.end(), {tile.points[i].unit_x(), tile.points[i].unit_y()});
  return coords;
}

struct Metrics {
  double energy = 0, davg = 0, nn1 = 0;
};

Metrics measure(const std::vector<double>& coords, double temperature) {
  SamplerOptions o;
  o.temperature = temperature;
  Metrics m;
  m.energy = energy_per_point(o, Density::constant(), coords);
  const analysis::NNStats nn = analysis::nn_stats(coords, 2, true);
  m.davg = nn.davg;
  m.nn1 = nn.nn1;
  return m;
}

// Mean RAPS over rings with band_lo <= f < band_hi, and how many periodogram values that mean covers.
std::pair<double, double> band_raps(const analysis::SpectrumStats& s, double lo, double hi) {
  double sum = 0, count = 0;
  for (std::size_t r = 0; r < s.raps.size(); ++r)
    if (s.ring_f[r] >= lo && s.ring_f[r] < hi) sum += s.raps[r] * s.ring_size[r], count += s.ring_size[r];
  return {count ? sum / count : std::nan(""), count};
}

TEST(GeneratorTest, EveryLevelOfTheDefaultSetMatchesTheFullSampler) {
  TileSet set;
  std::string detail;
  ASSERT_EQ(load_tileset(std::string(KDM_SOURCE_DIR) + "/tilesets/default.kdmt", set, &detail), Status::kOk)
      << detail;
  const BakeRecipe recipe = BakeRecipe::parse(set.recipe);
  for (std::size_t t = 0; t < set.tiles.size(); ++t) {
    const Tile& tile = set.tiles[t];
    for (std::uint32_t level = 0; level < set.levels; ++level) {
      const std::size_t n = tile.level_end[level];
      const std::vector<double> coords = prefix_coords(tile, n);
      const Metrics got = measure(coords, recipe.temperature);

      Metrics ref;
      std::vector<tools::PointSet> ref_sets;
      std::vector<double> ref_low_p;
      for (int run = 0; run < kReferenceRuns; ++run) {
        SamplerOptions o;
        o.n = static_cast<std::int64_t>(n);
        o.temperature = recipe.temperature;
        o.seed = 1000 + run;
        tools::PointSet s;
        s.coords = sample(o).points;
        const Metrics m = measure(s.coords, recipe.temperature);
        ref.energy += m.energy / kReferenceRuns;
        ref.davg += m.davg / kReferenceRuns;
        ref.nn1 += m.nn1 / kReferenceRuns;
        ref_low_p.push_back(analysis::spectrum_stats(analysis::periodogram(s.coords, 2, 0.6)).low_p);
        ref_sets.push_back(std::move(s));
      }
      const analysis::SpectrumStats ref_spectrum =
          analysis::spectrum_stats(analysis::average_periodogram(ref_sets, 2.0));
      const analysis::SpectrumStats tile_spectrum =
          analysis::spectrum_stats(analysis::periodogram(coords, 2, 2.0));
      std::printf(
          "tile %zu level %u (n=%zu): E/n %.4f (ref %.4f)  δavg %.4f (ref %.4f)  NN1%% %.3f (ref %.3f)  "
          "lowP %.4f (ref %.4f)\n",
          t, level, n, got.energy, ref.energy, got.davg, ref.davg, got.nn1, ref.nn1, tile_spectrum.low_p,
          ref_spectrum.low_p);
      EXPECT_LE(got.energy, ref.energy * 1.05) << "level " << level;
      EXPECT_GE(got.davg, ref.davg - 0.015) << "level " << level;
      EXPECT_GE(got.nn1, 0.85 * ref.nn1) << "level " << level;
      // lowP of one set averages few frequencies when n is small (n = 64: 5 of them), each roughly
      // exponential; there the 1.5× bar is noise, so small levels must instead fall within the
      // range of the 16 reference runs.
      const double band_count = 3.14159 * 0.25 * n / 2;  // distinct k with 0 < |k| < 0.5 sqrt(n)
      if (band_count >= 100)
        EXPECT_LE(tile_spectrum.low_p, 1.5 * ref_spectrum.low_p) << "level " << level;
      else
        EXPECT_LE(tile_spectrum.low_p, *std::max_element(ref_low_p.begin(), ref_low_p.end()))
            << "level " << level;
      // RAPS in bands of 0.25 over 0.5 <= f < 2: within ±0.1 of the reference, or 4 standard deviations
      // of a one-set band mean (RAPS / sqrt(values / 2), P(k) = P(-k)) where that is wider. Only for levels
      // of >= 4096 points: smaller levels are baked with 4–64× the default sweeps (BakeRecipe::sweeps_for)
      // and are measurably more ordered than default runs (sharper peak; noted on the tile-baking issue).
      for (double lo = 0.5; n >= 4096 && lo < 2.0 - 1e-9; lo += 0.25) {
        const auto [tile_band, values] = band_raps(tile_spectrum, lo, lo + 0.25);
        const double ref_band = band_raps(ref_spectrum, lo, lo + 0.25).first;
        if (!(values > 0)) continue;
        const double tolerance = std::max(0.1, 4 * ref_band / std::sqrt(values / 2));
        EXPECT_NEAR(tile_band, ref_band, tolerance) << "level " << level << " band f=" << lo;
      }
    }
  }
}

// Rank prefixes between complete levels (what the runtime emits at in-between densities) stay blue at low
// frequencies. Prefixes below 1792 points average too few frequencies for lowP to mean much (n = 832:
// 327 of them, a relative sd of about 6%); the shipped set is fixed, so the check is deterministic.
TEST(GeneratorTest, MidLevelPrefixesHaveLowLowFrequencyPower) {
  TileSet set;
  ASSERT_EQ(load_tileset(std::string(KDM_SOURCE_DIR) + "/tilesets/default.kdmt", set), Status::kOk);
  for (const Tile& tile : set.tiles)
    for (std::uint32_t level = 1; level < set.levels; ++level)
      for (int quarter = 1; quarter <= 3; ++quarter) {
        const std::size_t lo = tile.level_end[level - 1], hi = tile.level_end[level];
        const std::size_t n = lo + (hi - lo) * quarter / 4;
        if (n < 1792) continue;
        const std::vector<double> coords = prefix_coords(tile, n);
        const double low_p = analysis::spectrum_stats(analysis::periodogram(coords, 2, 0.6)).low_p;
        std::printf("level %u + %d/4 (n=%zu): lowP %.4f\n", level, quarter, n, low_p);
        EXPECT_LE(low_p, 0.1) << "n=" << n;  // the bar; measured 0.066–0.099
      }
}

}  // namespace
}  // namespace kdm::gen
