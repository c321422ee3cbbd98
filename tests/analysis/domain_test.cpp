// Point sets drawn in a rectangle (box): measured in that domain scaled to unit area (volume). Nearest
// neighbours and torus wrap against brute force, a set copied twice side by side (a 2:1 torus that is the
// square torus repeated) against the square set, the periodogram on the rectangle's reciprocal lattice
// against the direct sum, and a sampler's 2:1 set against its square sets.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "empty_circles_copies.h"
#include "kdm/analysis/common.h"
#include "kdm/analysis/empty_circles.h"
#include "kdm/analysis/nearest_neighbour.h"
#include "kdm/analysis/periodogram.h"
#include "kdm/analysis/report.h"
#include "kdm/generator/sampler.h"
#include "test_sets.h"

namespace kdm::analysis {
namespace {

using testing::uniform_set;

constexpr double kPi = 3.14159265358979323846;

TEST(Domain, SidesHaveUnitMeasureAndTheSquareIsExact) {
  const double two[3] = {2, 1, 1}, box[3] = {2, 1, 0.5}, equal[3] = {3, 3, 3};
  const Sides r = unit_measure_sides(two, 2);
  EXPECT_NEAR(r[0], std::sqrt(2.0), 1e-15);
  EXPECT_NEAR(r[0] * r[1], 1.0, 1e-15);
  const Sides b = unit_measure_sides(box, 3);
  EXPECT_NEAR(b[0] * b[1] * b[2], 1.0, 1e-15);
  EXPECT_NEAR(b[0] / b[2], 4.0, 1e-14);
  EXPECT_TRUE(unit_sides(unit_measure_sides(equal, 3)));
  EXPECT_TRUE(unit_sides(unit_measure_sides(two + 1, 2)));  // {1, 1}: the square, whatever z says
  for (const double bad : {0.0, -1.0, std::nan(""), HUGE_VAL}) {
    const double sides[3] = {1, bad, 1};
    EXPECT_THROW(unit_measure_sides(sides, 2), InvalidInput) << bad;
  }
  const double far[3] = {1e5, 1, 1};
  EXPECT_THROW(unit_measure_sides(far, 2), InvalidInput);
}

// Every point's nearest neighbour by comparing all pairs, in the domain's lengths (the minimum image on a
// torus of periods `sides`).
void brute_force_check(int dim, bool torus, std::size_t n, unsigned seed, const double* extent) {
  const tools::PointSet s = uniform_set(n, seed, dim);
  const Sides sides = unit_measure_sides(extent, dim);
  const NearestNeighbours nn = nearest_neighbours(s.coords, dim, torus, 2, sides);
  for (std::size_t i = 0; i < n; ++i) {
    double best = HUGE_VAL;
    std::size_t best_j = 0;
    for (std::size_t j = 0; j < n; ++j) {
      if (j == i) continue;
      double d2 = 0;
      for (int a = 0; a < dim; ++a) {
        double d = std::fabs(s.coords[j * dim + a] - s.coords[i * dim + a]);
        if (torus) d = std::min(d, 1 - d);  // the nearer of the two ways round
        d2 += d * sides[a] * d * sides[a];
      }
      if (d2 < best) best = d2, best_j = j;
    }
    ASSERT_NEAR(nn.distance[i], std::sqrt(best), 1e-14) << "point " << i;
    ASSERT_EQ(nn.index[i], best_j) << "point " << i;
  }
}

TEST(Domain, NearestNeighboursOnARectangleAndABoxMatchBruteForce) {
  const double wide[3] = {2, 1, 1}, tall[3] = {1, 5, 1}, box[3] = {2, 1, 0.5};
  brute_force_check(2, true, 600, 11, wide);
  brute_force_check(2, false, 600, 12, wide);
  brute_force_check(2, true, 400, 13, tall);
  brute_force_check(3, true, 400, 14, box);
  brute_force_check(3, false, 400, 15, box);
  brute_force_check(2, true, 4, 16, tall);  // one cell across: the wrap visits it repeatedly
}

// A 2:1 torus holding a square torus set twice, side by side, is that torus repeated: every point's
// neighbours, and every empty circle, are the square set's (in units of d_hex, which the doubled count
// and the √2-wide domain scale alike).
TEST(Domain, ASquareSetRepeatedOnATwoToOneTorusMeasuresAsTheSquare) {
  const tools::PointSet square = uniform_set(500, 21);
  tools::PointSet twice;
  for (int copy = 0; copy < 2; ++copy)
    for (std::size_t i = 0; i < square.size(); ++i)
      twice.coords.insert(twice.coords.end(), {(square.coords[2 * i] + copy) / 2, square.coords[2 * i + 1]});
  AnalysisOptions o;
  o.spectrum = false;
  const AnalysisReport a = analyze({square}, o);
  o.extent[0] = 2;
  const AnalysisReport b = analyze({twice}, o);
  EXPECT_NEAR(b.nn.dmin, a.nn.dmin, 1e-12);
  EXPECT_NEAR(b.nn.davg, a.nn.davg, 1e-12);
  EXPECT_NEAR(b.nn.nn1, a.nn.nn1, 1e-12);
  ASSERT_TRUE(a.has_empty_circles && b.has_empty_circles);
  EXPECT_EQ(b.empty_circles.triangles, 2 * a.empty_circles.triangles);  // 2n each: every hole found
  EXPECT_NEAR(b.empty_circles.largest, a.empty_circles.largest, 1e-9);
  EXPECT_NEAR(b.empty_circles.p999, a.empty_circles.p999, 1e-9);
  EXPECT_EQ(b.empty_circles.over_085, 2 * a.empty_circles.over_085);
  // g(r): twice the pairs, in shells of half the area, against 2n(2n − 1) ordered pairs instead of
  // n(n − 1): g scaled by 2(n − 1) / (2n − 1).
  ASSERT_EQ(a.gr.g.size(), b.gr.g.size());
  EXPECT_NEAR(b.gr.r_max, a.gr.r_max, 1e-12);
  const double pairs = (2.0 * 500 - 1) / (2.0 * 499);
  for (std::size_t k = 0; k < a.gr.g.size(); ++k) EXPECT_NEAR(b.gr.g[k] * pairs, a.gr.g[k], 1e-9) << k;
}

// A rectangle's torus is copied only where a circle through it may reach, as the square's: the same
// circles as copies in a widening margin, for a steep ramp (along either side), a cluster, uniform points
// and a few points, on a 2:1 and a 1:5 rectangle.
TEST(Domain, RectangleCopiesAroundTheHolesFindTheCirclesOfAWholeMargin) {
  std::vector<tools::PointSet> sets;
  tools::PointSet ramp = uniform_set(500, 4), across = uniform_set(500, 5);  // density ∝ e^(-20 x)
  for (std::size_t p = 0; p < ramp.size(); ++p) {
    ramp.coords[2 * p] = -std::log1p(-ramp.coords[2 * p] * (1 - std::exp(-20.0))) / 20;
    across.coords[2 * p + 1] = -std::log1p(-across.coords[2 * p + 1] * (1 - std::exp(-20.0))) / 20;
  }
  tools::PointSet cluster = uniform_set(400, 2);
  for (double& v : cluster.coords) v = 0.4 + 0.1 * v;
  sets.insert(sets.end(), {ramp, across, cluster, uniform_set(800, 6)});
  for (std::size_t n = 3; n <= 8; ++n) sets.push_back(uniform_set(n, 9));
  const std::array<double, 3> shapes[2] = {{2, 1, 1}, {1, 5, 1}};
  for (const std::array<double, 3>& shape : shapes) {
    const Sides sides = unit_measure_sides(shape.data(), 2);
    for (tools::PointSet s : sets) {
      for (std::size_t i = 0; i < s.coords.size(); i += 2)
        s.coords[i] *= sides[0], s.coords[i + 1] *= sides[1];
      std::vector<double> around =
          detail::torus_circumradii(s.coords, detail::TorusCopies::kAroundHoles, sides[0], sides[1]);
      std::vector<double> margin =
          detail::torus_circumradii(s.coords, detail::TorusCopies::kMargin, sides[0], sides[1]);
      EXPECT_EQ(around.size(), 2 * s.size()) << s.size() << " points, sides " << sides[0];
      std::sort(around.begin(), around.end());
      std::sort(margin.begin(), margin.end());
      EXPECT_EQ(around, margin) << s.size() << " points, sides " << sides[0];
    }
  }
}

// A box set on a rectangle: every judged circle is centred two spacings inside its sides, the long one
// included (judged on the unit square's, circles would reach past x = 1 in the rectangle's lengths).
TEST(Domain, BoxHolesOnARectangleStayInsideIt) {
  const tools::PointSet s = uniform_set(2000, 31);
  EmptyCircleOptions o;
  o.torus = false;
  const double wide[3] = {4, 1, 1};
  o.sides = unit_measure_sides(wide, 2);
  const EmptyCircles wide_holes = empty_circles({s}, o);
  o.sides = kUnitSides;
  const EmptyCircles square_holes = empty_circles({s}, o);
  // Uniform random points: the same set's holes in units of d_hex do not depend much on the shape
  // (largest about 2 for 2000 points), and both judge most of the 2n triangles inside the border.
  EXPECT_GT(wide_holes.triangles, 2000u);
  EXPECT_GT(square_holes.triangles, 2000u);
  EXPECT_GT(wide_holes.largest, 1.0);
  o.tile_size = 0.5;
  o.sides = unit_measure_sides(wide, 2);
  EXPECT_THROW(empty_circles({s}, o), InvalidInput);  // tile edges are the unit square's
}

// The rectangle's periodogram is S at integer (kx, ky) of the normalised coordinates, at frequency
// (kx/lx, ky/ly); its grid covers the disc |k| ≤ kmax in those frequencies and no more.
TEST(Domain, RectanglePeriodogramMatchesDirectSumOnItsLattice) {
  const tools::PointSet s = uniform_set(2000, 41);
  const double wide[3] = {2, 1, 1};
  const Sides sides = unit_measure_sides(wide, 2);
  const Periodogram p = periodogram(s.coords, 2, 2.5, 2, sides);
  EXPECT_GE(p.kx_max, p.kmax * sides[0] - 1e-9);
  EXPECT_GE(p.ky_max, p.kmax * sides[1] - 1e-9);
  EXPECT_LT(p.ky_max, p.kmax);
  for (const auto& k : std::vector<std::pair<int, int>>{
           {1, 0}, {0, -1}, {7, 3}, {-p.kx_max + 1, 0}, {0, p.ky_max - 1}, {30, -20}}) {
    double re = 0, im = 0;
    for (std::size_t j = 0; j < s.size(); ++j) {
      const double phase = -2 * kPi * (k.first * s.coords[2 * j] + k.second * s.coords[2 * j + 1]);
      re += std::cos(phase), im += std::sin(phase);
    }
    const double direct = (re * re + im * im) / double(s.size());
    EXPECT_NEAR(p.at(k.first, k.second), direct, 1e-8 * (1 + direct)) << k.first << "," << k.second;
  }
  int outside = 0;
  for (int ky = -p.ky_max; ky <= p.ky_max; ++ky)
    for (int kx = -p.kx_max; kx <= p.kx_max; ++kx) {
      const bool in_disc = std::hypot(kx / sides[0], ky / sides[1]) <= p.kmax;
      ASSERT_EQ(std::isnan(p.at(kx, ky)), !in_disc) << kx << "," << ky;
      outside += !in_disc;
    }
  EXPECT_GT(outside, 0);
  // Rings hold as many frequencies as the square's: the lattice has one per unit area of k either way.
  const SpectrumStats st = spectrum_stats(p);
  const SpectrumStats square = spectrum_stats(periodogram(s.coords, 2, 2.5, 2));
  for (std::size_t r = 10; r < st.ring_size.size(); r += 10)
    EXPECT_NEAR(double(st.ring_size[r]), double(square.ring_size[r]), 0.15 * double(square.ring_size[r]))
        << r;
}

TEST(Domain, TilingAndBadSidesAreRefused) {
  const tools::PointSet s = uniform_set(300, 51);
  AnalysisOptions o;
  o.extent[0] = 2;
  o.tile_size = 0.25;
  EXPECT_THROW(analyze({s}, o), InvalidInput);
  o.tile_size = 0;
  o.extent[1] = 0;
  EXPECT_THROW(analyze({s}, o), InvalidInput);
  o.extent[1] = std::nan("");
  EXPECT_THROW(analyze({s}, o), InvalidInput);
}

// The KDM sampler's sets of 4,096 points at its default temperature: drawn 2:1 and measured in their
// rectangle, they read as its square sets do; measured in the unit square, squeezed. Spread over seeds 1–8
// (kdm.sample, 2026-12-07; mean ± sd): δavg 0.8716 ± 0.0007 square, 0.8722 ± 0.0009 2:1 in its rectangle,
// 0.7310 ± 0.0043 squeezed; anisotropy 0.00 ± 0.06 dB, 0.01 ± 0.04 dB, +2.48 ± 0.08 dB; peak f 1.039 ±
// 0.017 and 1.039 ± 0.012. Tolerances: four sd of a difference of two sets (√2 · the larger sd).
TEST(Domain, ASamplerSetDrawnTwoToOneMeasuresAsItsSquareSets) {
  const auto draw = [](double aspect, std::uint64_t seed) {
    gen::SamplerOptions o;
    o.n = 4096;
    o.seed = seed;
    o.extent[0] = aspect;
    tools::PointSet s;
    s.coords = gen::sample(o).points;
    return s;
  };
  AnalysisOptions square_options;
  const AnalysisReport square = analyze({draw(1, 3)}, square_options);
  AnalysisOptions rectangle_options;
  rectangle_options.extent[0] = 2;
  const tools::PointSet wide = draw(2, 3);
  const AnalysisReport in_rectangle = analyze({wide}, rectangle_options);
  const AnalysisReport squeezed = analyze({wide}, square_options);
  EXPECT_NEAR(in_rectangle.nn.davg, square.nn.davg, 4 * std::sqrt(2.0) * 0.0009);
  EXPECT_NEAR(in_rectangle.spectrum_stats.anisotropy_db, square.spectrum_stats.anisotropy_db,
              4 * std::sqrt(2.0) * 0.06);
  EXPECT_LT(squeezed.nn.davg, square.nn.davg - 0.1);
  EXPECT_GT(squeezed.spectrum_stats.anisotropy_db, square.spectrum_stats.anisotropy_db + 1.5);
  // The rectangle's spectrum peaks where the square's does (f ≈ 1.1), not split by the squeeze.
  EXPECT_NEAR(in_rectangle.spectrum_stats.peak_f, square.spectrum_stats.peak_f, 4 * std::sqrt(2.0) * 0.017);
}

// 3D: a 2:1:0.5 box's set of 3,000 points measured in its box reads as a cube's set does. Over seeds 1–6
// (2026-12-07): δavg 0.8397 ± 0.0011 cube, 0.8388 ± 0.0009 box, 0.6392 ± 0.0038 squeezed into the cube.
TEST(Domain, ASamplerSetDrawnInABoxMeasuresAsItsCubeSets) {
  const auto draw = [](const double* extent, std::uint64_t seed) {
    gen::SamplerOptions o;
    o.dim = 3;
    o.n = 3000;
    o.seed = seed;
    std::copy(extent, extent + 3, o.extent);
    tools::PointSet s;
    s.dim = 3;
    s.coords = gen::sample(o).points;
    return s;
  };
  const double cube[3] = {1, 1, 1}, box[3] = {2, 1, 0.5};
  AnalysisOptions cube_options;
  AnalysisOptions box_options;
  std::copy(box, box + 3, box_options.extent);
  const AnalysisReport in_cube = analyze({draw(cube, 5)}, cube_options);
  const tools::PointSet boxed = draw(box, 5);
  const AnalysisReport in_box = analyze({boxed}, box_options);
  const AnalysisReport squeezed = analyze({boxed}, cube_options);
  EXPECT_NEAR(in_box.nn.davg, in_cube.nn.davg, 4 * std::sqrt(2.0) * 0.0011);
  EXPECT_LT(squeezed.nn.davg, in_cube.nn.davg - 0.1);
}

}  // namespace
}  // namespace kdm::analysis
