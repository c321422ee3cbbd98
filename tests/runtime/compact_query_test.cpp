// The compact output: query_points_compact writes query_points' points, in its order, as float positions
// and point keys; with or without keys, in both modes, for every kind of density, past the top level, when
// resumed through small buffers (a cursor serving both functions), with no allocation; keys are unique and
// wrap as documented; bad arguments are refused by name.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "allocation_counter.h"
#include "kdm/runtime/compact_query.h"
#include "random_partition.h"
#include "run_query.h"

namespace kdm {
namespace {

struct Compact {
  std::vector<float> xy;
  std::vector<std::uint64_t> keys;
};

std::vector<QueryPoint> run_full(const QueryParams& q) {
  return testing::run_query(q, 4096);
}

// Through a buffer of `capacity` points, keys if asked.
Compact run_compact(const QueryParams& q, std::size_t capacity, bool keys) {
  Compact all;
  std::vector<float> xy(2 * capacity);
  std::vector<std::uint64_t> key(capacity);
  QueryCursor cursor;
  for (;;) {
    std::size_t written = 0;
    const CompactPoints out{xy.data(), keys ? key.data() : nullptr};
    const Status s = query_points_compact(Tileset::builtin(), q, out, capacity, &written, &cursor);
    EXPECT_TRUE(s == Status::kOk || s == Status::kBufferFull) << status_message(s);
    all.xy.insert(all.xy.end(), xy.begin(), xy.begin() + 2 * written);
    if (keys) all.keys.insert(all.keys.end(), key.begin(), key.begin() + written);
    if (s != Status::kBufferFull) return all;
  }
}

double ramp(void*, double x, double) {
  return 0.2 + 0.1 * x;
}

// A region with edges inside tiles, so every emitter (inside, beside, edge lists) runs.
QueryParams region(QueryMode mode) {
  QueryParams q;
  q.x0 = -1.3, q.y0 = 0.4, q.x1 = 3.7, q.y1 = 4.1;
  q.origin_x = 1, q.origin_y = 2;
  q.scale = 2000;
  q.mode = mode;
  return q;
}

// The compact points are the full query's, their positions within the documented 2^-21 · (|position| +
// tile size) of its doubles (computed in float from the tile's corner and offsets where the density is
// constant, else its doubles rounded to float).
void expect_same(const std::vector<QueryPoint>& full, const Compact& compact, bool keys,
                 double tile_size = 1) {
  ASSERT_EQ(compact.xy.size(), 2 * full.size());
  if (keys) {
    ASSERT_EQ(compact.keys.size(), full.size());
  }
  for (std::size_t i = 0; i < full.size(); ++i) {
    ASSERT_LE(std::fabs(compact.xy[2 * i] - full[i].x), std::ldexp(std::fabs(full[i].x) + tile_size, -21));
    ASSERT_LE(std::fabs(compact.xy[2 * i + 1] - full[i].y),
              std::ldexp(std::fabs(full[i].y) + tile_size, -21));
    if (keys) {
      ASSERT_EQ(compact.keys[i], point_key(full[i].id)) << i;
    }
  }
}

TEST(CompactQueryTest, WritesTheFullQuerysPointsInItsOrder) {
  std::vector<float> image_values(16 * 16);
  for (int i = 0; i < 256; ++i) image_values[i] = float(0.1 + (i % 16) * (i / 16) / 225.0);
  DensityImageView image;
  image.width = image.height = 16;
  image.x0 = -2, image.y0 = -1, image.x1 = 5, image.y1 = 5;
  image.values = image_values.data();
  std::vector<float> mip;
  ASSERT_EQ(make_density_max_mip(image, mip), Status::kOk);
  for (QueryMode mode : {QueryMode::kStable, QueryMode::kSmooth}) {
    for (int kind = 0; kind < 3; ++kind) {
      QueryParams q = region(mode);
      if (kind == 1) q.density.kind = QueryDensity::Kind::kImage, q.density.image = &image;
      if (kind == 2) {
        q.density.kind = QueryDensity::Kind::kCallback;
        q.density.callback = ramp, q.density.callback_max = 0.6;
      }
      SCOPED_TRACE(::testing::Message() << "mode " << int(mode) << " density kind " << kind);
      const std::vector<QueryPoint> full = run_full(q);
      ASSERT_GT(full.size(), 5000u);
      for (bool keys : {false, true})
        for (std::size_t capacity : {std::size_t(1), std::size_t(997), std::size_t(1) << 16})
          expect_same(full, run_compact(q, capacity, keys), keys);
    }
  }
}

TEST(CompactQueryTest, WritesTheSubtilesPointsPastTheTopLevel) {
  QueryParams q;
  q.x0 = 0.2, q.y0 = 0.3, q.x1 = 0.45, q.y1 = 0.5;
  q.mode = QueryMode::kSmooth;
  q.scale = 4 * Tileset::builtin().max_points_per_tile();  // depth 1
  const std::vector<QueryPoint> full = run_full(q);
  ASSERT_GT(full.size(), 3000u);
  bool deep = false;
  for (const QueryPoint& p : full) deep = deep || p.id.depth > 0;
  ASSERT_TRUE(deep);
  for (std::size_t capacity : {std::size_t(300), std::size_t(1) << 16})
    expect_same(full, run_compact(q, capacity, true), true);
}

TEST(CompactQueryTest, KeepsTheFullQuerysPointsFarFromTheOrigin) {
  // Smooth mode settles a border tile's points by their float positions where these are far enough from
  // the region's sides, and by the full query's test in double where they are not: far from the origin a
  // float's step (2.4e-4 at 3,000; 3.9e-3 at 4·10^4, near the farthest a float output may lie at this
  // density, 2^21 spacings of 0.022) leaves more points to the test.
  for (double at : {3000.0, 4e4}) {
    QueryParams q = region(QueryMode::kSmooth);
    q.x0 += at, q.x1 += at, q.y0 -= at, q.y1 -= at;
    q.origin_x = q.origin_y = 0;
    SCOPED_TRACE(::testing::Message() << "region at " << at);
    const std::vector<QueryPoint> full = run_full(q);
    ASSERT_GT(full.size(), 30000u);
    for (std::size_t capacity : {std::size_t(997), std::size_t(1) << 16})
      expect_same(full, run_compact(q, capacity, true), true);
  }
}

TEST(CompactQueryTest, PartsOfARegionGiveItsPointsBitForBit) {
  // Whole tiles (converted by the straight loop) and cut ones (tested point by point) write a point alike.
  std::mt19937 rng(5);
  for (QueryMode mode : {QueryMode::kStable, QueryMode::kSmooth}) {
    QueryParams whole = region(mode);
    whole.x0 = -2, whole.y0 = 0, whole.x1 = 3, whole.y1 = 4;
    auto by_key = [](const Compact& c, std::map<std::uint64_t, std::pair<float, float>>& into) {
      for (std::size_t i = 0; i < c.keys.size(); ++i)
        EXPECT_TRUE(into.emplace(c.keys[i], std::make_pair(c.xy[2 * i], c.xy[2 * i + 1])).second);
    };
    std::map<std::uint64_t, std::pair<float, float>> all, parts;
    by_key(run_compact(whole, 1 << 16, true), all);
    for (const QueryParams& part : testing::random_grid_parts(whole, 4, rng))
      by_key(run_compact(part, 1 << 16, true), parts);
    EXPECT_GT(all.size(), 30000u);
    EXPECT_TRUE(all == parts) << "mode " << int(mode);
  }
}

TEST(CompactQueryTest, ACursorServesTheFullAndTheCompactQueryAlike) {
  const QueryParams q = region(QueryMode::kSmooth);
  const std::vector<QueryPoint> full = run_full(q);
  std::vector<QueryPoint> points(777);
  std::vector<float> xy(2 * 777);
  std::vector<std::uint64_t> keys(777);
  Compact mixed;
  QueryCursor cursor;
  for (int call = 0;; ++call) {
    std::size_t written = 0;
    Status s;
    if (call % 2) {
      s = query_points(Tileset::builtin(), q, points.data(), points.size(), &written, &cursor);
      for (std::size_t i = 0; i < written; ++i) {
        mixed.xy.push_back(float(points[i].x)), mixed.xy.push_back(float(points[i].y));
        mixed.keys.push_back(point_key(points[i].id));
      }
    } else {
      s = query_points_compact(Tileset::builtin(), q, {xy.data(), keys.data()}, keys.size(), &written,
                               &cursor);
      mixed.xy.insert(mixed.xy.end(), xy.begin(), xy.begin() + 2 * written);
      mixed.keys.insert(mixed.keys.end(), keys.begin(), keys.begin() + written);
    }
    if (s != Status::kBufferFull) break;
  }
  expect_same(full, mixed, true);
}

TEST(CompactQueryTest, KeysAreUniqueAndNameTheirPoint) {
  QueryParams q = region(QueryMode::kSmooth);
  q.x0 = -3e6, q.x1 = -3e6 + 6;  // tile coordinates beyond 2^21, kept in the key modulo 2^21
  q.origin_x = q.x0;
  const std::vector<QueryPoint> full = run_full(q);
  std::set<std::uint64_t> keys;
  for (const QueryPoint& p : full) {
    const std::uint64_t k = point_key(p.id);
    EXPECT_TRUE(keys.insert(k).second) << "two points share key " << k;
    const std::uint64_t mask = (std::uint64_t(1) << kKeyTileBits) - 1;
    EXPECT_EQ(k & mask, std::uint64_t(p.id.tile_x) & mask);
    EXPECT_EQ(k >> kKeyTileBits & mask, std::uint64_t(p.id.tile_y) & mask);
    EXPECT_EQ(k >> (2 * kKeyTileBits) & ((1u << kKeyRankBits) - 1), p.id.rank);
    EXPECT_EQ(k >> (2 * kKeyTileBits + kKeyRankBits), p.id.depth);
  }
  EXPECT_EQ(keys.size(), full.size());
  // Tiles 2^21 apart share their keys (the documented window); 1 apart they do not.
  const PointId id{-5, 7, 123, 2};
  EXPECT_EQ(point_key(id), point_key(PointId{-5 + (std::int64_t(1) << kKeyTileBits), 7, 123, 2}));
  EXPECT_NE(point_key(id), point_key(PointId{-4, 7, 123, 2}));
  EXPECT_NE(point_key(id), point_key(PointId{-5, 7, 123, 1}));
}

// A key gives its id back (point_id_of_key), given a tile of the region, also for negative tiles, far
// from the origin and past the top level: what fading a compact point by its threshold needs (its key's
// bits alone named another tile for tile -3 and a threshold of 5.8 where the point's is 5.1).
TEST(CompactQueryTest, AKeyGivesItsIdBackNearATileOfTheRegion) {
  for (const double x0 : {-3e6 - 0.5, -7.3, 2.5e5}) {
    for (const double scale : {2000.0, 3.1e6}) {  // the second past the top level: depth 1
      QueryParams q = region(QueryMode::kSmooth);
      q.x0 = x0, q.x1 = x0 + (scale > 1e6 ? 0.05 : 4), q.y0 = -2.2, q.y1 = q.y0 + (scale > 1e6 ? 0.05 : 4);
      q.origin_x = q.x0, q.origin_y = q.y0, q.scale = scale;
      const std::vector<QueryPoint> full = run_full(q);
      ASSERT_GT(full.size(), 100u);
      const std::int64_t near_x = std::int64_t(std::floor(q.x0)), near_y = std::int64_t(std::floor(q.y1));
      bool deep = false;
      for (const QueryPoint& p : full) {
        ASSERT_EQ(point_id_of_key(Tileset::builtin(), point_key(p.id), near_x, near_y), p.id);
        deep = deep || p.id.depth > 0;
      }
      EXPECT_EQ(deep, scale > 1e6);
    }
  }
}

TEST(CompactQueryTest, AllocatesNothing) {
  const QueryParams q = region(QueryMode::kSmooth);
  std::vector<float> xy(2 * 512);
  std::vector<std::uint64_t> keys(512);
  (void)Tileset::builtin();
  QueryCursor cursor;
  std::size_t written = 0, total = 0;
  const std::size_t before = testing::allocations();
  Status s;
  do {
    s = query_points_compact(Tileset::builtin(), q, {xy.data(), keys.data()}, 512, &written, &cursor);
    total += written;
  } while (s == Status::kBufferFull);
  EXPECT_EQ(testing::allocations(), before);
  EXPECT_GT(total, 5000u);
}

TEST(CompactQueryTest, RefusesMissingOutputByName) {
  const QueryParams q = region(QueryMode::kStable);
  QueryCursor cursor;
  std::size_t written = 7;
  QueryProblem why;
  EXPECT_EQ(query_points_compact(Tileset::builtin(), q, {}, 10, &written, &cursor, &why),
            Status::kInvalidArgument);
  EXPECT_EQ(why.kind, QueryProblem::Kind::kMissingArgument);
  EXPECT_STREQ(why.parameter, "out.xy");
  EXPECT_EQ(written, 0u);
  std::uint64_t keys[4];
  EXPECT_EQ(query_points_compact(Tileset::builtin(), q, {nullptr, keys}, 4, &written, &cursor, &why),
            Status::kInvalidArgument);
  EXPECT_STREQ(why.parameter, "out.xy");
  // No room asked: nothing to write, so no output needed; the region's points are all still to come.
  EXPECT_EQ(query_points_compact(Tileset::builtin(), q, {}, 0, &written, &cursor, &why), Status::kBufferFull);
  EXPECT_EQ(why.kind, QueryProblem::Kind::kNone);
  EXPECT_EQ(written, 0u);
  float xy[8];
  EXPECT_EQ(query_points_compact(Tileset::builtin(), q, {xy, nullptr}, 4, nullptr, &cursor, &why),
            Status::kInvalidArgument);
  EXPECT_STREQ(why.parameter, "written");
  QueryParams far = q;  // positions relative to the origin beyond a float
  far.origin_y = -5e69;
  QueryCursor fresh;
  EXPECT_EQ(query_points_compact(Tileset::builtin(), far, {xy, nullptr}, 4, &written, &fresh, &why),
            Status::kInvalidArgument);
  EXPECT_EQ(why.kind, QueryProblem::Kind::kTooFarFromOrigin);
  EXPECT_STREQ(why.parameter, "origin_y");
  far.origin_y = std::numeric_limits<double>::infinity();  // not a distance: named as not finite
  fresh = QueryCursor{};
  EXPECT_EQ(query_points_compact(Tileset::builtin(), far, {xy, nullptr}, 4, &written, &fresh, &why),
            Status::kInvalidArgument);
  EXPECT_EQ(why.kind, QueryProblem::Kind::kNotFinite);
  EXPECT_STREQ(why.parameter, "origin_y");
  // Within a float's range but where its step reaches a tile: every tile's points would fall together.
  // The limit stated is the nearer of that and the density's (2^21 spacings, below), so that a caller
  // moving the origin within it is served, not refused again with another limit.
  const double spacing = q.tile_size / std::sqrt(q.scale * q.density.constant * q.tile_size * q.tile_size);
  far.origin_y = 0, far.origin_x = q.x0 + std::ldexp(q.tile_size, 23) * 1.01;
  fresh = QueryCursor{};
  EXPECT_EQ(query_points_compact(Tileset::builtin(), far, {xy, nullptr}, 4, &written, &fresh, &why),
            Status::kInvalidArgument);
  EXPECT_EQ(why.kind, QueryProblem::Kind::kTooFarFromOrigin);
  EXPECT_STREQ(why.parameter, "origin_x");
  EXPECT_DOUBLE_EQ(why.limit, std::min(std::ldexp(q.tile_size, 23), std::ldexp(spacing, 21)));
  QueryParams sparse = far;  // a twentieth of a point per tile: spacings of 4.5 tiles, the tile's bound first
  sparse.scale = 0.05 / (q.density.constant * q.tile_size * q.tile_size);
  fresh = QueryCursor{};
  EXPECT_EQ(query_points_compact(Tileset::builtin(), sparse, {xy, nullptr}, 4, &written, &fresh, &why),
            Status::kInvalidArgument);
  EXPECT_EQ(why.kind, QueryProblem::Kind::kTooFarFromOrigin);
  EXPECT_EQ(why.limit, std::ldexp(q.tile_size, 23));
  // Nearer, but where the step passes a quarter of the spacing at the query's density (2^21 spacings
  // out): points would still fall together, and only the density says so.
  far.origin_x = q.x1 + std::ldexp(spacing, 21) * 1.01;
  fresh = QueryCursor{};
  EXPECT_EQ(query_points_compact(Tileset::builtin(), far, {xy, nullptr}, 4, &written, &fresh, &why),
            Status::kInvalidArgument);
  EXPECT_EQ(why.kind, QueryProblem::Kind::kTooFarFromOrigin);
  EXPECT_STREQ(why.parameter, "origin_x");
  EXPECT_DOUBLE_EQ(why.limit, std::ldexp(spacing, 21));
  far.origin_x = q.x1 + std::ldexp(spacing, 21) * 0.99;  // nearer: served, with the documented rounding
  fresh = QueryCursor{};
  EXPECT_NE(query_points_compact(Tileset::builtin(), far, {xy, nullptr}, 4, &written, &fresh, &why),
            Status::kInvalidArgument);
}

TEST(CompactQueryTest, RefusesKeysForTilesTooLargeToNumber) {
  // One tile (one colour) of one level holding 2^19 + 1 points: ranks past a key's 19 bits.
  TilesetData set;
  set.colours = 1, set.levels = 1;
  set.recipe = "test", set.generator_version = "test";
  const std::uint32_t count = (1u << kKeyRankBits) + 1;
  set.level_nominal = {count};
  set.tiles.resize(1);
  Tile& tile = set.tiles[0];
  for (std::uint32_t i = 0; i < count; ++i) {
    tile.points.push_back({std::uint16_t(i * 40503u), std::uint16_t(i * 2654435761u >> 16)});
    tile.keys.push_back(std::uint16_t(i >> 4));
  }
  tile.level_end = {count};
  std::vector<std::uint8_t> bytes;
  ASSERT_EQ(encode_tileset(set, bytes), Status::kOk);
  Tileset large;
  ASSERT_EQ(Tileset::load_memory(bytes.data(), bytes.size(), large), Status::kOk);
  QueryParams q;
  q.x1 = q.y1 = 1, q.scale = 100;
  std::vector<float> xy(2 * 256);
  std::vector<std::uint64_t> keys(256);
  QueryCursor cursor;
  std::size_t written = 0;
  QueryProblem why;
  EXPECT_EQ(query_points_compact(large, q, {xy.data(), keys.data()}, 256, &written, &cursor, &why),
            Status::kInvalidArgument);
  EXPECT_EQ(why.kind, QueryProblem::Kind::kKeysUnsupported);
  EXPECT_STREQ(why.parameter, "out.keys");
  EXPECT_EQ(why.value, double(count));
  char line[300];  // the count and the limit, not the count as if it were the keys' value
  describe_query_problem(why, line, sizeof line);
  EXPECT_NE(
      std::strstr(line, (": its tiles hold " + std::to_string(count) + " points, a key numbers at most " +
                         std::to_string(std::uint64_t(why.limit)) + "; ask for no 'out.keys'")
                            .c_str()),
      nullptr)
      << line;
  // Positions alone need no key.
  EXPECT_EQ(query_points_compact(large, q, {xy.data(), nullptr}, 256, &written, &cursor, &why), Status::kOk);
  EXPECT_GT(written, 50u);
}

}  // namespace
}  // namespace kdm
