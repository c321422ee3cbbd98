// Density bounds: an image's min- and max-mip and a callback's optional bounds let a query skip reading the
// density where a point's emission is not in doubt; the points stay those of reading it everywhere, bit
// for bit, in both modes, and the callback is called far less.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <vector>

#include "kdm/runtime/query.h"
#include "run_query.h"

namespace kdm {
namespace {

using testing::same_bits;

std::vector<QueryPoint> run(const QueryParams& q) {
  return testing::run_query(q);
}

// A ramp in x, 0.1 at x = -2 to 0.9 at x = 6, with a zero strip below x = -1.5 (where smooth mode's check
// at the glided position matters), counting its calls.
struct Ramp {
  std::atomic<long> calls{0};
  static double at(double x) { return x < -1.5 ? 0.0 : 0.1 + 0.1 * (x + 2); }
  static double density(void* self, double x, double) {
    static_cast<Ramp*>(self)->calls.fetch_add(1, std::memory_order_relaxed);
    return at(x);
  }
  static void bounds(void*, double x0, double, double x1, double, double* lo, double* hi) {
    *lo = x0 < -1.5 ? 0.0 : at(x0), *hi = at(std::max(x1, -1.5));
  }
  static void no_bounds(void*, double, double, double, double, double* lo, double* hi) {
    *lo = *hi = std::numeric_limits<double>::quiet_NaN();
  }
};

QueryParams ramp_query(Ramp& ramp, QueryMode mode) {
  QueryParams q;
  q.x0 = -2, q.y0 = -0.7, q.x1 = 6, q.y1 = 3.3;
  q.scale = 3000, q.mode = mode;
  q.density.kind = QueryDensity::Kind::kCallback;
  q.density.callback = Ramp::density, q.density.user = &ramp, q.density.callback_max = 0.9;
  return q;
}

TEST(DensityBoundsTest, ACallbacksBoundsKeepItsPointsAndSaveItsCalls) {
  for (QueryMode mode : {QueryMode::kStable, QueryMode::kSmooth}) {
    Ramp ramp;
    QueryParams q = ramp_query(ramp, mode);
    const std::vector<QueryPoint> read_everywhere = run(q);
    const long calls_everywhere = ramp.calls.exchange(0);
    ASSERT_GT(read_everywhere.size(), 20000u);
    q.density.bounds = Ramp::bounds;
    EXPECT_TRUE(same_bits(run(q), read_everywhere)) << "mode " << int(mode);
    const long calls_bounded = ramp.calls.exchange(0);
    std::printf("mode %d: %ld of %ld calls\n", int(mode), calls_bounded, calls_everywhere);
    // Stable mode reads the density only between the bounds of the quarter-by-quarter cell of its tile a
    // point lies in (a tenth of the ramp per tile here: 0.125 of the calls with the tile's bounds alone,
    // measured 0.037 with its cells'); smooth mode below its upper bound, once per point (measured 0.433).
    EXPECT_LT(calls_bounded, (mode == QueryMode::kStable ? 0.06 : 0.65) * calls_everywhere)
        << "mode " << int(mode);
    q.density.bounds = Ramp::no_bounds;  // NaN bounds are no bounds
    EXPECT_TRUE(same_bits(run(q), read_everywhere)) << "mode " << int(mode);
    EXPECT_EQ(ramp.calls.exchange(0), calls_everywhere);
  }
}

TEST(DensityBoundsTest, PastTheTopLevelBoundsKeepThePoints) {
  // Smooth mode descends into subtiles past the top level (32,768 points per tile), where the bounds of a
  // subtile decide which of its points are visited: about 3 times the top here.
  Ramp ramp;
  QueryParams q = ramp_query(ramp, QueryMode::kSmooth);
  q.x0 = 0.1, q.y0 = 0.2, q.x1 = 0.4, q.y1 = 0.45, q.scale = 3 * 32768 / 0.3;
  const std::vector<QueryPoint> read_everywhere = run(q);
  std::size_t deep = 0;
  for (const QueryPoint& p : read_everywhere) deep += p.id.depth > 0;
  ASSERT_GT(deep, 1000u);
  q.density.bounds = Ramp::bounds;
  EXPECT_TRUE(same_bits(run(q), read_everywhere));
}

TEST(DensityBoundsTest, AnImagesPointsAreThoseOfReadingItEverywhere) {
  // The image query (bounded by its mips) against a callback reading the same image with no bounds.
  std::vector<float> values(40 * 30), mip;
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 40; ++x) values[y * 40 + x] = float(x < 4 ? 0.0 : 0.05 + 0.9 * (x * y % 17) / 16.0);
  DensityImageView image;
  image.width = 40, image.height = 30;
  image.x0 = -2, image.y0 = -1, image.x1 = 6, image.y1 = 4;
  image.values = values.data();
  ASSERT_EQ(make_density_max_mip(image, mip), Status::kOk);
  for (QueryMode mode : {QueryMode::kStable, QueryMode::kSmooth}) {
    QueryParams q;
    q.x0 = -2, q.y0 = -1, q.x1 = 6, q.y1 = 4;
    q.scale = 3000, q.mode = mode;
    q.density.kind = QueryDensity::Kind::kImage, q.density.image = &image;
    const std::vector<QueryPoint> bounded = run(q);
    q.density = QueryDensity{};
    q.density.kind = QueryDensity::Kind::kCallback, q.density.callback_max = 0.95;
    q.density.user = &image;
    q.density.callback = [](void* im, double x, double y) {
      return static_cast<DensityImageView*>(im)->at(x, y);
    };
    const std::vector<QueryPoint> everywhere = run(q);
    ASSERT_GT(everywhere.size(), 20000u);
    EXPECT_TRUE(same_bits(bounded, everywhere)) << "mode " << int(mode);
  }
}

}  // namespace
}  // namespace kdm
