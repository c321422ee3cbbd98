// emission_threshold: the expected count per tile above which a point is emitted, as callers use it to
// fade objects in. It must be the query's own rule: a stable query at a constant density emits exactly
// the points whose thresholds lie below its count, at depth 0 and past the top level.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <set>
#include <tuple>
#include <vector>

#include "kdm/runtime/query.h"
#include "run_query.h"

namespace kdm {
namespace {

using Key = std::tuple<std::int64_t, std::int64_t, std::uint32_t, std::uint32_t>;
Key key(const PointId& id) {
  return {id.tile_x, id.tile_y, id.rank, id.depth};
}

QueryParams uniform(double per_tile, QueryMode mode) {
  QueryParams q;
  q.x0 = -1.5, q.y0 = 0.25, q.x1 = 2.5, q.y1 = 3.75;  // whole tiles and parts of tiles
  q.tile_size = 1, q.scale = per_tile, q.mode = mode;
  return q;
}

// Stable mode: every point a rising count adds has a threshold between the two counts, and every point
// already there one below the first: the thresholds are the emission rule itself.
TEST(EmissionThreshold, IsWhereAStablePointAppears) {
  const Tileset& set = Tileset::builtin();
  for (const auto& counts : {std::pair{300.0, 330.0}, std::pair{4000.0, 4100.0}}) {
    const std::vector<QueryPoint> before = testing::run_query(uniform(counts.first, QueryMode::kStable));
    const std::vector<QueryPoint> after = testing::run_query(uniform(counts.second, QueryMode::kStable));
    std::set<Key> old;
    for (const QueryPoint& p : before) {
      old.insert(key(p.id));
      const double t = emission_threshold(set, p.id);
      ASSERT_GE(t, 0);
      ASSERT_LT(t, counts.first);
    }
    std::size_t added = 0;
    for (const QueryPoint& p : after) {
      const double t = emission_threshold(set, p.id);
      ASSERT_LT(t, counts.second);
      if (old.count(key(p.id)) == 0) {
        ++added;
        EXPECT_GE(t, counts.first) << p.id.rank;
      }
    }
    EXPECT_EQ(added + before.size(), after.size());               // nothing left, only added
    EXPECT_GT(added, 0.5 * (counts.second - counts.first) * 14);  // the region holds 14 tiles' area
  }
}

// Smooth mode past the top level: a point's threshold is in its own (sub)tile's count, m^(2·depth) times
// smaller than a depth-0 tile's; the points of each depth reach close to it.
TEST(EmissionThreshold, CountsInTheTilesOfEachDepth) {
  const Tileset& set = Tileset::builtin();
  const double m = set.data().subtiles_per_side();
  ASSERT_GT(m, 1);
  QueryParams q = uniform(48000, QueryMode::kSmooth);
  q.x0 = 0.2, q.y0 = 0.2, q.x1 = 0.8, q.y1 = 0.8;
  const std::vector<QueryPoint> points = testing::run_query(q);
  double highest[2] = {0, 0};
  for (const QueryPoint& p : points) {
    ASSERT_LE(p.id.depth, 1u);
    const double count = q.scale / std::pow(m * m, p.id.depth), t = emission_threshold(set, p.id);
    ASSERT_GE(t, 0);
    ASSERT_LT(t, count);
    highest[p.id.depth] = std::max(highest[p.id.depth], t / count);
  }
  EXPECT_GT(highest[0], 0.6);  // the top level's 32,768 of 48,000
  EXPECT_GT(highest[1], 0.9);  // the subtiles' own points, appearing up to the count
}

// Smooth mode in the hand-over (N_top to m² K_h per tile): a sub-point no point glides onto appears at its
// place in its parent's list, far above its own threshold (a fade by the latter popped it in at once):
// every point a rising count adds has its threshold, in its own tile's count, between the two counts.
TEST(EmissionThreshold, IsWhereASubPointAppearsInTheHandOver) {
  const Tileset& set = Tileset::builtin();
  const double m = set.data().subtiles_per_side();
  for (const auto& counts : {std::pair{33000.0, 33400.0}, std::pair{34000.0, 34500.0}}) {
    QueryParams q = uniform(counts.first, QueryMode::kSmooth);
    q.x0 = -0.4, q.y0 = -0.4, q.x1 = 2.4, q.y1 = 1.9;  // wider, for the points that glide into the region
    std::set<Key> old;
    for (const QueryPoint& p : testing::run_query(q)) old.insert(key(p.id));
    q.x0 = 0.1, q.y0 = 0.1, q.x1 = 1.9, q.y1 = 1.4;
    q.scale = counts.second;
    std::size_t added = 0;
    for (const QueryPoint& p : testing::run_query(q)) {
      const double per_tile = std::pow(m * m, p.id.depth), t = emission_threshold(set, p.id) * per_tile;
      ASSERT_LT(t, counts.second) << p.id.depth << " " << p.id.rank;
      if (old.count(key(p.id))) continue;
      ++added;
      EXPECT_GE(t, counts.first * (1 - 1e-9)) << "depth " << p.id.depth << " rank " << p.id.rank;
    }
    EXPECT_GT(added, 100u);
  }
}

// A point's stable position is where a stable query puts it, relative to the query's origin, at every
// depth inside its own (sub)tile.
TEST(EmissionThreshold, StablePositionIsWhereAStableQueryPutsAPoint) {
  const Tileset& set = Tileset::builtin();
  QueryParams q = uniform(2000, QueryMode::kStable);
  q.tile_size = 2.5, q.origin_x = 1.25, q.origin_y = -3;
  const std::vector<QueryPoint> points = testing::run_query(q);
  ASSERT_GT(points.size(), 1000u);
  for (const QueryPoint& p : points) {
    double x = 0, y = 0;
    ASSERT_TRUE(stable_position(set, p.id, q.tile_size, q.origin_x, q.origin_y, &x, &y));
    ASSERT_NEAR(x, p.x, 1e-12) << p.id.rank;
    ASSERT_NEAR(y, p.y, 1e-12) << p.id.rank;
  }
  const double m = set.data().subtiles_per_side();
  QueryParams deep = uniform(48000, QueryMode::kSmooth);
  deep.x0 = 0.2, deep.y0 = 0.2, deep.x1 = 0.8, deep.y1 = 0.8;
  std::size_t sub_points = 0;
  for (const QueryPoint& p : testing::run_query(deep)) {
    double x = 0, y = 0;
    ASSERT_TRUE(stable_position(set, p.id, 1, 0, 0, &x, &y));
    const double side = std::pow(m, -double(p.id.depth));
    EXPECT_GE(x, double(p.id.tile_x) * side);
    EXPECT_LT(x, double(p.id.tile_x + 1) * side);
    EXPECT_GE(y, double(p.id.tile_y) * side);
    EXPECT_LT(y, double(p.id.tile_y + 1) * side);
    sub_points += p.id.depth > 0;
  }
  EXPECT_GT(sub_points, 100u);
  double x = 0, y = 0;
  EXPECT_FALSE(stable_position(set, PointId{0, 0, 1u << 30, 0}, 1, 0, 0, &x, &y));
  EXPECT_FALSE(stable_position(set, PointId{0, 0, 0, 0}, 0, 0, 0, &x, &y));
  EXPECT_FALSE(stable_position(set, PointId{0, 0, 0, 0}, std::nan(""), 0, 0, &x, &y));
  EXPECT_FALSE(stable_position(set, PointId{0, 0, 0, 0}, 1, 0, 0, nullptr, &y));
}

TEST(EmissionThreshold, IsNegativeForIdsTheSetDoesNotHave) {
  const Tileset& set = Tileset::builtin();
  EXPECT_LT(emission_threshold(set, PointId{0, 0, 1u << 30, 0}), 0);
  EXPECT_LT(emission_threshold(set, PointId{0, 0, 0, kMaxQueryDepth + 1}), 0);
  EXPECT_LT(emission_threshold(Tileset(), PointId{0, 0, 0, 0}), 0);
  EXPECT_GE(emission_threshold(set, PointId{-7, 1000000007, 0, kMaxQueryDepth}), 0);
  // Tiles no query reaches (and whose neighbours' coordinates would overflow).
  const std::int64_t most = std::numeric_limits<std::int64_t>::max();
  EXPECT_LT(emission_threshold(set, PointId{most, 0, 0, 0}), 0);
  EXPECT_LT(emission_threshold(set, PointId{0, -most - 1, 0, 1}), 0);
  EXPECT_EQ(tile_of(set, PointId{most, most, 0, 0}), nullptr);
}

}  // namespace
}  // namespace kdm
