// Pair correlation, density accuracy and tiling diagnostics against known truths.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "kdm/analysis/common.h"
#include "kdm/analysis/density.h"
#include "kdm/analysis/pair_correlation.h"
#include "kdm/analysis/periodogram.h"
#include "kdm/analysis/tiling.h"
#include "test_sets.h"

namespace kdm::analysis {
namespace {

using testing::jittered_grid;
using testing::torus_hex_lattice;
using testing::uniform_set;

constexpr double kPi = 3.14159265358979323846;

void expect_flat_g(bool torus, int dim) {
  // For i.i.d. uniform points the estimator is unbiased for g = 1. A bin's value is a count of (nearly
  // independent) unordered pairs over its expectation: relative sd ≈ 1/sqrt(expected unordered pairs).
  // Box weights are ≤ 1/(1 − r_max)^dim ≈ 1.1 here; we allow 5 sd.
  std::vector<tools::PointSet> sets;
  for (unsigned s = 0; s < 4; ++s)
    sets.push_back(uniform_set(4096, 300 + s + 10 * dim + (torus ? 0 : 5), dim));
  const int bins = 30;
  const PairCorrelation g = pair_correlation(sets, torus, 3.0, bins);
  ASSERT_EQ(g.g.size(), static_cast<std::size_t>(bins));
  for (int b = 0; b < bins; ++b) {
    const double r0 = g.spacing * g.r_max * b / bins, r1 = g.spacing * g.r_max * (b + 1) / bins;
    const double shell =
        dim == 2 ? kPi * (r1 * r1 - r0 * r0) : 4.0 / 3.0 * kPi * (r1 * r1 * r1 - r0 * r0 * r0);
    const double pairs = 4 * 4096.0 * 4095.0 / 2 * shell;
    EXPECT_NEAR(g.g[b], 1.0, 5 / std::sqrt(pairs) * (torus ? 1.0 : 1.1)) << "bin " << b << " dim " << dim;
  }
}

TEST(PairCorrelation, PoissonIsOneOnTorusAndInBox) {
  expect_flat_g(true, 2);
  expect_flat_g(false, 2);
  expect_flat_g(true, 3);
  expect_flat_g(false, 3);
}

TEST(PairCorrelation, LatticeHasNoPairsBelowItsSpacing) {
  const tools::PointSet s = torus_hex_lattice(26, 30);
  const PairCorrelation g = pair_correlation({s}, true, 3.0, 60);
  const double nn = std::min(1.0 / 26, std::hypot(0.5 / 26, 1.0 / 30)) / g.spacing;  // ≈ 0.996 d_hex
  double mass_below = 0, peak = 0;
  for (std::size_t b = 0; b < g.g.size(); ++b) {
    if (g.r[b] + 0.5 * g.r_max / 60 <= nn) mass_below += g.g[b];
    peak = std::max(peak, g.g[b]);
  }
  EXPECT_EQ(mass_below, 0.0);
  EXPECT_GT(peak, 5.0);  // all six neighbours fall in one narrow bin
}

// Points on one another are counted as one position with its multiplicity: the same g(r) as counting
// every ordered pair (brute force here), up to the order of the sums.
TEST(PairCorrelation, PointsOnOneAnotherCountEveryPair) {
  for (bool torus : {true, false}) {
    tools::PointSet s = uniform_set(400, 21);
    for (int copies = 1; copies <= 40; ++copies)  // groups of 2 to 41 points
      for (int a = 0; a < 2; ++a) s.coords.push_back(s.coords[copies * 2 + a]);
    for (int k = 0; k < 30; ++k) s.coords.insert(s.coords.end(), {0.25, 0.75});
    const int bins = 20;
    const PairCorrelation g = pair_correlation({s}, torus, 3.0, bins);
    const double r_abs = g.r_max * g.spacing, n = static_cast<double>(s.size());
    std::vector<double> hist(bins, 0.0);
    for (std::size_t i = 0; i < s.size(); ++i)
      for (std::size_t j = 0; j < s.size(); ++j) {
        if (i == j) continue;
        const double dx = axis_delta(s.coords[2 * i], s.coords[2 * j], torus),
                     dy = axis_delta(s.coords[2 * i + 1], s.coords[2 * j + 1], torus);
        const double d = std::hypot(dx, dy);
        if (d < r_abs)
          hist[std::min(bins - 1, static_cast<int>(d / (r_abs / bins)))] +=
              torus ? 1.0 : 1.0 / ((1 - std::abs(dx)) * (1 - std::abs(dy)));
      }
    for (int b = 0; b < bins; ++b) {
      const double r0 = r_abs * b / bins, r1 = r_abs * (b + 1) / bins;
      EXPECT_NEAR(g.g[b], hist[b] / (n * (n - 1) * kPi * (r1 * r1 - r0 * r0)), 1e-9 * (1 + g.g[b]))
          << "bin " << b << " torus " << torus;
    }
    EXPECT_GT(g.g[0], 10.0);  // the groups' pairs at distance 0 (25.7 here; a uniform set's bin is about 1)
  }
}

double uniform(double, double) {
  return 1.0;
}

TEST(Density, PoissonHasUnitRmsZ) {
  // Counts in windows of expected μ out of n binomial points: E z² = 1 − μ/n. Each z² has variance ≈ 2, so
  // the mean over W pooled windows has sd sqrt(2/W) and the RMS sd ≈ sqrt(2/W)/2. 5 sd allowed.
  double z2 = 0, mu = 0;
  std::size_t windows = 0;
  for (unsigned s = 0; s < 8; ++s) {
    const tools::PointSet p = uniform_set(4096, 400 + s);
    const DensityAccuracy d = density_accuracy(p.coords, 2, uniform);
    EXPECT_GE(d.mean_expected, 20.0);
    EXPECT_LT(d.mean_expected, 40.0);
    EXPECT_NEAR(d.bias, 0.0, 1e-12);
    EXPECT_EQ(d.zero_density, 0u);
    z2 += d.rms_z * d.rms_z * d.windows;
    mu += d.mean_expected * d.windows;
    windows += d.windows;
  }
  const double rms = std::sqrt(z2 / windows), w = static_cast<double>(windows);
  EXPECT_NEAR(rms, std::sqrt(1 - mu / w / 4096), 5 * std::sqrt(2 / w) / 2);
}

TEST(Density, NonUniformTargetIsMatched) {
  // ρ(x, y) = x: x = sqrt(u) has density 2x. Poisson-like again → RMS z ≈ 1 (same tolerance as above).
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  double z2 = 0;
  std::size_t windows = 0;
  for (int s = 0; s < 8; ++s) {
    std::vector<double> c;
    for (int i = 0; i < 4096; ++i) c.push_back(std::sqrt(u(rng))), c.push_back(u(rng));
    const DensityAccuracy d = density_accuracy(c, 2, [](double x, double) { return 3 * x; });
    z2 += d.rms_z * d.rms_z * d.windows;
    windows += d.windows;
  }
  EXPECT_NEAR(std::sqrt(z2 / windows), 1.0, 5 * std::sqrt(2.0 / windows) / 2 + 0.01);
  // The same points against a uniform target are badly off.
  std::vector<double> c;
  for (int i = 0; i < 4096; ++i) c.push_back(std::sqrt(u(rng))), c.push_back(u(rng));
  EXPECT_GT(density_accuracy(c, 2, uniform).rms_z, 3.0);
}

// Bands span the density's own range: zero cells stay zero (from the summed-area table's differences they
// came out as 1e-15-sized residue and set the lowest band, eight of ten bands then empty), so a target
// of 0, 0.01 to 0.51 and 1 has bands from about 0.01 to 1.
TEST(Density, BandsSpanTheDensitysOwnRange) {
  // The zero cells last, after the table's sums have grown: a difference of large sums leaves residue.
  const auto steps = [](double x, double y) { return x > 0.5 || y > 0.5 ? 0.0 : x < 0.25 ? 1.0 : 0.01 + y; };
  std::vector<double> c;
  for (int i = 0; i < 64; ++i)
    for (int j = 0; j < 64; ++j) c.push_back(0.25 * (i + 0.5) / 64), c.push_back(0.5 * (j + 0.5) / 64);
  const DensityAccuracy d = density_accuracy(c, 2, steps);
  ASSERT_EQ(d.bands.size(), 10u);
  EXPECT_GE(d.bands.front().lo, 0.01);  // the lowest raster cell's 0.01 + y, y its centre (under 0.003)
  EXPECT_LT(d.bands.front().lo, 0.013);
  EXPECT_NEAR(d.bands.back().hi, 1.0, 1e-9);
  EXPECT_GT(d.bands.front().expected, 0.0);  // the 0.01 cells, in the first band
}

TEST(Density, StratifiedSetIsFarBelowPoisson) {
  const tools::PointSet p = jittered_grid(64, 9);
  const DensityAccuracy d = density_accuracy(p.coords, 2, uniform);
  EXPECT_LT(d.rms_z, 0.5);
  // Windows that do not align with the strata still stay well below Poisson: only the boundary cells vary.
  DensityOptions o;
  o.raster = 333;
  EXPECT_LT(density_accuracy(p.coords, 2, uniform, o).rms_z, 0.6);
}

TEST(Density, BiasAndZeroDensityRegion) {
  const tools::PointSet p = uniform_set(2000, 11);
  DensityOptions o;
  o.expected_total = 1000;  // twice as many points as asked
  EXPECT_NEAR(density_accuracy(p.coords, 2, uniform, o).bias, 1.0, 1e-9);
  // Zero density on the left half: the points there are counted, and the windows miss them.
  auto right = [](double x, double) { return x < 0.5 ? 0.0 : 1.0; };
  const DensityAccuracy d = density_accuracy(p.coords, 2, right);
  std::size_t left = 0;
  for (std::size_t i = 0; i < p.size(); ++i) left += p.coords[2 * i] < 0.5;
  EXPECT_EQ(d.zero_density, left);
  EXPECT_NEAR(d.bias, -static_cast<double>(left) / 2000.0, 1e-9);
  EXPECT_THROW(density_accuracy(p.coords, 2, [](double, double) { return 0.0; }), InvalidInput);
  EXPECT_THROW(density_accuracy(p.coords, 2, [](double, double) { return -1.0; }), InvalidInput);
}

TEST(Tiling, TilesPerAxis) {
  EXPECT_EQ(tiles_per_axis(0.125), 8);
  EXPECT_EQ(tiles_per_axis(1.0 / 3.0), 3);
  EXPECT_THROW(tiles_per_axis(0.3), InvalidInput);
  EXPECT_THROW(tiles_per_axis(0), InvalidInput);
  EXPECT_THROW(tiles_per_axis(2), InvalidInput);
}

TEST(Tiling, PeriodicityRatioDetectsRepeatedTile) {
  // One random tile of 64 points repeated 8×8: S(k) = 64·S_tile(k) on k ∈ 8ℤ², 0 elsewhere, so P at lattice
  // frequencies is 64× the tile's and the rings average it with ~63/64 zeros → ratio ≈ 64.
  const tools::PointSet tile = uniform_set(64, 12);
  tools::PointSet rep;
  for (int ty = 0; ty < 8; ++ty)
    for (int tx = 0; tx < 8; ++tx)
      for (std::size_t i = 0; i < tile.size(); ++i) {
        rep.coords.push_back((tx + tile.coords[2 * i]) / 8);
        rep.coords.push_back((ty + tile.coords[2 * i + 1]) / 8);
      }
  const Periodogram p = periodogram(rep.coords, 2, 2.5);
  const PeriodicityResult r = periodicity_ratio(p, spectrum_stats(p), 0.125);
  EXPECT_GT(r.ratio, 30.0);
  // White noise: mean of F ≈ 1200 exponential values (half independent) over the ring means: sd ≈ sqrt(2/F).
  const tools::PointSet w = uniform_set(4096, 13);
  const Periodogram pw = periodogram(w.coords, 2, 2.5);
  const PeriodicityResult rw = periodicity_ratio(pw, spectrum_stats(pw), 0.125);
  EXPECT_GT(rw.frequencies, 1000u);
  EXPECT_NEAR(rw.ratio, 1.0, 5 * std::sqrt(2.0 / rw.frequencies) + 0.02);
  // Against the lattice frequencies' neighbours: the repeated tile has no power off the lattice at all, bar
  // the transform's rounding (it read 1.9e27 from that), so the ratio is infinite; white noise has 24
  // exponential values over 192, whose ratio's log has sd ≈ 0.22: 5 sd allowed.
  EXPECT_EQ(r.lattice_ratio, HUGE_VAL);
  EXPECT_EQ(r.lattice_frequencies, 24u);  // (i, j) in [-2, 2]² but 0: what tells JSON's null from NaN
  // 4 points a tile, 4 × 4 tiles: the periodogram reaches |k| = 5, short of (4, 0)'s neighbour (5, 1).
  tools::PointSet small;
  for (int t = 0; t < 16; ++t)
    for (std::size_t i = 0; i < 4; ++i)
      small.coords.insert(small.coords.end(),
                          {(t % 4 + tile.coords[2 * i]) / 4, (t / 4 + tile.coords[2 * i + 1]) / 4});
  const Periodogram low = periodogram(small.coords, 2, 0.1);
  const PeriodicityResult none = periodicity_ratio(low, spectrum_stats(low), 0.25);
  EXPECT_EQ(none.lattice_frequencies, 0u);
  EXPECT_TRUE(std::isnan(none.lattice_ratio));
  EXPECT_NEAR(std::log(rw.lattice_ratio), 0.0, 5 * 0.22);
}

// Uniform random points have the mean density at every distance from the tile edges: each band's count is
// Poisson, so its ratio has sd 1/sqrt(expected); 5 sd allowed. A set whose points keep away from the edges
// shows the gap in the first bands and the surplus further in.
TEST(Tiling, EdgeBandsMeasureDensityNearTileEdges) {
  EdgeBands uniform;
  for (unsigned s = 0; s < 8; ++s) add_edge_bands(uniform_set(20000, 500 + s).coords, 2, 1.0 / 8, uniform);
  for (int b = 0; b < EdgeBands::kBands; ++b)
    EXPECT_NEAR(uniform.ratio(b), 1.0, 5 / std::sqrt(uniform.expected[b])) << "band " << b;
  double all = 0;
  for (int b = 0; b < EdgeBands::kBands; ++b) all += uniform.expected[b];
  EXPECT_NEAR(all / 8, 20000 * (1 - std::pow(1 - 2 * 2 * std::sqrt(2 / (std::sqrt(3.0) * 20000)) * 8, 2)),
              1e-6 * all);  // the bands cover 2 d_hex from each edge
  const tools::PointSet p = uniform_set(20000, 520);
  std::vector<double> kept;  // drop the points within 0.5 d_hex of an edge of the 8×8 tiles
  const double half = 0.5 * std::sqrt(2 / (std::sqrt(3.0) * 20000));
  for (std::size_t i = 0; i < p.size(); ++i) {
    double d = 1;
    for (int k = 0; k < 2; ++k) {
      const double f = p.coords[2 * i + k] * 8 - std::floor(p.coords[2 * i + k] * 8);
      d = std::min(d, std::min(f, 1 - f) / 8);
    }
    if (d >= half) kept.push_back(p.coords[2 * i]), kept.push_back(p.coords[2 * i + 1]);
  }
  EdgeBands gapped;
  add_edge_bands(kept, 2, 1.0 / 8, gapped);
  EXPECT_LT(gapped.ratio(0), 0.05);  // bands 0 and 1 are the removed half spacing (n is smaller now, so
  EXPECT_LT(gapped.first_spacing_ratio(), 0.8);  // its d_hex a little larger: band 2 is partly empty too)
  EXPECT_GT(gapped.ratio(7), 1.0);               // the kept points are all further in
  EXPECT_THROW(add_edge_bands(kept, 2, 0.3, gapped), InvalidInput);
}

TEST(Tiling, SeamClassification) {
  // Pairs: across x = 0.5 (seam), inside a tile (interior), across the torus edge x = 0 (seam on the torus).
  const std::vector<double> c = {0.49, 0.30, 0.51, 0.30, 0.20, 0.80, 0.22, 0.80, 0.005, 0.62, 0.995, 0.62};
  std::vector<double> seam, interior;
  const NearestNeighbours nn = nearest_neighbours(c, 2, true);
  split_by_seam(c, 2, nn, 0.5, seam, interior);
  EXPECT_EQ(seam.size(), 4u);
  EXPECT_EQ(interior.size(), 2u);
  const SeamStats s = seam_stats({tools::PointSet{2, c, {}, {}, {}}}, true, 0.5);
  EXPECT_NEAR(s.seam.dmin, 0.01 / hex_spacing(6), 1e-9);
  EXPECT_NEAR(s.interior.davg, 0.02 / hex_spacing(6), 1e-9);
}

TEST(Tiling, OneSidedKolmogorovSmirnovAsksOnlyWhetherTheFirstIsSmaller) {
  std::mt19937_64 rng(15);
  std::normal_distribution<double> g(0, 1);
  std::vector<double> a, b, smaller, larger;
  for (int i = 0; i < 2000; ++i)
    a.push_back(g(rng)), b.push_back(g(rng)), smaller.push_back(g(rng) - 0.2), larger.push_back(g(rng) + 0.2);
  EXPECT_GT(ks_smaller(a, b).p_value, 0.01);
  EXPECT_LT(ks_smaller(smaller, b).p_value, 1e-6);
  EXPECT_GT(ks_smaller(larger, b).p_value, 0.5);  // larger values are no evidence of "smaller"
  EXPECT_DOUBLE_EQ(ks_smaller({1, 2, 3}, {4, 5, 6}).statistic, 1.0);
  EXPECT_DOUBLE_EQ(ks_smaller({4, 5, 6}, {1, 2, 3}).statistic, 0.0);
  // Smirnov's bound: D+ = 1 with m = 1.5 gives exp(-3).
  EXPECT_NEAR(ks_smaller({1, 2, 3}, {4, 5, 6}).p_value, std::exp(-3.0), 1e-12);
}

TEST(Tiling, OneSidedKolmogorovSmirnovCanLookBelowALengthOnly) {
  // a's values bunch at and above b's median (0.9): an excess above it, none below.
  const std::vector<double> a = {0.9, 0.9, 0.9, 0.9, 0.92, 0.97}, b = {0.6, 0.7, 0.8, 0.9, 0.95, 1.0};
  EXPECT_NEAR(ks_smaller(a, b).statistic, 1.0 / 6, 1e-12);
  EXPECT_DOUBLE_EQ(ks_smaller(a, b, 0.9).statistic, 0.0);
  // Below the cut the excess is the same as without it.
  EXPECT_NEAR(ks_smaller({0.5, 0.9}, b, 0.85).statistic, 0.5, 1e-12);
  EXPECT_NEAR(ks_smaller({0.5, 0.9}, b).statistic, 0.5, 1e-12);
}

TEST(Tiling, KolmogorovSmirnov) {
  EXPECT_DOUBLE_EQ(ks_two_sample({1, 2, 3}, {4, 5, 6}).statistic, 1.0);
  EXPECT_DOUBLE_EQ(ks_two_sample({1, 2, 3, 4}, {1, 2, 3, 4}).statistic, 0.0);
  EXPECT_DOUBLE_EQ(ks_two_sample({1, 2, 3, 4}, {1, 2, 3, 4}).p_value, 1.0);
  std::mt19937_64 rng(14);
  std::normal_distribution<double> g(0, 1);
  std::vector<double> a, b, shifted;
  for (int i = 0; i < 2000; ++i) a.push_back(g(rng)), b.push_back(g(rng)), shifted.push_back(g(rng) + 0.3);
  const KsResult same = ks_two_sample(a, b), diff = ks_two_sample(a, shifted);
  EXPECT_GT(same.p_value, 0.01);
  EXPECT_LT(diff.p_value, 1e-10);
  // Ties step together: a = {1,1,2}, b = {1,2,2} → D = |2/3 − 1/3|.
  EXPECT_NEAR(ks_two_sample({1, 1, 2}, {1, 2, 2}).statistic, 1.0 / 3.0, 1e-15);
  // p against the Kolmogorov distribution written with the other (Jacobi-transformed) series,
  // 1 − Q(λ) = √(2π)/λ Σ_{k≥1} exp(−(2k−1)²π²/(8λ²)): x = 0..N−1, y = x + s gives D = s/N exactly.
  const int n = 5000, shift = 136;
  std::vector<double> x(n), y(n);
  for (int i = 0; i < n; ++i) x[i] = i, y[i] = i + shift;
  const KsResult k = ks_two_sample(x, y);
  EXPECT_NEAR(k.statistic, double(shift) / n, 1e-15);
  const double m = std::sqrt(n / 2.0), lambda = (m + 0.12 + 0.11 / m) * k.statistic;
  double cdf = 0;
  for (int j = 1; j < 50; ++j)
    cdf += std::exp(-(2 * j - 1) * (2 * j - 1) * kPi * kPi / (8 * lambda * lambda));
  cdf *= std::sqrt(2 * kPi) / lambda;
  EXPECT_NEAR(k.p_value, 1 - cdf, 1e-9);
  EXPECT_NEAR(k.p_value, 0.05, 0.005);  // λ ≈ 1.36, the familiar 5% point
}

}  // namespace
}  // namespace kdm::analysis
