// The full sampler where a density's range is extreme: few points for a dense spot beside a faint one, a
// sharp step, a small piece of the support apart from the rest, and ramps of 1:10^7 and more, where kernels
// in the faint part are wide and freeze early.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "kdm/analysis/nearest_neighbour.h"
#include "kdm/generator/sampler.h"

namespace kdm::gen {
namespace {

SamplerOptions options_for(std::int64_t n, Domain domain, std::uint64_t seed) {
  SamplerOptions o;
  o.n = n;
  o.domain = domain;
  o.seed = seed;
  o.threads = 1;
  return o;
}

/// The ramp R^-x across the unit square: 1 at x = 0, 1/R at x = 1.
Density steep_ramp(double R) {
  Density d;
  d.function = [=](const double* u) { return std::pow(R, -u[0]); };
  return d;
}

bool in_square(double x, double y, double x0, double y0, double side) {
  return x >= x0 && x < x0 + side && y >= y0 && y < y0 + side;
}

// A black pixel and a pixel of grey 254 on white, 64 × 64: 255 parts of the mass against 1. Ten points
// belong on the black one (each lands on the grey one with probability 1/256). The last kernels that bring
// the count to n must fit the room left, not go whole where the density is nearly zero and stack there.
TEST(ExtremeDensityTest, FewPointsCoverADenseSpotNotAFaintOne) {
  const double side = 1.0 / 64;
  Density d;
  d.function = [=](const double* u) {
    if (in_square(u[0], u[1], 10 * side, 53 * side, side)) return 1.0;
    if (in_square(u[0], u[1], 50 * side, 23 * side, side)) return 1.0 / 255;
    return 0.0;
  };
  for (std::uint64_t seed : {1, 2, 3}) {
    const SampleResult r = sample(options_for(10, Domain::kBox, seed), d);
    int on_dense = 0;
    for (std::size_t j = 0; j < r.size(); ++j)
      on_dense += in_square(r.points[2 * j], r.points[2 * j + 1], 10 * side, 53 * side, side * (1 + 1e-9));
    EXPECT_GE(on_dense, 9) << "seed " << seed;
    // Ten points in a square of side 1/64 are about 0.005 apart; stacked ones were 0 apart.
    const analysis::NearestNeighbours nn = analysis::nearest_neighbours(r.points, 2, false, 1);
    for (double dist : nn.distance) EXPECT_GT(dist, 5e-4) << "seed " << seed;
  }
}

// Nearest-neighbour distance of each point over the spacing 1/√ρ the ramp R^-x asks for there.
std::vector<double> spacing_ratios(const SampleResult& r, double R, bool torus) {
  const double n = static_cast<double>(r.size());
  const analysis::NearestNeighbours nn = analysis::nearest_neighbours(r.points, 2, torus, 1);
  std::vector<double> ratio(r.size());
  for (std::size_t j = 0; j < r.size(); ++j) {
    const double rho = n * std::log(R) / (1 - 1 / R) * std::pow(R, -r.points[2 * j]);
    ratio[j] = nn.distance[j] * std::sqrt(rho);
  }
  return ratio;
}

// On a torus the ramp's faint end meets its dense one. Kernels placed whole in the faint end to make up n
// froze there, several at one node: 20 repeated points at 1:10^7 and 2,000 points, 2,157 at 1:10^9 and
// 20,000. Now none.
TEST(ExtremeDensityTest, NoRepeatedPointsOnSteepRamps) {
  for (const auto& [R, n] : {std::pair{1e7, 2000}, std::pair{1e9, 20000}}) {
    const SampleResult r = sample(options_for(n, Domain::kTorus, 1), steep_ramp(R));
    const analysis::NearestNeighbours nn = analysis::nearest_neighbours(r.points, 2, true, 1);
    int repeated = 0;
    for (double dist : nn.distance) repeated += dist < 1e-9;
    EXPECT_EQ(repeated, 0) << "1:" << R;
  }
}

// Kernels born by a split sit closer than their spacing until a sweep spreads them; if they froze at birth
// they stayed so, and active kernels could not follow the ramp into its faint end, where their kernels
// would be wider than the bound. At 1:10^7 with 20,000 points, seeds 1–6, points nearer than 0.3 of the
// local spacing numbered 31–160 that way, and 0–5 now (0.3: well below blue noise's nearest distances,
// whose median ratio here is 0.94). 15 is three times the worst measured.
TEST(ExtremeDensityTest, FaintEndOfASteepRampHasNoClumps) {
  const double R = 1e7;
  const Density d = steep_ramp(R);
  for (std::uint64_t seed : {3, 4}) {
    const SampleResult r = sample(options_for(20000, Domain::kBox, seed), d);
    int clumped = 0;
    for (double ratio : spacing_ratios(r, R, false)) clumped += ratio < 0.3;
    std::printf("1:1e7 ramp, seed %d: %d points nearer than 0.3 of the spacing\n", int(seed), clumped);
    EXPECT_LE(clumped, 15) << "seed " << seed;
  }
}

// In a box a 1:10^6 ramp's last tenth expects 0.06 of 20,000 points. Once count fixing had no node left
// short of mass, the kernels it added to make up n went where a one-point kernel is widest, one a node of
// the faintest column: 52, 2, 1, 15, 8, 3, 10 and 5 points in that tenth at seeds 1-8, a row along the far
// wall. Now 0 or 1 there at those seeds; 3 allows the odd point and fails the row.
TEST(ExtremeDensityTest, TheFaintEndOfARampGetsNoRowOfPointsToMakeUpTheCount) {
  const double R = 1e6;
  const Density d = steep_ramp(R);
  for (std::uint64_t seed : {1, 4}) {
    const SampleResult r = sample(options_for(20000, Domain::kBox, seed), d);
    int last_tenth = 0;
    for (std::size_t j = 0; j < r.size(); ++j) last_tenth += r.points[2 * j] > 0.9;
    EXPECT_LE(last_tenth, 3) << "seed " << seed;
  }
}

/// The share of a density's integral inside a region, by the midpoint rule on a 1000² grid.
template <class Inside>
double share_inside(const Density& d, Inside inside) {
  double part = 0, whole = 0;
  const int m = 1000;
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) {
      const double u[2] = {(i + 0.5) / m, (j + 0.5) / m};
      const double v = d.function(u);
      whole += v;
      if (inside(u[0], u[1])) part += v;
    }
  return part / whole;
}

/// The smallest distance between points of `xy` inside the square [lo, hi)², by cells of side `cell`.
double closest_pair_inside(const std::vector<double>& xy, double lo, double hi, double cell) {
  const int side = static_cast<int>((hi - lo) / cell) + 1;
  std::vector<std::vector<std::size_t>> cells(static_cast<std::size_t>(side) * side);
  auto cell_of = [&](double v) { return std::min(side - 1, static_cast<int>((v - lo) / cell)); };
  for (std::size_t i = 0; i < xy.size(); i += 2)
    if (xy[i] >= lo && xy[i] < hi && xy[i + 1] >= lo && xy[i + 1] < hi)
      cells[std::size_t(cell_of(xy[i + 1])) * side + cell_of(xy[i])].push_back(i);
  double closest = HUGE_VAL;
  for (int cy = 0; cy < side; ++cy)
    for (int cx = 0; cx < side; ++cx)
      for (std::size_t i : cells[std::size_t(cy) * side + cx])
        for (int ny = std::max(0, cy - 1); ny <= std::min(side - 1, cy + 1); ++ny)
          for (int nx = std::max(0, cx - 1); nx <= std::min(side - 1, cx + 1); ++nx)
            for (std::size_t j : cells[std::size_t(ny) * side + nx])
              if (j > i) closest = std::min(closest, std::hypot(xy[i] - xy[j], xy[i + 1] - xy[j + 1]));
  return closest;
}

// A 100 × 100 array of 0.02 with a 30 × 30 block of 1.02 in a corner, 40,000 points: the faint side
// (outside the block) should hold the integral's share, 6,890 points, and the block no stacked points.
// Count fixing kept to kernels no heavier than the surplus removed the faint side's light kernels by the
// dozen where one dense kernel was the cheaper (at these seeds the background kept 0.66 and 0.61 of its
// share), and kernels lighter than their node asks for, added to make up n, hid in their heavy neighbours'
// footprints and refined into clumps (pairs 0.22 and 0.28 d_hex apart here, 7 of 12 runs on a torus or in
// a box). Now 0.97 and 1.00 (seeds 1-6, torus and box: 0.95-1.00) and no pair under 0.45 d_hex in the
// block in those 12 runs. 0.85 and 0.4 lie below every run measured and above those failures.
TEST(ExtremeDensityTest, TheFaintSideOfASharpStepKeepsItsPoints) {
  std::vector<float> values(100 * 100, 0.02f);
  for (int y = 70; y < 100; ++y)
    for (int x = 70; x < 100; ++x) values[y * 100 + x] += 1.0f;
  const Density d = Density::from_values(100, 100, values);
  auto faint = [](double x, double y) { return !(x >= 0.7 && y >= 0.7); };
  const int n = 40000;
  const double expected = n * share_inside(d, faint);
  for (std::uint64_t seed : {2, 4}) {
    const SampleResult r = sample(options_for(n, Domain::kTorus, seed), d);
    int count = 0;
    for (std::size_t i = 0; i < r.points.size(); i += 2) count += faint(r.points[i], r.points[i + 1]);
    const double block_spacing = std::sqrt(2 / (std::sqrt(3.0) * (n - expected) / 0.09));  // d_hex there
    const double closest = closest_pair_inside(r.points, 0.705, 0.995, block_spacing) / block_spacing;
    std::printf(
        "step 1:51, seed %d: %d points on the faint side, %.3f of %.0f; closest pair in the block "
        "%.3f d_hex\n",
        int(seed), count, count / expected, expected, closest);
    EXPECT_GE(count, 0.85 * expected) << "seed " << seed;
    EXPECT_GE(closest, 0.4) << "seed " << seed;
  }
}

// A disk of radius 0.2 and one of 0.03 (a 200 × 200 array of 1 and 0): the small one is narrower than a
// kernel of the coarsest level, which placed one kernel of weight 16 there; nothing carries weight across
// zero density after that, so it kept 16 points of its 218 at 10,000 points (64 of 872 at 40,000).
// Kernels moved between the pieces of the support give it 218 at seeds 1-2 (872 at 40,000); 5% either side
// is far from the old count and leaves room for a few fringe points outside the disk.
TEST(ExtremeDensityTest, ASmallPieceOfTheSupportGetsItsShare) {
  std::vector<float> values(200 * 200, 0.0f);
  auto inside = [](double x, double y, double cx, double cy, double r) {
    return (x - cx) * (x - cx) + (y - cy) * (y - cy) < r * r;
  };
  for (int row = 0; row < 200; ++row)
    for (int col = 0; col < 200; ++col) {
      const double x = (col + 0.5) / 200, y = (row + 0.5) / 200;  // row 0 at the bottom
      if (inside(x, y, 0.25, 0.5, 0.2) || inside(x, y, 0.8, 0.8, 0.03)) values[row * 200 + col] = 1;
    }
  const Density d = Density::from_values(200, 200, values);
  const int n = 10000;
  const double share = n * share_inside(d, [](double x, double) { return x > 0.6; });
  for (std::uint64_t seed : {1, 2}) {
    const SampleResult r = sample(options_for(n, Domain::kTorus, seed), d);
    int count = 0;
    for (std::size_t i = 0; i < r.points.size(); i += 2) count += r.points[i] > 0.6;
    std::printf("small disk, seed %d: %d points of a share of %.1f (%lld kernels moved between pieces)\n",
                int(seed), count, share, static_cast<long long>(r.report.moved_between_pieces));
    EXPECT_NEAR(count, share, 0.05 * share) << "seed " << seed;
    EXPECT_GT(r.report.moved_between_pieces, 0);
  }
}

}  // namespace
}  // namespace kdm::gen
