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
