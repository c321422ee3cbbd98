// Density bounds: an image's min- and max-mip and a callback's optional bounds let a query skip reading the
// density where a point's emission is not in doubt; the points stay those of reading it everywhere, bit
// for bit, in both modes, and the callback is called far less.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
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
  static void crossed_bounds(void*, double, double, double, double, double* lo, double* hi) {
    *lo = 5, *hi = 0;  // a bug in the caller's bounds, not a density of 0
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
    // NaN bounds, and bounds that contradict themselves, are no bounds.
    for (auto* none : {Ramp::no_bounds, Ramp::crossed_bounds}) {
      q.density.bounds = none;
      EXPECT_TRUE(same_bits(run(q), read_everywhere)) << "mode " << int(mode);
      EXPECT_EQ(ramp.calls.exchange(0), calls_everywhere);
    }
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

// The ramp as a batch callback, counting its calls and the positions it is asked for.
struct BatchRamp {
  std::atomic<long> calls{0}, values{0}, largest{0}, singles{0};
  static void density(void* self, std::size_t n, const double* x, const double*, double* out) {
    BatchRamp& r = *static_cast<BatchRamp*>(self);
    r.calls.fetch_add(1, std::memory_order_relaxed), r.values.fetch_add(long(n), std::memory_order_relaxed);
    if (n == 1) r.singles.fetch_add(1);
    if (long(n) > r.largest.load()) r.largest.store(long(n));
    for (std::size_t i = 0; i < n; ++i) out[i] = Ramp::at(x[i]);
  }
};

TEST(DensityBoundsTest, ABatchCallbackGivesTheCallbacksPoints) {
  for (QueryMode mode : {QueryMode::kStable, QueryMode::kSmooth}) {
    for (bool bounded : {false, true}) {
      Ramp ramp;
      BatchRamp batch;
      QueryParams q = ramp_query(ramp, mode);  // its region cuts tiles along y
      if (bounded) q.density.bounds = Ramp::bounds;
      const std::vector<QueryPoint> one_by_one = testing::run_query(q, 1 << 20);  // one call
      ASSERT_GT(one_by_one.size(), 20000u);
      q.density.callback = nullptr, q.density.batch_callback = BatchRamp::density, q.density.user = &batch;
      const std::string where = "mode " + std::to_string(int(mode)) + (bounded ? ", bounds" : "");
      // Through a buffer of 7 points: every cursor stop lands inside a gathered batch.
      EXPECT_TRUE(same_bits(testing::run_query(q, 7), one_by_one)) << where;
      batch.calls = batch.values = 0;
      EXPECT_TRUE(same_bits(testing::run_query(q, 1 << 20), one_by_one)) << where;  // one call
      EXPECT_LE(batch.largest.load(), long(kDensityBatch)) << where;
      // Stable mode reads the positions the scalar callback is asked for, no more (a call that fills the
      // buffer also reads the rest of its batch); smooth mode also reads the glided positions of emitted
      // points just outside the region (measured 2.6% and 0.5% more). A call serves a batch of a tile's
      // reads: measured 123 to 31 values a call on average (the cells' bounds leave stable mode a few dozen
      // reads a tile), against one value a call for the scalar callback.
      if (mode == QueryMode::kStable) {
        EXPECT_EQ(batch.values.load(), ramp.calls.load()) << where;
      }
      EXPECT_LE(batch.values.load(), long(1.05 * ramp.calls.load())) << where;
      EXPECT_GT(batch.values.load(), 25 * batch.calls.load()) << where;
      // Chunks a tenth of a tile wide are visited through their cells' lists, a batch per tile and chunk.
      std::vector<QueryPoint> chunks;
      QueryParams part = q;
      for (int k = 0; k < 80; ++k) {
        part.x0 = q.x0 + k * 0.1, part.x1 = k == 79 ? q.x1 : q.x0 + (k + 1) * 0.1;
        const std::vector<QueryPoint> points = run(part);
        chunks.insert(chunks.end(), points.begin(), points.end());
      }
      QueryParams whole = ramp_query(ramp, mode);
      if (bounded) whole.density.bounds = Ramp::bounds;
      std::vector<QueryPoint> scalar_chunks;
      for (int k = 0; k < 80; ++k) {
        whole.x0 = q.x0 + k * 0.1, whole.x1 = k == 79 ? q.x1 : q.x0 + (k + 1) * 0.1;
        const std::vector<QueryPoint> points = run(whole);
        scalar_chunks.insert(scalar_chunks.end(), points.begin(), points.end());
      }
      EXPECT_EQ(chunks.size(), one_by_one.size()) << where;
      EXPECT_TRUE(same_bits(chunks, scalar_chunks)) << where;
    }
  }
}

TEST(DensityBoundsTest, ABatchCallbackServesPastTheTopLevel) {
  Ramp ramp;
  BatchRamp batch;
  QueryParams q = ramp_query(ramp, QueryMode::kSmooth);
  q.x0 = 0.1, q.y0 = 0.2, q.x1 = 0.4, q.y1 = 0.45, q.scale = 3 * 32768 / 0.3;
  for (bool bounded : {false, true}) {
    if (bounded) q.density.bounds = Ramp::bounds;
    q.density.callback = Ramp::density, q.density.batch_callback = nullptr, q.density.user = &ramp;
    ramp.calls = 0;
    const std::vector<QueryPoint> one_by_one = testing::run_query(q, 1 << 20);
    const long scalar_calls = ramp.calls.exchange(0);
    std::size_t deep = 0;
    for (const QueryPoint& p : one_by_one) deep += p.id.depth > 0;
    ASSERT_GT(deep, 1000u);
    q.density.callback = nullptr, q.density.batch_callback = BatchRamp::density, q.density.user = &batch;
    batch.calls = batch.values = batch.singles = 0;
    EXPECT_TRUE(same_bits(testing::run_query(q, 1 << 20), one_by_one)) << bounded;
    // The subtiles' own points are read a batch at a time, their ancestors' points, hand-overs and
    // appearing points a block of ranks at a time (read ahead): measured 63 and 40 values a call of more
    // than one, without and with bounds, and 11 and 6 calls of one value (of 46,886 and 19,802 values),
    // where every value not read in a batch was a call of its own.
    const long batched_values = batch.values - batch.singles, batched_calls = batch.calls - batch.singles;
    std::printf("bounds %d: %ld values in %ld calls of more than one, %ld of one; %ld scalar calls\n",
                int(bounded), batched_values, batched_calls, batch.singles.load(), scalar_calls);
    EXPECT_GT(batched_values, 20 * batched_calls) << bounded;
    EXPECT_LT(100 * batch.singles.load(), batch.values.load()) << bounded;
    // Reading ahead asks for few positions the scalar query does not: only the items past where a full
    // table cut a block short are read again with the next block (measured: as many values as the scalar
    // calls, and 10 more of 47,238 on another baking of the built-in set; the bar allows 0.5%).
    EXPECT_LE(batch.values.load(), scalar_calls + scalar_calls / 200) << bounded;
    EXPECT_TRUE(same_bits(testing::run_query(q, 7), one_by_one)) << bounded;
  }
}

// A density that varies over a few hundred spacings at four million times the top level, read one value or
// many a call.
struct Wave {
  static double at(double x, double y) { return 0.5 + 0.4 * std::sin(3000 * x) * std::cos(2000 * y); }
  static double density(void*, double x, double y) { return at(x, y); }
  static void batch(void*, std::size_t n, const double* x, const double* y, double* out) {
    for (std::size_t i = 0; i < n; ++i) out[i] = at(x[i], y[i]);
  }
};

TEST(DensityBoundsTest, ABatchCallbackServesDeepFarFromTheOrigin) {
  // Four million times the top level (depth 3 of subtiles 32 times smaller a side), 10^6 units out.
  QueryParams q;
  q.x0 = 1e6 + 0.1, q.y0 = -1e6 + 0.2, q.x1 = q.x0 + 2e-4, q.y1 = q.y0 + 1.5e-4;
  q.origin_x = 1e6, q.origin_y = -1e6;
  q.scale = 4e6 * 32768, q.mode = QueryMode::kSmooth;
  q.density.kind = QueryDensity::Kind::kCallback, q.density.callback_max = 0.9;
  q.density.callback = Wave::density;
  const std::vector<QueryPoint> one_by_one = testing::run_query(q, 1 << 16);
  std::uint32_t deepest = 0;
  for (const QueryPoint& p : one_by_one) deepest = std::max(deepest, p.id.depth);
  ASSERT_GT(one_by_one.size(), 1000u);
  ASSERT_GE(deepest, 3u);
  q.density.callback = nullptr, q.density.batch_callback = Wave::batch;
  EXPECT_TRUE(same_bits(testing::run_query(q, 1 << 16), one_by_one));
  EXPECT_TRUE(same_bits(testing::run_query(q, 5), one_by_one));
}

TEST(DensityBoundsTest, ACallbackDensityNeedsExactlyOneOfItsFunctions) {
  Ramp ramp;
  QueryParams q = ramp_query(ramp, QueryMode::kStable);
  q.density.batch_callback = BatchRamp::density;
  const QueryProblem both = testing::refusal(q);
  EXPECT_EQ(both.kind, QueryProblem::Kind::kBadDensity);
  EXPECT_STREQ(both.parameter, "density.batch_callback");
  q.density.callback = nullptr, q.density.batch_callback = nullptr;
  EXPECT_STREQ(testing::refusal(q).parameter, "density.callback");
}

TEST(DensityBoundsTest, AnImagesMipsHoldEachBlocksExtremesWidenedByATexel) {
  // Every size up to a few blocks, odd ones included: each block's maximum and minimum over its 8 × 8
  // texels and the ring of one texel around them (clamped to the image), and bilinear values between
  // them anywhere in the block.
  std::mt19937 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    const int w = 1 + int(rng() % 40), h = 1 + int(rng() % 40);
    std::vector<float> values(std::size_t(w) * h), mip;
    for (float& v : values) v = std::uniform_real_distribution<float>(0, 5)(rng);
    DensityImageView image;
    image.width = w, image.height = h, image.x1 = w, image.y1 = h, image.values = values.data();
    ASSERT_EQ(make_density_max_mip(image, mip), Status::kOk);
    ASSERT_EQ(image.mip_width, (w + 7) / 8);
    ASSERT_EQ(image.mip_height, (h + 7) / 8);
    for (int by = 0; by < image.mip_height; ++by)
      for (int bx = 0; bx < image.mip_width; ++bx) {
        float hi = 0, lo = std::numeric_limits<float>::infinity();
        for (int y = std::max(0, 8 * by - 1); y < std::min(h, 8 * by + 9); ++y)
          for (int x = std::max(0, 8 * bx - 1); x < std::min(w, 8 * bx + 9); ++x)
            hi = std::max(hi, values[std::size_t(y) * w + x]),
            lo = std::min(lo, values[std::size_t(y) * w + x]);
        ASSERT_EQ(image.max_mip[by * image.mip_width + bx], hi) << w << " x " << h;
        ASSERT_EQ(image.min_mip[by * image.mip_width + bx], lo) << w << " x " << h;
        const double x = std::min(8 * bx + 8.0, double(w)) - 0.3, y = 8 * by + 0.2;  // inside the block
        EXPECT_LE(image.at(x, y), image.max_over(x, y, x, y));
        EXPECT_GE(image.at(x, y), image.min_over(x, y, x, y));
      }
  }
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
  // Smooth mode also gliding together (glide_count.h), whose corners an image reads a block at a time.
  for (int variant = 0; variant < 3; ++variant) {
    const QueryMode mode = variant == 0 ? QueryMode::kStable : QueryMode::kSmooth;
    QueryParams q;
    q.x0 = -2, q.y0 = -1, q.x1 = 6, q.y1 = 4;
    q.scale = 3000, q.mode = mode, q.glide_together = variant == 2;
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
    EXPECT_TRUE(same_bits(bounded, everywhere)) << "variant " << variant;
  }
}

}  // namespace
}  // namespace kdm
