// Classes of images on one grid by the images of their running sums (ClassImageSums): the union is the
// one-class query at the last sum's image, in stable mode classes 0 … k together exactly the one-class query
// at sum k, smooth mode's classes stable mode's; parts of a region, the compact output and ParallelQuery
// give the same points and classes; the classes follow those of the images given one by one; refusals by
// name; no allocation in queries.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <random>
#include <tuple>
#include <vector>

#include "class_points.h"
#include "kdm/runtime/class_image_sums.h"
#include "kdm/runtime/class_query.h"
#include "kdm/runtime/parallel_query.h"
#include "random_partition.h"

namespace kdm {
namespace {

/// ThreeImages by their running sums.
struct SummedImages : testing::ThreeImages {
  const DensityImageView* pointers[3] = {&views[0], &views[1], &views[2]};
  ClassImageSums sums;
  SummedImages() { EXPECT_EQ(sums.build(pointers, 3), Status::kOk); }
  ClassQueryParams query(double x0, double y0, double x1, double y1, double scale, QueryMode mode) const {
    ClassQueryParams q;
    q.query.x0 = x0, q.query.y0 = y0, q.query.x1 = x1, q.query.y1 = y1;
    q.query.scale = scale, q.query.mode = mode;
    q.class_count = 3;
    q.image_sums = &sums;
    return q;
  }
  /// `q` with the images given one by one instead of their sums.
  ClassQueryParams one_by_one(const ClassQueryParams& q) const {
    ClassQueryParams images = q;
    images.image_sums = nullptr;
    for (int k = 0; k < 3; ++k)
      images.classes[k].kind = QueryDensity::Kind::kImage, images.classes[k].image = &views[k];
    return images;
  }
};

/// The one-class query at sum k's image over q's region.
QueryParams at_sum(const ClassQueryParams& q, std::uint32_t k) {
  QueryParams one = q.query;
  one.density.kind = QueryDensity::Kind::kImage;
  one.density.image = &q.image_sums->sum(k);
  return one;
}

TEST(ClassImageSumsTest, SumsAreTheImagesAddedTexelByTexel) {
  SummedImages im;
  ASSERT_EQ(im.sums.count(), 3u);
  for (std::size_t i = 0; i < 32 * 32; ++i) {
    float sum = 0;
    for (int k = 0; k < 3; ++k) {
      sum += im.values[k][i];
      ASSERT_EQ(im.sums.sum(k).values[i], sum) << i;
    }
  }
  ClassImageSums moved = std::move(im.sums);  // it owns its texels: a move keeps the views valid
  EXPECT_NEAR(moved.sum(2).at(1.3, 2.2),
              im.views[0].at(1.3, 2.2) + im.views[1].at(1.3, 2.2) + im.views[2].at(1.3, 2.2), 1e-5);
  EXPECT_GT(moved.sum(2).max_over(0, 0, 4, 4), moved.sum(1).max_over(0, 0, 4, 4));
}

TEST(ClassImageSumsTest, StableClassesAreTheOneClassQueriesAtTheSums) {
  SummedImages im;
  const ClassQueryParams q = im.query(-0.4, 0.3, 4.3, 4.6, 900, QueryMode::kStable);
  const testing::Points all = testing::run_classes(q, 1000);
  for (std::uint32_t k = 0; k < 3; ++k) {
    const testing::Points upto = testing::up_to_class(all, int(k));
    const QueryParams one = at_sum(q, k);
    testing::expect_same(upto, testing::run_one(one), "classes 0 … k against the one-class query at sum k");
    EXPECT_GT(upto.size(), 3000u * (k + 1));
  }
}

TEST(ClassImageSumsTest, SmoothUnionIsTheSmoothQueryAtTheLastSumWithStableModesClasses) {
  SummedImages im;
  // At the top level and past it (the sum's peak, about 3.2, at 20,000 per unit area passes the top
  // level's 32,768 points per tile).
  for (double scale : {900.0, 20000.0}) {
    const double side = scale > 1000 ? 0.6 : 3.7;
    const ClassQueryParams smooth = im.query(1.7, 1.6, 1.7 + side, 1.6 + side, scale, QueryMode::kSmooth);
    const testing::Points all = testing::run_classes(smooth, 777);
    const QueryParams one = at_sum(smooth, 2);
    testing::expect_same(all, testing::run_one(one), "the smooth union");
    std::size_t deep = 0;
    for (const auto& [id, e] : all) deep += std::get<3>(id) > 0;
    if (scale > 1000) {
      EXPECT_GT(deep, all.size() / 10);
      continue;
    }  // past the top level a point is classed by its subtile's threshold
    ClassQueryParams stable = smooth;
    stable.query.mode = QueryMode::kStable;
    const testing::Points fixed = testing::run_classes(stable);
    std::size_t both = 0;
    for (const auto& [id, e] : all) {
      const auto it = fixed.find(id);
      if (it == fixed.end()) continue;
      ASSERT_EQ(e.cls, it->second.cls);
      ++both;
    }
    EXPECT_GT(both, all.size() * 9 / 10);
  }
}

TEST(ClassImageSumsTest, ClassesFollowTheImagesGivenOneByOne) {
  // The sums are added in float and read once where the images are read one by one and added in double:
  // the same points and classes but for a threshold within rounding of a density (none here; a few in
  // 10^7 would be).
  SummedImages im;
  for (QueryMode mode : {QueryMode::kStable, QueryMode::kSmooth}) {
    const ClassQueryParams sums = im.query(-0.4, 0.3, 4.3, 4.6, 900, mode);
    const testing::Points a = testing::run_classes(sums), b = testing::run_classes(im.one_by_one(sums));
    ASSERT_EQ(a.size(), b.size());
    std::size_t differ = 0;
    for (auto i = a.begin(), j = b.begin(); i != a.end(); ++i, ++j) {
      ASSERT_TRUE(i->first == j->first);
      differ += i->second.cls != j->second.cls;
    }
    EXPECT_EQ(differ, 0u) << "mode " << int(mode);
  }
}

// In smooth mode a point glides by its density, which the sums give in float where images given one by one
// are summed in double: the same ids, at positions that differ in their last bits. Most just above the
// first keyframes (10 to 200 expected points per tile), where a spacing's glide spans a small range of
// counts. Over 11.4 million points (random images and ThreeImages, tile sides 0.25, 1 and 4, 4 to 4 · 10^5
// points per tile, with and without glide_together) the largest difference was 1.4 · 10^-7 of a tile side,
// and in this sample of that sweep 1.5 · 10^-7; the headers state under 3 · 10^-7, which it checks.
TEST(ClassImageSumsTest, SmoothPositionsDifferFromTheImagesGivenOneByOneInTheirLastBits) {
  SummedImages im;
  double largest = 0;
  std::size_t points = 0;
  for (double tile : {0.25, 1.0, 4.0})
    for (double per_tile : {10.0, 20.0, 30.0, 50.0, 100.0, 300.0})
      for (bool together : {false, true}) {
        const double scale = per_tile / (tile * tile), side = std::min(3.8, std::sqrt(20000 / (3 * scale)));
        ClassQueryParams sums = im.query(0.1, 0.1, 0.1 + side, 0.1 + side, scale, QueryMode::kSmooth);
        sums.query.tile_size = tile, sums.query.glide_together = together;
        const testing::Points a = testing::run_classes(sums), b = testing::run_classes(im.one_by_one(sums));
        ASSERT_EQ(a.size(), b.size());
        for (auto i = a.begin(), j = b.begin(); i != a.end(); ++i, ++j) {
          ASSERT_TRUE(i->first == j->first);
          largest = std::max({largest, std::fabs(i->second.x - j->second.x) / tile,
                              std::fabs(i->second.y - j->second.y) / tile});
        }
        points += a.size();
      }
  EXPECT_GT(points, 100000u);
  EXPECT_GT(largest, 1e-9);  // they do differ: the bound is not vacuous
  EXPECT_LT(largest, 3e-7) << "in tile sides, over " << points << " points";
  std::printf("largest difference %.3g of a tile side over %zu points\n", largest, points);
}

TEST(ClassImageSumsTest, PartsCompactOutputAndThreadsGiveTheSamePointsAndClasses) {
  SummedImages im;
  std::mt19937 rng(5);
  for (QueryMode mode : {QueryMode::kStable, QueryMode::kSmooth}) {
    const ClassQueryParams whole = im.query(-0.4, 0.3, 4.3, 4.6, 900, mode);
    testing::expect_parts_give_the_whole(whole, rng);
    const testing::Points all = testing::run_classes(whole);

    // The records in order, then the compact output and two workers over the same buffer size.
    std::vector<QueryPoint> out(all.size() + 1);
    std::vector<std::uint8_t> cls(out.size()), cls2(out.size());
    std::size_t written = 0, written2 = 0;
    QueryCursor cursor;
    ASSERT_EQ(query_classes(Tileset::builtin(), whole, out.data(), cls.data(), out.size(), &written, &cursor),
              Status::kOk);
    std::vector<float> xy(2 * out.size());
    std::vector<std::uint64_t> keys(out.size());
    cursor = QueryCursor{};
    ASSERT_EQ(query_classes_compact(Tileset::builtin(), whole, CompactPoints{xy.data(), keys.data()},
                                    cls2.data(), out.size(), &written2, &cursor),
              Status::kOk);
    ASSERT_EQ(written2, written);
    for (std::size_t i = 0; i < written; ++i) {
      ASSERT_EQ(keys[i], point_key(out[i].id)) << i;
      ASSERT_EQ(cls2[i], cls[i]) << i;
    }
    ParallelQuery pq;
    ASSERT_EQ(pq.init(2), Status::kOk);
    std::vector<QueryPoint> par(out.size());
    std::vector<std::uint8_t> par_cls(out.size());
    ASSERT_EQ(pq.run(Tileset::builtin(), whole, par.data(), par_cls.data(), par.size(), &written2,
                     std_thread_runner()),
              Status::kOk);
    ASSERT_EQ(written2, written);
    std::map<testing::Id, int> by_id;
    for (std::size_t i = 0; i < written; ++i) by_id[testing::id_of(par[i])] = par_cls[i];
    for (std::size_t i = 0; i < written; ++i) ASSERT_EQ(by_id.at(testing::id_of(out[i])), cls[i]) << i;
  }
}

TEST(ClassImageSumsTest, BadInputIsRefusedByName) {
  SummedImages im;
  ClassImageSums sums;
  const char* why = nullptr;
  EXPECT_EQ(sums.build(im.pointers, 0, &why), Status::kInvalidArgument);
  EXPECT_STREQ(why, "the class count is not 1 ... 8");
  EXPECT_EQ(sums.build(im.pointers, 9, &why), Status::kInvalidArgument);
  EXPECT_EQ(sums.build(nullptr, 2, &why), Status::kInvalidArgument);
  DensityImageView other = im.views[1];
  other.x1 = 5;  // another grid
  const DensityImageView* mixed[2] = {&im.views[0], &other};
  EXPECT_EQ(sums.build(mixed, 2, &why), Status::kInvalidArgument);
  EXPECT_STREQ(why, "an image is not on the first image's grid (size and world rectangle)");
  std::vector<float> bad = im.values[1];
  bad[17] = std::numeric_limits<float>::quiet_NaN();
  other = im.views[1], other.values = bad.data();
  EXPECT_EQ(sums.build(mixed, 2, &why), Status::kInvalidArgument);
  EXPECT_STREQ(why, "an image has a negative or non-finite value");
  bad[17] = -1;
  EXPECT_EQ(sums.build(mixed, 2, &why), Status::kInvalidArgument);
  bad[17] = 3e38f;
  std::vector<float> big(bad.size(), 3e38f);
  other.values = big.data();
  const DensityImageView* twice[3] = {&other, &other, &other};
  EXPECT_EQ(sums.build(twice, 3, &why), Status::kInvalidArgument);
  EXPECT_STREQ(why, "the images' sum overflows a float");
  EXPECT_EQ(sums.count(), 0u);  // a refused build leaves it empty

  // Queries: sums for another class count, or beside a joint density.
  ClassQueryParams q = im.query(0, 0, 4, 4, 100, QueryMode::kStable);
  std::vector<QueryPoint> out(16);
  std::uint8_t cls[16];
  std::size_t written = 0;
  QueryProblem problem;
  q.class_count = 2;
  EXPECT_EQ(query_classes(Tileset::builtin(), q, out.data(), cls, 16, &written, nullptr, &problem),
            Status::kInvalidArgument);
  EXPECT_STREQ(problem.parameter, "image_sums");
  EXPECT_EQ(problem.value, 2);  // the classes asked, and those the sums were built for
  EXPECT_EQ(problem.limit, 3);
  char line[200];
  describe_query_problem(problem, line, sizeof line);
  EXPECT_STREQ(line, "'image_sums' holds the sums of 3 classes, the query has 2");
  q.class_count = 3;
  q.joint.densities = [](void*, double, double, double* v) { v[0] = v[1] = v[2] = 1; };
  EXPECT_EQ(query_classes(Tileset::builtin(), q, out.data(), cls, 16, &written, nullptr, &problem),
            Status::kInvalidArgument);
  EXPECT_STREQ(problem.parameter, "image_sums");
  q.joint.densities = nullptr;
  const ClassImageSums empty;
  q.image_sums = &empty;
  EXPECT_EQ(query_classes(Tileset::builtin(), q, out.data(), cls, 16, &written, nullptr, &problem),
            Status::kInvalidArgument);
  EXPECT_STREQ(problem.parameter, "image_sums");
}

// A move leaves the source empty: its views had gone on pointing into the texels it gave away, and a query
// given it read freed memory.
TEST(ClassImageSumsTest, AMoveLeavesTheSourceEmpty) {
  SummedImages im;
  ClassImageSums a;
  ASSERT_EQ(a.build(im.pointers, 3), Status::kOk);
  const float first = a.sum(2).values[5];
  ClassImageSums b = std::move(a);
  EXPECT_EQ(a.count(), 0u);  // NOLINT(bugprone-use-after-move): the state a move leaves is the point
  EXPECT_EQ(b.count(), 3u);
  EXPECT_EQ(b.sum(2).values[5], first);
  ClassImageSums c;
  c = std::move(b);
  EXPECT_EQ(b.count(), 0u);  // NOLINT(bugprone-use-after-move)
  EXPECT_EQ(c.sum(2).values[5], first);
  ClassQueryParams q = im.query(0, 0, 4, 4, 100, QueryMode::kStable);
  q.image_sums = &b;
  std::vector<QueryPoint> out(16);
  std::uint8_t cls[16];
  std::size_t written = 0;
  QueryProblem problem;
  EXPECT_EQ(query_classes(Tileset::builtin(), q, out.data(), cls, 16, &written, nullptr, &problem),
            Status::kInvalidArgument);
  EXPECT_STREQ(problem.parameter, "image_sums");
}

TEST(ClassImageSumsTest, QueriesAllocateNothing) {
  SummedImages im;
  testing::expect_class_queries_allocate_nothing(im.query(0, 0, 4, 4, 500, QueryMode::kStable));
}

}  // namespace
}  // namespace kdm
