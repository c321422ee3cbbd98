// Nearest-neighbour statistics: the cell list against brute force, exact lattice values (2D near-hex torus
// lattice, 3D FCC), the Poisson mean, and input validation.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "kdm/analysis/classes.h"
#include "kdm/analysis/common.h"
#include "kdm/analysis/density.h"
#include "kdm/analysis/nearest_neighbour.h"
#include "test_sets.h"

namespace kdm::analysis {
namespace {

using testing::torus_hex_lattice;
using testing::uniform_set;

// `copies`: every 7th point is repeated this many times more, at its very position, the copies spread
// through the set (groups the search answers without comparing their members).
void brute_force_check(int dim, bool torus, std::size_t n, unsigned seed, std::size_t copies = 0) {
  tools::PointSet s = uniform_set(n, seed, dim);
  for (std::size_t c = 0; c < copies; ++c)
    for (std::size_t i = 0; i < n; i += 7)
      for (int a = 0; a < dim; ++a) s.coords.push_back(s.coords[i * dim + a]);
  n = s.size();
  const NearestNeighbours nn = nearest_neighbours(s.coords, dim, torus, 2);
  for (std::size_t i = 0; i < n; ++i) {
    double best = std::numeric_limits<double>::infinity();
    std::size_t best_j = 0;
    for (std::size_t j = 0; j < n; ++j) {
      if (j == i) continue;
      double d2 = 0;
      for (int a = 0; a < dim; ++a) {
        const double d = axis_delta(s.coords[i * dim + a], s.coords[j * dim + a], torus);
        d2 += d * d;
      }
      if (d2 < best) best = d2, best_j = j;
    }
    ASSERT_DOUBLE_EQ(nn.distance[i], std::sqrt(best)) << "point " << i;
    ASSERT_EQ(nn.index[i], best_j) << "point " << i;
  }
}

TEST(NearestNeighbour, CellListMatchesBruteForce) {
  brute_force_check(2, true, 700, 1);
  brute_force_check(2, false, 700, 2);
  brute_force_check(3, true, 500, 3);
  brute_force_check(3, false, 500, 4);
  brute_force_check(2, true, 5, 5);  // grid of one cell: wrap-around visits it repeatedly
  brute_force_check(3, false, 3, 6);
}

TEST(NearestNeighbour, PointsOnOneAnotherMatchBruteForce) {
  brute_force_check(2, true, 300, 7, 1);
  brute_force_check(2, false, 300, 8, 3);
  brute_force_check(3, true, 200, 9, 2);
  brute_force_check(3, false, 200, 10, 1);
}

// The closest pair of different classes, against brute force, on the torus and in the box, with classes
// of very different sizes (one class of 5 points among 2,000).
TEST(NearestNeighbour, CrossClassClosestPairMatchesBruteForce) {
  for (bool torus : {false, true})
    for (int rare : {0, 1}) {
      tools::PointSet s = uniform_set(2000, 11 + rare);
      for (std::size_t i = 0; i < s.size(); ++i)
        s.classes.push_back(static_cast<std::uint8_t>(rare ? (i % 400 == 0) : i % 3));
      double best = HUGE_VAL;
      for (std::size_t i = 0; i < s.size(); ++i)
        for (std::size_t j = i + 1; j < s.size(); ++j) {
          if (s.classes[i] == s.classes[j]) continue;
          double dx = std::fabs(s.coords[2 * i] - s.coords[2 * j]),
                 dy = std::fabs(s.coords[2 * i + 1] - s.coords[2 * j + 1]);
          if (torus) dx = std::min(dx, 1 - dx), dy = std::min(dy, 1 - dy);
          best = std::min(best, std::hypot(dx, dy));
        }
      EXPECT_DOUBLE_EQ(cross_class_closest(s, torus), best / hex_spacing(s.size())) << torus << rare;
    }
  // With a target density, in local spacings: each pair's distance over d_hex scaled by √(mean ρ / ρ) at
  // its midpoint, among the pairs within two local spacings of either point.
  const DensityFunction ramp = [](double x, double) { return 0.2 + x; };  // mean 0.7
  for (bool torus : {false, true}) {
    tools::PointSet s = uniform_set(1500, 21);
    for (std::size_t i = 0; i < s.size(); ++i) s.classes.push_back(static_cast<std::uint8_t>(i % 3));
    const double spacing = hex_spacing(s.size());
    const auto local = [&](double x, double y) { return spacing * std::sqrt(0.7 / ramp(x, y)); };
    double best = HUGE_VAL;
    for (std::size_t i = 0; i < s.size(); ++i)
      for (std::size_t j = i + 1; j < s.size(); ++j) {
        if (s.classes[i] == s.classes[j]) continue;
        double dx = s.coords[2 * j] - s.coords[2 * i], dy = s.coords[2 * j + 1] - s.coords[2 * i + 1];
        if (torus) dx -= std::round(dx), dy -= std::round(dy);
        const double d = std::hypot(dx, dy);
        if (d > 2 * local(s.coords[2 * i], 0) && d > 2 * local(s.coords[2 * j], 0)) continue;
        double mx = s.coords[2 * i] + dx / 2;
        if (torus) mx -= std::floor(mx);
        best = std::min(best, d / local(mx, 0));
      }
    // The ramp's mean over density_scale's 256² grid is 0.7 to rounding: the same up to 1e-12.
    EXPECT_NEAR(cross_class_closest(s, torus, ramp), best, 1e-9) << torus;
    EXPECT_NE(cross_class_closest(s, torus, ramp), cross_class_closest(s, torus)) << torus;
  }
  tools::PointSet one = uniform_set(10, 1);
  one.classes.assign(10, 4);
  EXPECT_TRUE(std::isnan(cross_class_closest(one, true)));
  one.classes.clear();
  EXPECT_THROW(cross_class_closest(one, true), InvalidInput);
}

TEST(NearestNeighbour, TorusWrapsAroundTheEdge) {
  const std::vector<double> c = {0.01, 0.5, 0.99, 0.5, 0.5, 0.9};
  const NearestNeighbours t = nearest_neighbours(c, 2, true);
  EXPECT_NEAR(t.distance[0], 0.02, 1e-12);
  EXPECT_EQ(t.index[0], 1u);
  EXPECT_NEAR(t.offset[0], -0.02, 1e-12);  // the link leaves through x = 0
  const NearestNeighbours b = nearest_neighbours(c, 2, false);
  EXPECT_NEAR(b.distance[0], std::hypot(0.49, 0.4), 1e-12);
}

TEST(NearestNeighbour, NearHexTorusLatticeHasExactSpacing) {
  const int cols = 26, rows = 30;  // rows/cols = 1.1538 ≈ 2/√3 = 1.1547
  const tools::PointSet s = torus_hex_lattice(cols, rows);
  const double horizontal = 1.0 / cols, diagonal = std::hypot(0.5 / cols, 1.0 / rows);
  const double spacing = std::min(horizontal, diagonal);
  const double expected = spacing / hex_spacing(s.size());
  const NNStats st = nn_stats(s.coords, 2, true);
  EXPECT_NEAR(st.dmin, expected, 1e-9);
  EXPECT_NEAR(st.davg, expected, 1e-9);
  EXPECT_NEAR(st.nn1, expected, 1e-9);
  EXPECT_NEAR(expected, 1.0, 0.01);  // and it is close to the hexagonal ideal
}

TEST(NearestNeighbour, FccLatticeIsOneInFccUnits) {
  const int m = 6;  // m³ cubic cells with 4 points each: NN distance (1/m)/√2 = fcc_spacing(4m³)
  tools::PointSet s;
  s.dim = 3;
  const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  for (int z = 0; z < m; ++z)
    for (int y = 0; y < m; ++y)
      for (int x = 0; x < m; ++x)
        for (const auto& b : basis) {
          s.coords.push_back((x + b[0]) / m);
          s.coords.push_back((y + b[1]) / m);
          s.coords.push_back((z + b[2]) / m);
        }
  const NNStats st = nn_stats(s.coords, 3, true);
  EXPECT_NEAR(st.dmin, 1.0, 1e-9);
  EXPECT_NEAR(st.davg, 1.0, 1e-9);
}

TEST(NearestNeighbour, PoissonMeanDistance) {
  // Poisson NN distance in 2D has mean 1/(2√λ) and sd sqrt((4 − π)/(4πλ)); in d_hex units the mean is
  // 0.5 / sqrt(2/√3) = 0.4653. With 4·16384 pooled (weakly dependent) values, sd(mean) ≈ 0.0009 in these
  // units.
  double sum = 0;
  std::size_t count = 0;
  for (unsigned seed = 10; seed < 14; ++seed) {
    const tools::PointSet s = uniform_set(16384, seed);
    const NNStats st = nn_stats(s.coords, 2, true);
    sum += st.davg * st.count;
    count += st.count;
  }
  EXPECT_NEAR(sum / count, 0.5 / std::sqrt(2.0 / std::sqrt(3.0)), 0.005);
}

TEST(NearestNeighbour, SummaryAndQuantile) {
  const NNStats st = summarise_nn({1, 2, 3, 4}, 2.0, 4, 2.0);
  EXPECT_DOUBLE_EQ(st.dmin, 0.5);
  EXPECT_DOUBLE_EQ(st.davg, 1.25);
  EXPECT_DOUBLE_EQ(st.dmax, 2.0);
  EXPECT_DOUBLE_EQ(st.nn1, 0.5);
  ASSERT_EQ(st.histogram.size(), 4u);
  EXPECT_EQ(st.histogram[1], 1u);  // 0.5 ∈ [0.5, 1)
  EXPECT_EQ(st.histogram[3], 2u);  // 1.5 and the overflow 2.0
  EXPECT_EQ(st.overflow, 1u);      // 2.0, at hist_max: counted apart too
  std::vector<double> v(100);
  for (int i = 0; i < 100; ++i) v[i] = 100 - i;
  EXPECT_DOUBLE_EQ(quantile(v, 0.01), 1.0);
  EXPECT_DOUBLE_EQ(quantile(v, 0.5), 50.0);
  EXPECT_TRUE(std::isnan(summarise_nn({}, 1.0).davg));
}

TEST(NearestNeighbour, RejectsBadInput) {
  EXPECT_THROW(nearest_neighbours({0.5, 0.5}, 2, true), InvalidInput);            // one point
  EXPECT_THROW(nearest_neighbours({0.1, 0.2, 0.3}, 2, true), InvalidInput);       // not a multiple of dim
  EXPECT_THROW(nearest_neighbours({0.1, 0.2, 1.5, 0.3}, 2, true), InvalidInput);  // outside [0,1]
  EXPECT_THROW(nearest_neighbours({0.1, NAN, 0.5, 0.3}, 2, true), InvalidInput);
  EXPECT_THROW(nearest_neighbours({0.1, 0.2, 0.5, 0.3}, 4, true), InvalidInput);
}

}  // namespace
}  // namespace kdm::analysis
