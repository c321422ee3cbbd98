// Algorithm 1 (chain.h) against the distribution it must sample, P ∝ exp(-E/T), and eq. 7's gradient
// against finite differences of E.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "platform/huge_pages.h"
#include "sampler/chain.h"

namespace kdm::gen {
namespace {

constexpr int kM = 8;          // a tiny torus: 8×8 nodes
constexpr float kRho = 0.43f;  // about four kernels fit

DensityGrid<2> uniform_grid() {
  DensityGrid<2> d;
  d.grid.dims = {kM, kM};
  d.grid.torus = true;
  d.rho.assign(kM * kM, kRho);
  return d;
}

std::vector<Particle<2>> fixed_points() {
  std::vector<Particle<2>> fixed(2);
  fixed[0].x = {1.3, 2.1};
  fixed[1].x = {5.2, 4.4};
  for (auto& p : fixed) p.active = false;
  return fixed;
}

// E with the free point at x, by brute force: all kernels splatted into a fresh residual.
double energy_with_free_point_at(const DensityGrid<2>& d, const ChainParams& params, Vec<2> x) {
  Chain<2> chain(d, params);
  Chain<2>::Scratch s;
  for (const auto& p : fixed_points()) chain.splat(p, 1.0f, s);
  Particle<2> free;
  free.x = x;
  chain.splat(free, 1.0f, s);
  return chain.energy();
}

constexpr int kBins = 4;  // 4×4 bins of 2×2 grid units

// Exact bin probabilities of the free point: ∫ exp(-E/T) over each bin (midpoint rule, 16 samples per
// grid unit per axis; E varies on the scale σ ≈ 1.5, so the rule's error is far below the test's tolerance).
std::vector<double> exact_bin_probabilities(const DensityGrid<2>& d, const ChainParams& params) {
  const int per_unit = 16, samples = kM * per_unit;
  std::vector<double> energy(samples * samples);
  double e_min = 1e300;
  for (int j = 0; j < samples; ++j)
    for (int i = 0; i < samples; ++i) {
      energy[j * samples + i] =
          energy_with_free_point_at(d, params, {(i + 0.5) / per_unit, (j + 0.5) / per_unit});
      e_min = std::min(e_min, energy[j * samples + i]);
    }
  std::vector<double> bins(kBins * kBins, 0.0);
  double total = 0;
  for (int j = 0; j < samples; ++j)
    for (int i = 0; i < samples; ++i) {
      const double w = std::exp(-(energy[j * samples + i] - e_min) / params.temperature);
      bins[(j * kBins / samples) * kBins + i * kBins / samples] += w;
      total += w;
    }
  for (double& b : bins) b /= total;
  return bins;
}

// Runs the chain on the free point and returns Pearson's χ² of its thinned positions against `expected`.
double chain_chi_square(const DensityGrid<2>& d, const ChainParams& params,
                        const std::vector<double>& expected) {
  Chain<2> chain(d, params);
  Chain<2>::Scratch s;
  for (const auto& p : fixed_points()) chain.splat(p, 1.0f, s);
  Particle<2> free;
  free.x = {3.0, 6.0};
  chain.splat(free, 1.0f, s);
  // Thinning: the bin indicator's autocorrelation drops below 0.05 within ~40 updates at these settings
  // (measured), so samples 50 updates apart are close to independent and Pearson's χ² applies.
  const int thin = 50, samples = 20000;
  std::vector<double> counts(kBins * kBins, 0.0);
  for (int t = 0; t < samples * thin; ++t) {
    Rng rng(7, static_cast<std::uint64_t>(t));
    chain.update(free, rng, s);
    if (t % thin == 0) {
      const int bx = static_cast<int>(free.x[0] / (kM / kBins)),
                by = static_cast<int>(free.x[1] / (kM / kBins));
      counts[by * kBins + bx] += 1;
    }
  }
  double chi2 = 0;
  for (int b = 0; b < kBins * kBins; ++b) {
    const double mu = expected[b] * samples;
    chi2 += (counts[b] - mu) * (counts[b] - mu) / mu;
  }
  return chi2;
}

// 15 degrees of freedom: P(χ² > 37.7) = 0.001. A correct chain passes at this fixed seed; the same
// test on the unadjusted chain (no MH test) with a large step fails it by a wide margin, which shows
// the test can tell a biased sampler from an exact one.
constexpr double kChiSquare15Dof999 = 37.7;

TEST(ChainTest, SamplesBoltzmannDistributionExactly) {
  const DensityGrid<2> d = uniform_grid();
  ChainParams params;
  params.temperature = 0.3;
  params.step = 2.0;
  const std::vector<double> expected = exact_bin_probabilities(d, params);
  // The distribution is far from uniform (else the test would be weak): bins differ by > 3x.
  EXPECT_GT(*std::max_element(expected.begin(), expected.end()),
            3 * *std::min_element(expected.begin(), expected.end()));
  const double chi2 = chain_chi_square(d, params, expected);
  std::printf("MH chain: chi2 = %.1f (15 dof)\n", chi2);
  EXPECT_LT(chi2, kChiSquare15Dof999);
}

TEST(ChainTest, UnadjustedLangevinIsDetectablyBiased) {
  const DensityGrid<2> d = uniform_grid();
  ChainParams params;
  params.temperature = 0.3;
  params.step = 2.0;
  const std::vector<double> expected = exact_bin_probabilities(d, params);
  params.metropolis = false;
  params.step = 8.0;
  const double chi2 = chain_chi_square(d, params, expected);
  std::printf("unadjusted chain: chi2 = %.1f (15 dof)\n", chi2);
  EXPECT_GT(chi2, 3 * kChiSquare15Dof999);
}

// The energy and its gradient do not depend on where the seam of the torus lies: a configuration moved by
// whole nodes, so that a kernel's footprint wraps across the seam or not, gives the same values.
TEST(ChainTest, EnergyAndGradientAreTheSameAcrossTheSeam) {
  constexpr int m = 64;
  DensityGrid<2> d;
  d.grid.dims = {m, m};
  d.grid.torus = true;
  d.rho.assign(m * m, kRho);
  Rng rng(11);
  std::vector<Particle<2>> base(160);
  for (auto& p : base) p.x = {m * rng.uniform(), m * rng.uniform()};
  base[0].x = {10.37, 20.81};
  double e0 = 0;
  Vec<2> g0{};
  for (int shift = 0; shift < m; ++shift) {
    for (int axis = 0; axis < 2; ++axis) {
      Chain<2> chain(d, ChainParams{});
      Chain<2>::Scratch s;
      std::vector<Particle<2>> moved = base;
      for (auto& p : moved) {
        p.x[axis] += shift;
        d.grid.canonical(p.x);
        chain.splat(p, 1.0f, s);
      }
      const double e = chain.energy_change_if_removed(moved[0], s);
      const Vec<2> g = chain.gradient(moved[0], s);
      if (shift == 0 && axis == 0) e0 = e, g0 = g;
      // Float sums in another order (a wrapping footprint is walked as two runs): a few ulps of R.
      EXPECT_NEAR(e, e0, 1e-5) << "shift " << shift << " axis " << axis;
      for (int k = 0; k < 2; ++k) EXPECT_NEAR(g[k], g0[k], 1e-5) << "shift " << shift << " axis " << axis;
    }
  }
}

// A sweep updates the checkerboard's cells colour by colour (checkerboard.h). With the cells fixed and
// points free to cross their borders, that order depended on where the points were, and the sweep no
// longer left P invariant: at 256 points on a 64² torus (two cells per axis, borders at 0 and 32) the
// side of a border whose cell is updated first held 5% fewer points than its share within half a node,
// the other side 5% more; on the torus this showed as fewer points just above 0 and more just below 1.
// The model is translation invariant, so both sides must hold the same. Measured here over 80 chains of
// 1,000 sweeps: (late side - early side) / share was +0.10 before the fix; its spread between chains is
// 0.13, so its standard error over 80 chains is 0.015, and the bound of 0.045 is three of them (the
// difference is -0.006 ± 0.009 over 200 chains with the fix).
TEST(ChainTest, CellBordersDoNotBiasTheDensity) {
  constexpr int m = 64, n = 256, chains = 80, sweeps = 1000, every = 5;
  constexpr double band = 0.5;  // nodes on each side of a border
  DensityGrid<2> d;
  d.grid.dims = {m, m};
  d.grid.torus = true;
  d.rho.assign(m * m, kRho);
  ChainParams params;
  params.temperature = 0.5 / 4.5;  // the sampler's defaults (kModelTemperaturePerUser, Δt = 0.35)
  params.step = 0.35;
  params.sigma_bound = 1.5 / std::sqrt(double(kRho));  // as the multi-scale driver bounds a level
  params.max_step = params.sigma_bound;
  // The cells Chain::sweeps() lays out for these bounds: two per axis, so there are borders to cross.
  Checkerboard<2> board;
  board.layout(d.grid, std::ceil(kCut * params.sigma_bound) + 1 + 3 + std::ceil(params.max_step));
  ASSERT_EQ(board.cells_per_axis()[0], 2);
  ASSERT_EQ(board.cells_per_axis()[1], 2);
  double early = 0, late = 0, records = 0, sum = 0, sum_sq = 0;
  for (int c = 0; c < chains; ++c) {
    Rng rng(1000 + c);
    std::vector<Particle<2>> points(n);
    for (auto& p : points) p.x = {m * rng.uniform(), m * rng.uniform()};
    Chain<2> chain(d, params);
    chain.splat_all(points, 1);
    ChainCounters counters;
    chain.sweeps(points, {std::uint64_t(77 + c), 0, 0, 1}, 20, 1, counters);  // from the uniform start
    double e = 0, l = 0;
    for (int s = 0; s < sweeps; s += every) {
      chain.sweeps(points, {std::uint64_t(77 + c), 0, 100 + s, 1}, every, 1, counters);
      for (const auto& p : points) {
        for (int k = 0; k < 2; ++k) {
          const double x = p.x[k];
          // Cell 0 ([0, 32)) is updated before cell 1 ([32, 64)) in every row of cells.
          e += x < band || (x >= m / 2 - band && x < m / 2);
          l += (x >= m / 2 && x < m / 2 + band) || x >= m - band;
        }
      }
    }
    const double share = (sweeps / every) * n * 2.0 * 2 * band / m;
    early += e, late += l, records += share;
    sum += (l - e) / share, sum_sq += (l - e) * (l - e) / (share * share);
  }
  const double diff = (late - early) / records, mean = sum / chains;
  const double se = std::sqrt((sum_sq / chains - mean * mean) / chains);
  std::printf(
      "within %.1f node of a border: early side %+.4f, late side %+.4f of the share; late - early "
      "%+.4f (standard error %.4f)\n",
      band, early / records - 1, late / records - 1, diff, se);
  EXPECT_LT(std::fabs(diff), 0.045);
}

TEST(ChainTest, GradientMatchesFiniteDifferences) {
  // Uniform density: σ is the same everywhere, so E's derivative is exactly eq. 7's (no σ term).
  DensityGrid<2> d;
  d.grid.dims = {32, 32};
  d.grid.torus = true;
  d.rho.assign(32 * 32, kRho);
  ChainParams params;
  Chain<2> chain(d, params);
  Chain<2>::Scratch s;
  Rng rng(3);
  std::vector<Particle<2>> others(40);
  for (auto& p : others) {
    p.x = {32 * rng.uniform(), 32 * rng.uniform()};
    chain.splat(p, 1.0f, s);
  }
  int checked = 0;
  for (int trial = 0; trial < 20; ++trial) {
    Particle<2> p;
    p.x = {32 * rng.uniform(), 32 * rng.uniform()};
    chain.splat(p, 1.0f, s);
    const Vec<2> g = chain.gradient(p, s);
    const double h = 1e-3;
    Vec<2> fd;
    bool kink = false;
    for (int k = 0; k < 2; ++k) {
      // E is piecewise smooth (|R| kinks where R = 0); central and one-sided differences agree only
      // away from kinks, and those trials are skipped.
      Particle<2> plus = p, minus = p;
      plus.x[k] += h;
      minus.x[k] -= h;
      chain.splat(p, -1.0f, s);
      chain.splat(plus, 1.0f, s);
      const double ep = chain.energy();
      chain.splat(plus, -1.0f, s);
      chain.splat(minus, 1.0f, s);
      const double em = chain.energy();
      chain.splat(minus, -1.0f, s);
      chain.splat(p, 1.0f, s);
      const double e0 = chain.energy();
      fd[k] = (ep - em) / (2 * h);
      kink |= std::fabs((ep - e0) / h - (e0 - em) / h) > 0.05 * (std::fabs(fd[k]) + 0.1);
    }
    chain.splat(p, -1.0f, s);
    if (kink) continue;
    ++checked;
    for (int k = 0; k < 2; ++k) EXPECT_NEAR(g[k], fd[k], 0.02 * (std::fabs(fd[k]) + 0.05)) << "axis " << k;
  }
  EXPECT_GE(checked, 10);
}

}  // namespace
}  // namespace kdm::gen

namespace kdm::gen {
namespace {

// The ziggurat's deviates against the standard normal: Kolmogorov–Smirnov over 10^6 draws (fixed seed)
// with the 1% critical value 1.63/√n; the moments and the mass of the tail beyond the ziggurat's base
// (drawn by its own, rarely taken path) within 4 standard errors. A layer table off by one, or a tail
// drawn from the wrong distribution, moves D to several times the bar.
TEST(RngTest, ZigguratDrawsTheStandardNormal) {
  Rng rng(2026);
  const int n = 1000000;
  std::vector<double> v(n);
  double mean = 0, second = 0, tail = 0;
  for (double& x : v) {
    x = rng.normal();
    mean += x / n;
    second += x * x / n;
    tail += std::fabs(x) > NormalZiggurat::kTailStart ? 1.0 / n : 0.0;
  }
  std::sort(v.begin(), v.end());
  double d = 0;
  for (int i = 0; i < n; ++i) {
    const double cdf = 0.5 * std::erfc(-v[i] / std::sqrt(2.0));
    d = std::max({d, std::fabs(cdf - double(i) / n), std::fabs(double(i + 1) / n - cdf)});
  }
  const double tail_expected = std::erfc(NormalZiggurat::kTailStart / std::sqrt(2.0));
  std::printf("KS D %.2e (bar %.2e), mean %.4f, variance %.4f, tail %.2e (expected %.2e)\n", d,
              1.63 / std::sqrt(double(n)), mean, second - mean * mean, tail, tail_expected);
  EXPECT_LT(d, 1.63 / std::sqrt(double(n)));
  EXPECT_NEAR(mean, 0.0, 4 / std::sqrt(double(n)));
  EXPECT_NEAR(second - mean * mean, 1.0, 4 * std::sqrt(2.0 / n));
  EXPECT_NEAR(tail, tail_expected, 4 * std::sqrt(tail_expected / n));
}

// A footprint kept between sweeps must be the footprint a fresh build gives, field for field, and must
// not be used for any other position or scale.
TEST(ChainTest, CachedFootprintIsTheFreshBuild) {
  Grid<2> grid;
  grid.dims = {64, 48};
  KernelTable table;
  for (const Vec<2> x : {Vec<2>{20.3, 17.8}, Vec<2>{30.0, 47.9}, Vec<2>{63.2, 5.5}}) {
    Footprint<2> built, loaded;
    built.build(grid, x, 1.52, 0.43, true, &table);
    CachedFootprint<2> cache;
    cache.keep(built, x, 1.52);
    if (!built.contiguous) {  // wraps along axis 0: never kept
      EXPECT_FALSE(cache.holds(x, 1.52, 0.43));
      continue;
    }
    ASSERT_TRUE(cache.holds(x, 1.52, 0.43));
    EXPECT_FALSE(cache.holds(Vec<2>{x[0] + 1e-9, x[1]}, 1.52, 0.43));
    EXPECT_FALSE(cache.holds(x, 1.53, 0.43));
    cache.load(loaded);
    EXPECT_EQ(loaded.amplitude, built.amplitude);
    EXPECT_EQ(loaded.start, built.start);
    ASSERT_EQ(loaded.width, built.width);
    for (int k = 0; k < built.width; ++k) {
      EXPECT_EQ(loaded.row_value[k], built.row_value[k]);
      EXPECT_EQ(loaded.row_deriv[k], built.row_deriv[k]);
    }
    ASSERT_EQ(loaded.axes[1].count, built.axes[1].count);
    for (int b = 0; b < built.axes[1].count; ++b) {
      EXPECT_EQ(loaded.axes[1].index[b], built.axes[1].index[b]);
      EXPECT_EQ(loaded.axes[1].value[b], built.axes[1].value[b]);
      EXPECT_EQ(loaded.axes[1].deriv[b], built.axes[1].deriv[b]);
    }
  }
}

// Scratch that one thread writes on every update must not share a cache line with anything else: small
// buffers from the allocator do (glibc's chunks are 16 bytes apart), and that made half the seeds a third
// slower on two threads (kernel.h, LineAllocator).
TEST(LineAllocatorTest, SmallBuffersShareNoCacheLineWithLaterAllocations) {
  auto line = [](const void* p) { return reinterpret_cast<std::uintptr_t>(p) / 64; };
  std::vector<LineVector<float>> owned;
  std::vector<std::vector<float>> others;
  for (int i = 0; i < 64; ++i) {
    owned.emplace_back(static_cast<std::size_t>(1 + i % 13));
    others.emplace_back(static_cast<std::size_t>(1 + i % 5));
  }
  for (const LineVector<float>& v : owned) {
    ASSERT_EQ(reinterpret_cast<std::uintptr_t>(v.data()) % 64, 0u);
    const std::uintptr_t first = line(v.data()), last = line(v.data() + v.size() - 1);
    for (const std::vector<float>& o : others)
      EXPECT_TRUE(line(o.data() + o.size() - 1) < first || line(o.data()) > last)
          << "a buffer of " << o.size() << " floats shares a line with one of " << v.size();
  }
  for (std::size_t n = 1; n <= 100; ++n) {  // whole lines asked of the heap, so nothing follows in the last
    EXPECT_EQ(LineAllocator<float>::bytes(n) % 64, 0u) << n;
    EXPECT_GE(LineAllocator<float>::bytes(n), n * sizeof(float)) << n;
  }
  EXPECT_EQ(alignof(Chain<2>::Scratch), 64u);
  EXPECT_EQ(sizeof(Chain<2>::Scratch) % 64, 0u);
}

// The footprint cache is advised into huge pages. Advice must never touch contents (MADV_DONTNEED or
// MADV_FREE in its place would zero pages that were written), whatever the range's alignment.
TEST(HugePagesTest, AdviceKeepsTheContentsOfAnyRange) {
  std::vector<std::uint64_t> buffer((std::size_t(6) << 20) / sizeof(std::uint64_t));
  for (std::size_t i = 0; i < buffer.size(); ++i) buffer[i] = i * 0x9e3779b97f4a7c15ull;
  char* bytes = reinterpret_cast<char*>(buffer.data());
  const std::size_t size = buffer.size() * sizeof(std::uint64_t);
  advise_huge_pages(bytes, size);
  advise_huge_pages(bytes + 3, size - 5);
  advise_huge_pages(bytes + 4096, 100);
  advise_huge_pages(nullptr, 0);
  for (std::size_t i = 0; i < buffer.size(); ++i) ASSERT_EQ(buffer[i], i * 0x9e3779b97f4a7c15ull) << i;
}

// The grids and particle arrays use these in place of the vector constructor and resize(): they must be
// those, contents and all, however large (6 MiB holds whole 2 MiB pages to advise) or small.
TEST(HugePagesTest, VectorHelpersKeepTheirContents) {
  const std::size_t big = (std::size_t(6) << 20) / sizeof(float);
  const std::vector<float> filled = vector_on_huge_pages(big, 2.5f);
  ASSERT_EQ(filled.size(), big);
  EXPECT_EQ(std::count(filled.begin(), filled.end(), 2.5f), static_cast<std::ptrdiff_t>(big));
  EXPECT_TRUE(vector_on_huge_pages(0, 1.0f).empty());
  std::vector<int> v = {7, 8, 9};
  resize_on_huge_pages(v, big);  // grows: new storage, old contents first, then zeros
  ASSERT_EQ(v.size(), big);
  EXPECT_EQ(v[0], 7);
  EXPECT_EQ(v[2], 9);
  EXPECT_EQ(std::count(v.begin() + 3, v.end(), 0), static_cast<std::ptrdiff_t>(big - 3));
  v[big - 1] = 5;
  resize_on_huge_pages(v, 2);  // shrinks in place
  EXPECT_EQ(v, (std::vector<int>{7, 8}));
  resize_on_huge_pages(v, 4);
  EXPECT_EQ(v, (std::vector<int>{7, 8, 0, 0}));
}

TEST(HugePagesTest, LargeFootprintCacheHoldsNothingUntilKept) {
  FootprintCache<2> cache;
  const std::size_t n = (std::size_t(8) << 20) / sizeof(CachedFootprint<2>);  // advised: 8 MiB
  cache.reset(n, 2);
  ASSERT_EQ(cache.size(), n);
  Grid<2> grid;
  grid.dims = {64, 48};
  KernelTable table;
  Footprint<2> built;
  const Vec<2> x{20.3, 17.8};
  built.build(grid, x, 1.52, 0.43, true, &table);
  for (std::size_t j : {std::size_t(0), n / 2, n - 1}) {
    EXPECT_FALSE(cache[j].holds(x, 1.52, 0.43)) << j;
    cache[j].keep(built, x, 1.52);
    EXPECT_TRUE(cache[j].holds(x, 1.52, 0.43)) << j;
  }
}

}  // namespace
}  // namespace kdm::gen
