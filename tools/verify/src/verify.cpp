// Parts 1 and 2 of the generator test (verify.h): every tile and level against full-sampler runs, and
// the direct check. The bars, and why small tiles, few frequencies and small levels' RAPS are judged
// otherwise: docs/design.md §5 (the shipped set's figures: docs/quality.md).
#include <algorithm>
#include <cmath>
#include <limits>

#include "kdm/analysis/nearest_neighbour.h"
#include "kdm/analysis/periodogram.h"
#include "kdm/generator/bake.h"
#include "kdm/generator/sampler.h"
#include "kdm/verify/verify.h"
#include "tile_torus.h"

namespace kdm::verify {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Metrics {
  double energy = 0, davg = 0, nn1 = 0;
};

Metrics measure(const std::vector<double>& coords, double temperature, double side, int threads) {
  Metrics m;
  m.energy =
      gen::energy_per_point(torus_options(temperature, side, threads), gen::Density::constant(), coords);
  const analysis::NNStats nn = analysis::nn_stats(coords, 2, true, threads);
  m.davg = nn.davg, m.nn1 = nn.nn1;
  return m;
}

// Mean RAPS over rings with lo ≤ f < hi, and how many periodogram values that mean covers.
std::pair<double, double> band_raps(const analysis::SpectrumStats& s, double lo, double hi) {
  double sum = 0, count = 0;
  for (std::size_t r = 0; r < s.raps.size(); ++r)
    if (s.ring_f[r] >= lo && s.ring_f[r] < hi) sum += s.raps[r] * s.ring_size[r], count += s.ring_size[r];
  return {count ? sum / count : kNaN, count};
}

// Tiles less than b.small_tile_spacings point spacings wide.
bool small_tiles(const Bars& b, double points_per_tile) {
  return std::sqrt(points_per_tile) < b.small_tile_spacings;
}

struct Reference {
  LevelReference summary;
  analysis::SpectrumStats spectrum;  ///< of the averaged periodogram up to f = 2; empty over budget
};

Reference reference(const TilesetData& set, std::uint32_t level, double temperature,
                    const VerifyOptions& options, const std::function<void(double)>& done) {
  const std::uint32_t n = set.level_nominal[level];
  Reference ref;
  LevelReference& s = ref.summary;
  s.level = level, s.points_per_tile = n, s.side = n <= 2048 ? 2 : 1;
  std::vector<tools::PointSet> sets;
  const int runs = options.statistics ? options.reference_runs : 0;
  if (!runs) s.energy = s.davg = s.nn1 = s.low_p = s.low_p_max = kNaN;
  for (int run = 0; run < runs; ++run) {
    gen::SamplerOptions o = torus_options(temperature, s.side, options.threads);
    o.n = static_cast<std::int64_t>(n * s.side * s.side);
    o.seed = 1000 + run;
    tools::PointSet points;
    points.coords = gen::sample(o).points;
    const Metrics m = measure(points.coords, temperature, s.side, options.threads);
    s.energy += m.energy / runs, s.davg += m.davg / runs, s.nn1 += m.nn1 / runs;
    const double low_p =
        analysis::spectrum_stats(analysis::periodogram(points.coords, 2, 0.6, options.threads)).low_p;
    s.low_p += low_p / runs, s.low_p_max = std::max(s.low_p_max, low_p);
    sets.push_back(std::move(points));
    done(double(o.n));
  }
  if (runs && 4.0 * n <= double(options.spectrum_budget))  // the tile tori hold 4n points
    ref.spectrum = analysis::spectrum_stats(analysis::average_periodogram(sets, 2.0, options.threads));
  s.control_drop = s.control_drift = kNaN;
  if (options.direct_check) {
    gen::SamplerOptions o = torus_options(temperature, 1, options.threads);
    o.n = n;
    o.seed = 2000 + level;
    const Relaxed control =
        relax(gen::sample(o).points, {}, 1, temperature, 1 / std::sqrt(double(n)), 99, options.threads);
    s.control_drop = control.drop, s.control_drift = control.drift;
  }
  return ref;
}

void judge_statistics(const std::vector<double>& coords, const Reference& ref, double temperature,
                      const VerifyOptions& options, TileResult& out) {
  const LevelReference& level = ref.summary;
  const Bars& b = options.bars;
  const bool small = small_tiles(b, level.points_per_tile);
  const double nominal = level.points_per_tile;
  const Metrics got = measure(coords, temperature, 2, options.threads);
  out.energy = got.energy, out.davg = got.davg, out.nn1 = got.nn1;
  out.checks.push_back({"E/n", got.energy, level.energy * (small ? b.small_energy : b.energy), true});
  out.checks.push_back({"δavg", got.davg, level.davg - b.davg, false});
  out.checks.push_back({"NN1%", got.nn1, level.nn1 * (small ? b.small_nn1 : b.nn1), false});

  out.low_p = kNaN;
  if (out.points <= options.spectrum_budget) {
    const bool with_raps = !ref.spectrum.raps.empty() && nominal >= b.raps_min_points;
    const analysis::SpectrumStats spectrum =
        analysis::spectrum_stats(analysis::periodogram(coords, 2, with_raps ? 2.0 : 0.6, options.threads));
    out.low_p = spectrum.low_p;
    const double band_count = 3.14159 * 0.25 * double(out.points) / 2;  // distinct k, 0 < |k| < 0.5 √n
    if (band_count >= 100)
      out.checks.push_back({"lowP", spectrum.low_p, level.low_p * (small ? b.small_low_p : b.low_p), true});
    else
      out.checks.push_back({"lowP (few freq.)", spectrum.low_p,
                            level.low_p_max * (small ? b.small_low_p_of_largest : b.low_p_of_largest), true});
    for (double lo = 0.5; with_raps && lo < 2.0 - 1e-9; lo += 0.25) {
      const auto [tile_band, values] = band_raps(spectrum, lo, lo + 0.25);
      const double ref_band = band_raps(ref.spectrum, lo, lo + 0.25).first;
      if (!(values > 0)) continue;
      // A one-set band mean of `values` exponentials, P(k) = P(−k): its sd is RAPS / √(values / 2).
      const double tolerance = std::max(b.raps, 4 * ref_band / std::sqrt(values / 2));
      char name[32];
      std::snprintf(name, sizeof name, "|ΔRAPS| f %.2g-%.2g", lo, lo + 0.25);
      out.checks.push_back({name, std::fabs(tile_band - ref_band), tolerance, true});
    }
  }
}

void judge_tile(const TilesetData& set, std::size_t t, const Reference& ref, double temperature,
                const VerifyOptions& options, TileResult& out) {
  const LevelReference& level = ref.summary;
  const Bars& b = options.bars;
  const bool small = small_tiles(b, level.points_per_tile);
  const double nominal = level.points_per_tile;
  std::vector<double> own, others;
  const std::vector<double> coords = torus_points(set, t, nominal, &own, &others);
  out.points = coords.size() / 2;
  out.energy = out.davg = out.nn1 = out.low_p = out.drop = out.drift = kNaN;
  if (options.statistics) judge_statistics(coords, ref, temperature, options, out);
  if (options.direct_check) {
    const double spacing = 0.5 / std::sqrt(nominal);  // the unit square holds 2×2 tiles
    const Relaxed r = relax(own, others, 2, temperature, spacing, 77 + t, options.threads);
    out.drop = r.drop, out.drift = r.drift;
    out.checks.push_back({"energy drop", r.drop, small ? b.small_energy_drop : b.energy_drop, true});
    out.checks.push_back({"drift", r.drift, b.drift * level.control_drift, true});
  }
}

}  // namespace

namespace {
bool all_passed(const std::vector<Check>& checks) {
  return std::all_of(checks.begin(), checks.end(), [](const Check& c) { return c.passed(); });
}
}  // namespace

bool TileResult::passed() const {
  return all_passed(checks);
}
bool KeyframeResult::passed() const {
  return all_passed(checks);
}

bool DensityResult::passed() const {
  return all_passed(checks);
}

std::size_t Report::failed_checks() const {
  std::size_t failed = 0;
  for (const TileResult& t : tiles)
    for (const Check& c : t.checks) failed += !c.passed();
  for (const DensityResult& d : densities)
    for (const Check& c : d.checks) failed += !c.passed();
  for (const KeyframeResult& k : keyframes)
    for (const Check& c : k.checks) failed += !c.passed();
  return failed;
}

Report verify_tileset(const TilesetData& set, const VerifyOptions& options_in) {
  VerifyOptions options = options_in;
  if (options.reference_runs < 2) throw gen::InvalidArgument("verify: at least 2 reference runs are needed");
  if (options.levels.empty())
    for (std::uint32_t k = 0; k < set.levels; ++k) options.levels.push_back(k);
  // A level named twice is judged once.
  std::sort(options.levels.begin(), options.levels.end());
  options.levels.erase(std::unique(options.levels.begin(), options.levels.end()), options.levels.end());
  for (std::uint32_t k : options.levels)
    if (k >= set.levels)
      throw gen::InvalidArgument("verify: level " + std::to_string(k) + " is not in the tile set (it has " +
                                 std::to_string(set.levels) + ")");
  // The references sample each level's nominal count: a set whose tiles hold far less (a forged file of
  // 282 bytes declaring 4.29e9 points per tile) would have them sample without end what no tile holds.
  for (std::uint32_t k : options.levels) {
    double held = 0;
    for (const Tile& tile : set.tiles) held += tile.level_end[k];
    held /= double(set.tiles.size());
    if (double(set.level_nominal[k]) > 4 * held + 64)
      throw gen::InvalidArgument(
          "verify: level " + std::to_string(k) + " declares " + std::to_string(set.level_nominal[k]) +
          " points per tile, but its tiles hold " + std::to_string(std::llround(held)) +
          " on average: not a set the baker made (its references would sample what no "
          "tile holds)");
  }
  double temperature = 0;  // the reference runs sample at the bake's temperature
  try {
    temperature = gen::BakeRecipe::parse(set.recipe).temperature;
  } catch (const gen::InvalidArgument& e) {
    throw gen::InvalidArgument("verify: the recipe stored in the tile set does not parse (" +
                               std::string(e.what()) +
                               "), so the temperature it was baked at is unknown (a set from another kdm "
                               "version? verify it with that version)");
  }

  // Progress in units of points sampled or measured, roughly proportional to the time they take.
  double total = 0, finished = 0;
  for (std::uint32_t k : options.levels) {
    const double n = set.level_nominal[k];
    if (options.statistics)
      total += options.reference_runs * n * (n <= 2048 ? 4 : 1) + set.tiles.size() * 4 * n;
    if (options.direct_check) total += set.tiles.size() * 4 * n;
    if (options.seams) total += set.tiles.size() * 4 * n * (k ? 4 : 1);
  }
  if (options.glide_track)
    for (std::size_t g = 0; g < set.keyframe_nominal.size(); ++g)
      if (keyframe_judged(set, options.levels, g))
        total += set.tiles.size() * 4 * 2.0 * set.keyframe_nominal[g];
  const auto done = [&](double units) {
    finished += units;
    if (options.progress) options.progress(std::min(1.0, finished / total));
  };

  Report report;
  for (std::uint32_t k : options.levels) {
    const Reference ref = reference(set, k, temperature, options, done);
    report.levels.push_back(ref.summary);
    for (std::size_t t = 0; t < set.tiles.size(); ++t) {
      TileResult row;
      row.tile = t, row.level = k;
      for (std::size_t c = 4, rest = t; c-- > 0; rest /= set.colours) row.colours[c] = rest % set.colours;
      judge_tile(set, t, ref, temperature, options, row);
      report.tiles.push_back(std::move(row));
      done(4.0 * set.level_nominal[k] * (options.statistics + options.direct_check));
    }
  }
  if (options.seams) judge_densities(set, options, report, done);
  if (options.glide_track) judge_keyframes(set, options, report, done);
  if (options.glide_track && set.handover_zone &&
      std::find(options.levels.begin(), options.levels.end(), set.levels - 1) != options.levels.end())
    judge_handover(set, options, report, done);
  if (options.progress) options.progress(1.0);
  return report;
}

}  // namespace kdm::verify
