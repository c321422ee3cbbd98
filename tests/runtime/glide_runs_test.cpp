// glide_count.h's lattice and glide_runs.h's block loops: the same numbers as the rule they compute.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "glide_runs.h"

namespace kdm::detail {
namespace {

bool same_bits(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

TEST(GlideRunsTest, LatticeFloorIsStdFloorBitForBit) {
  // Values where a floor goes wrong: zeros, halves, around 2^52 and 2^53, the largest and smallest
  // doubles, infinities, and random values over every magnitude and both signs.
  std::vector<double> values = {0.0,
                                -0.0,
                                0.5,
                                -0.5,
                                1.0,
                                -1.0,
                                2.5,
                                -2.5,
                                1e-310,
                                -1e-310,
                                0x1p52,
                                -0x1p52,
                                0x1p52 - 0.5,
                                -(0x1p52 - 0.5),
                                0x1p52 + 1,
                                -(0x1p52 + 1),
                                0x1p53 + 2,
                                -(0x1p53 + 2),
                                1e300,
                                -1e300,
                                std::numeric_limits<double>::max(),
                                std::numeric_limits<double>::lowest(),
                                std::numeric_limits<double>::infinity(),
                                -std::numeric_limits<double>::infinity()};
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> exponent(-60, 70), unit(0, 1);
  for (int i = 0; i < 100000; ++i) {
    const double v = std::ldexp(unit(random), int(exponent(random)));
    values.push_back(i % 2 ? v : -v);
    values.push_back(std::nextafter(std::round(v), 0.0));  // just below and above whole numbers
    values.push_back(std::nextafter(std::round(v), HUGE_VAL));
  }
  // Bit for bit but for the sign of a zero (−0 gives +0, as the integer conversion it replaced did).
  for (double v : values)
    if (v == 0)
      EXPECT_EQ(GlideLattice::floor(v), 0.0) << v;
    else
      EXPECT_TRUE(same_bits(GlideLattice::floor(v), std::floor(v))) << v << ": " << GlideLattice::floor(v);
  EXPECT_TRUE(std::isnan(GlideLattice::floor(std::numeric_limits<double>::quiet_NaN())));
}

TEST(GlideRunsTest, BlockLoopsGiveGlideCountsBitForBit) {
  // A density that differs at every corner; points at counts over several lattice sizes, in tiles near
  // and far from the origin, in blocks of every length up to kGlideBlock.
  auto density = [](double x, double y) { return 0.5 + 0.45 * std::sin(37 * x) * std::cos(23 * y); };
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> unit(0, 1);
  int lifted = 0;
  for (std::size_t count = 1; count <= kGlideBlock; ++count)
    for (double side : {1.0, 0.37, 2.5e-4}) {
      for (double origin : {0.0, -3.0, 1e6}) {
        double expected[kGlideBlock], x[kGlideBlock], y[kGlideBlock], coarse[kGlideBlock], out[kGlideBlock];
        double cx[GlideLattice::kCorners * kGlideBlock], cy[GlideLattice::kCorners * kGlideBlock];
        double value[GlideLattice::kCorners * kGlideBlock];
        for (std::size_t k = 0; k < count; ++k) {
          expected[k] = std::exp(std::log(0.3) + unit(random) * std::log(40000 / 0.3));
          x[k] = origin + unit(random) * side, y[k] = origin - unit(random) * side;
        }
        const double area = 1000 * side * side;
        glide_corners_run(expected, x, y, count, side, cx, cy, coarse);
        for (std::size_t r = 0; r < GlideLattice::kCorners * count; ++r) value[r] = density(cx[r], cy[r]);
        glide_counts_run(expected, coarse, value, count, area, out);
        for (std::size_t k = 0; k < count; ++k) {
          const double one = glide_count(expected[k], x[k], y[k], side, area, density);
          ASSERT_TRUE(same_bits(out[k], one))
              << out[k] << " against " << one << ", count " << count << " side " << side << " point " << k;
          lifted += one > expected[k];
        }
      }
    }
  EXPECT_GT(lifted, 100);  // the corners did lift counts, so the reads were compared
}

}  // namespace
}  // namespace kdm::detail
