// Smooth queries past the top level (runtime/src/descent.h) on two small sets with a hand-over onto 4×4
// subtiles per tile: three levels (32 … 512 points per tile) handed over onto the subtiles' level 0, and
// four (32 … 2,048) onto their level 1. For both, the densities asked for are served to four depths, a
// point once emitted stays emitted with its id and moves continuously, partitions (random grids of cuts),
// resumed calls and threads give the same bits at depths 0 to 4 and 10^9 units from the origin, the loops
// for varying and constant densities agree, and positions far from the world origin keep their precision.
// Densities are stated in units of the set's top level, N_top.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <map>
#include <new>
#include <random>
#include <set>
#include <thread>
#include <tuple>
#include <vector>

#include "allocation_counter.h"
#include "handover_levels.h"
#include "kdm/generator/bake.h"
#include "kdm/runtime/class_query.h"
#include "kdm/runtime/query.h"
#include "kdm/runtime/tileset.h"
#include "random_partition.h"

namespace kdm {
namespace {

/// The small set handing over onto its subtiles' level `level`, loaded as a query would.
Tileset bake_small_set(std::uint32_t level) {
  std::vector<std::uint8_t> bytes;
  EXPECT_EQ(encode_tileset(testing::small_handover_set(level), bytes), Status::kOk);
  Tileset t;
  EXPECT_EQ(Tileset::load_memory(bytes.data(), bytes.size(), t), Status::kOk);
  return t;
}

class DescentTest : public testing::HandoverLevelTest<Tileset, bake_small_set> {};
INSTANTIATE_TEST_SUITE_P(HandoverLevel, DescentTest, ::testing::Values(0u, 1u), testing::handover_level_name);

/// The set the running test queries.
const Tileset& small_set() {
  return DescentTest::set();
}
/// Its top level's nominal points per tile, N_top.
double top() {
  return small_set().max_points_per_tile();
}

using Key = std::tuple<std::int64_t, std::int64_t, std::uint32_t, std::uint32_t>;
Key key(const PointId& id) {
  return {id.tile_x, id.tile_y, id.rank, id.depth};
}

std::vector<QueryPoint> query(const QueryParams& p, std::size_t chunk = 1 << 16) {
  std::vector<QueryPoint> all, buffer(chunk);
  QueryCursor cursor;
  for (;;) {
    std::size_t n = 0;
    const Status s = query_points(small_set(), p, buffer.data(), buffer.size(), &n, &cursor);
    all.insert(all.end(), buffer.begin(), buffer.begin() + std::ptrdiff_t(n));
    if (s == Status::kOk) return all;
    EXPECT_EQ(s, Status::kBufferFull);
    if (s != Status::kBufferFull) return all;
  }
}

/// A uniform smooth query of `side` × `side` tiles at `per_tile` expected points per tile.
QueryParams uniform(double side, double per_tile) {
  QueryParams p;
  p.x1 = p.y1 = side;
  p.scale = per_tile;
  p.mode = QueryMode::kSmooth;
  return p;
}

double ramp(void*, double x, double) {
  return 0.25 + 0.75 * std::clamp(x / 2, 0.0, 1.0);
}

TEST_P(DescentTest, SmoothQueriesGoFourDepthsPastTheTopAndStableOnesStopThere) {
  const Tileset& t = small_set();
  ASSERT_EQ(t.data().subtiles_per_side(), 4u);
  EXPECT_EQ(query_density_limit(t, QueryMode::kStable), top());
  EXPECT_EQ(query_density_limit(t, QueryMode::kSmooth), top() * std::pow(4.0, 8));
  QueryParams p = uniform(0.01, top() * std::pow(4.0, 8) * 1.01);
  std::vector<QueryPoint> out(16);
  std::size_t n = 0;
  QueryCursor cursor;
  QueryProblem why;
  EXPECT_EQ(query_points(t, p, out.data(), out.size(), &n, &cursor, &why), Status::kInvalidArgument);
  EXPECT_EQ(why.kind, QueryProblem::Kind::kDensityTooHigh);
  p.scale = 1.17 * top(), p.mode = QueryMode::kStable, cursor = {};
  EXPECT_EQ(query_points(t, p, out.data(), out.size(), &n, &cursor, &why), Status::kInvalidArgument);
  EXPECT_EQ(why.limit, top());
  p.mode = QueryMode::kSmooth, cursor = {};
  EXPECT_EQ(query_points(t, p, out.data(), out.size(), &n, &cursor, &why), Status::kOk);
}

TEST_P(DescentTest, EveryDepthHasTheExpectedCount) {
  // Windows of 20,000 expected points. Over 20 windows each, count / expected had means 0.993–1.011 (the
  // small set's own counts per tile) and standard deviations 0.12–0.24%: 3% is 8 deviations past the bias.
  for (const double n : {1.37, 5.86, 16.0 * 3, 256 * 1.7, 4096 * 2.5}) {
    const double per_tile = n * top();
    const double side = std::sqrt(20000 / per_tile);
    const std::vector<QueryPoint> points = query(uniform(side, per_tile));
    const double expected = per_tile * side * side;
    EXPECT_NEAR(double(points.size()) / expected, 1.0, 0.03) << per_tile << " points per tile";
    std::uint32_t deepest = 0;
    std::set<Key> ids;
    for (const QueryPoint& q : points) deepest = std::max(deepest, q.id.depth), ids.insert(key(q.id));
    EXPECT_EQ(ids.size(), points.size()) << "every id once";
    // Depth d + 1's first points (the sub-points no point glides onto) appear past N_top · m^(2d).
    std::uint32_t depth = 0;
    for (double from = top(); per_tile > from; from *= 16) ++depth;
    EXPECT_EQ(deepest, depth) << per_tile;
  }
}

/// A step of ×20 at x = 0.5037: more than m² = 16, so a point and its sub-point (or a sub-point and its
/// own) can lie on either side, and a depth can take a point over before its parent has.
double step(void*, double x, double) {
  return x < 0.5037 ? 1.0 : 0.05;
}

TEST_P(DescentTest, PointsStayWithTheirIdsAndMoveContinuouslyAsTheScaleGrows) {
  // A tile by half a tile, through the hand-overs from depth 0 to depth 2 in steps of 1.25% in scale.
  // Each density gliding by each point's own count, then together (QueryParams::glide_together).
  for (int run = 0; run < 4; ++run) {
    double (*density)(void*, double, double) = run % 2 ? step : ramp;
    QueryParams p = uniform(1, 0);
    p.y1 = 0.5;
    p.glide_together = run >= 2;
    p.density.kind = QueryDensity::Kind::kCallback, p.density.callback = density, p.density.callback_max = 1;
    std::map<Key, std::pair<double, double>> before;
    double largest_step = 0;  // in spacings where the point is
    const int steps = 300;
    for (int s = 0; s <= steps; ++s) {
      p.scale = 0.78 * top() * std::pow(32 / 0.78, double(s) / steps);
      std::map<Key, std::pair<double, double>> now;
      const std::vector<QueryPoint> points = query(p);
      for (const QueryPoint& q : points) now[key(q.id)] = {q.x, q.y};
      ASSERT_EQ(now.size(), points.size()) << "an id emitted twice at scale " << p.scale;
      for (const auto& [id, at] : before) {
        const double spacing = 1 / std::sqrt(p.scale * density(nullptr, at.first, 0));
        const auto it = now.find(id);
        // A point leaves only across the region's border, which it may glide over.
        if (it == now.end()) {
          const double border = std::min({at.first, 1 - at.first, at.second, 0.5 - at.second});
          EXPECT_LT(border, 4 * spacing) << "point lost at scale " << p.scale;
          continue;
        }
        largest_step = std::max(
            largest_step, std::hypot(it->second.first - at.first, it->second.second - at.second) / spacing);
      }
      before = std::move(now);
    }
    // A hand-over takes the scale from where a point's count reaches N_top to where it and its
    // sub-point's pass their ends, at least ×2.83 here (three keyframe intervals of ×√2): 80 steps or more
    // for a glide of up to 3 spacings, about 0.04 spacings a step, where a jump would be a spacing or
    // more. Measured: 0.026–0.049 on the ramp, 0.11 across the step; gliding together 0.081–0.103 there.
    std::printf("%s%s: largest step %.3f spacings\n", density == ramp ? "ramp" : "step",
                p.glide_together ? ", together" : "", largest_step);
    EXPECT_LT(largest_step, 0.35) << (density == ramp ? "ramp" : "step")
                                  << (p.glide_together ? ", together" : "");
  }
}

TEST_P(DescentTest, OneQueryServesARadialMapOf1To100000) {
  // exp(-ln(10^5) · min(1, 2r)) over the unit square, as a 256² image: 1 at the centre, 10^-5 from r = ½
  // on, 0.1 to 10^4 times N_top points per tile. Each tenth of the log range gets the points the image's
  // own integral asks for.
  const int texels = 256;
  std::vector<float> values(texels * texels), mip;
  const double a = std::log(1e5);
  auto radial = [&](double x, double y) {
    return std::exp(-a * std::min(1.0, 2 * std::hypot(x - 0.5, y - 0.5)));
  };
  for (int y = 0; y < texels; ++y)
    for (int x = 0; x < texels; ++x)
      values[y * texels + x] = float(radial((x + 0.5) / texels, (y + 0.5) / texels));
  DensityImageView image;
  image.width = image.height = texels;
  image.values = values.data();
  ASSERT_EQ(make_density_max_mip(image, mip), Status::kOk);
  QueryParams p = uniform(1, 8.4e7);
  p.tile_size = 0.25 * std::sqrt(top() / 512);  // the same points per tile relative to N_top
  p.density.kind = QueryDensity::Kind::kImage, p.density.image = &image;
  auto band = [&](double rho) { return std::min(9, int(std::log(std::max(rho, 1e-300)) / -a * 10)); };
  std::vector<double> got(10), expected(10);
  const std::vector<QueryPoint> points = query(p);
  for (const QueryPoint& q : points) got[std::size_t(band(image.at(q.x, q.y)))] += 1;
  const int grid = 4096;  // the image's integral, band by band, at 16² samples per texel
  for (int y = 0; y < grid; ++y)
    for (int x = 0; x < grid; ++x) {
      const double rho = image.at((x + 0.5) / grid, (y + 0.5) / grid);
      expected[std::size_t(band(rho))] += rho * p.scale / (double(grid) * grid);
    }
  std::uint32_t deepest = 0;
  for (const QueryPoint& q : points) deepest = std::max(deepest, q.id.depth);
  EXPECT_EQ(deepest, 4u);  // past N_top · 16^3 points per tile, depth-4 sub-points appear
  // Counts in a band of N expected points spread by about √N (1/√200 = 7% for the smallest band tested,
  // under 0.3% for the largest); smooth mode moves points up to a spacing across band borders. Measured:
  // 0.982–1.023 (bands 0–7 within 0.3–0.9%; the last two, 659 and 413 points expected, within one √N).
  for (int b = 0; b < 10; ++b) {
    if (expected[b] < 200) continue;
    EXPECT_NEAR(got[b] / expected[b], 1.0, std::max(0.02, 3 / std::sqrt(expected[b])))
        << "band " << b << ": " << got[b] << " points, " << expected[b] << " expected";
  }
}

TEST_P(DescentTest, PartitionsAndResumedCallsGiveTheSameBits) {
  // A ramp (every point through the general loop) and a constant density (subtiles inside the region emit
  // their own points through a loop of their own, those cut by a border through the general one).
  for (const bool constant : {false, true}) {
    QueryParams p = uniform(0, top() * 40);
    p.x0 = 0.3, p.y0 = -0.2, p.x1 = 1.1, p.y1 = 0.45;
    p.origin_x = 0.25, p.origin_y = 0.125;
    if (!constant)
      p.density.kind = QueryDensity::Kind::kCallback, p.density.callback = ramp, p.density.callback_max = 1;
    const std::vector<QueryPoint> whole = query(p), chunked = query(p, 7);
    ASSERT_EQ(whole.size(), chunked.size());
    for (std::size_t i = 0; i < whole.size(); ++i) {
      EXPECT_EQ(whole[i].x, chunked[i].x);
      EXPECT_TRUE(whole[i].id == chunked[i].id);
    }
    std::map<Key, std::pair<double, double>> parts;
    for (const double cut : {0.41, 0.7731}) {
      QueryParams a = p, b = p;
      a.x1 = b.x0 = cut;
      for (const QueryParams& part : {a, b})
        for (const QueryPoint& q : query(part))
          EXPECT_TRUE(parts.emplace(key(q.id), std::pair{q.x, q.y}).second);
      ASSERT_EQ(parts.size(), whole.size());
      for (const QueryPoint& q : whole) {
        const auto it = parts.find(key(q.id));
        ASSERT_NE(it, parts.end());
        EXPECT_EQ(it->second.first, q.x);
        EXPECT_EQ(it->second.second, q.y);
      }
      parts.clear();
    }
  }
}

double three_quarters(void*, double, double) {
  return 0.75;
}

TEST_P(DescentTest, AConstantCallbackGivesTheConstantDensitysBitsAtEveryDepth) {
  // A varying density's loops (each point's own count, batched, and culled beside the region) and a
  // constant density's (one count and bracket per tile) meet the same counts here, so they must emit the
  // same points, ids and position bits: at depths 0 to 3, through a small buffer. (A tile the region cuts
  // may give them in another order: whether it goes cell by cell is decided by the density's glide reach.)
  for (const double n : {0.78, 16.0 * 3, 256 * 2.2, 4096 * 1.3}) {
    const double per_tile = n * top();
    QueryParams p = uniform(0, per_tile / 0.75);
    const double side = std::sqrt(9000 / per_tile);
    p.x0 = 0.37, p.y0 = -0.61, p.x1 = p.x0 + side, p.y1 = p.y0 + side * 0.7;
    p.origin_x = 0.5, p.origin_y = -0.5;
    p.density.constant = 0.75;
    std::vector<QueryPoint> constant = query(p, 333);
    p.density.kind = QueryDensity::Kind::kCallback, p.density.callback = three_quarters;
    p.density.callback_max = 0.75;
    std::vector<QueryPoint> callback = query(p, 333);
    for (std::vector<QueryPoint>* points : {&constant, &callback})
      std::sort(points->begin(), points->end(),
                [](const QueryPoint& a, const QueryPoint& b) { return key(a.id) < key(b.id); });
    ASSERT_EQ(constant.size(), callback.size()) << per_tile;
    EXPECT_GT(constant.size(), 3000u);
    for (std::size_t i = 0; i < constant.size(); ++i) {
      ASSERT_TRUE(constant[i].id == callback[i].id) << per_tile << " point " << i;
      ASSERT_EQ(constant[i].x, callback[i].x) << per_tile << " point " << i;
      ASSERT_EQ(constant[i].y, callback[i].y) << per_tile << " point " << i;
    }
  }
}

TEST_P(DescentTest, PartitionsFarFromTheWorldOriginAtDepthFourKeepEveryPoint) {
  // Depth 4 at 10^11 world units, where a coordinate's rounding (2^-20 ≈ 1e-6) spans many of a subtile's
  // position units (1/65536 of its side, 6e-8): the subtiles beside a cut, which pass over the points that
  // cannot glide into their part, still emit every point of the whole once.
  const double far = 1e11, per_tile = top() * 65536 * 0.9;
  QueryParams p = uniform(0, per_tile);
  p.x0 = p.origin_x = far, p.y0 = p.origin_y = -far;
  p.x1 = far + 1.0 / 32, p.y1 = -far + 1.0 / 64;
  const std::vector<QueryPoint> whole = query(p);
  ASSERT_GT(whole.size(), 5000u);
  for (const double cut : {1.0 / 77, 1.0 / 43}) {
    std::set<Key> parts;
    QueryParams a = p, b = p;
    a.x1 = b.x0 = far + cut;
    for (const QueryParams& part : {a, b})
      for (const QueryPoint& q : query(part)) EXPECT_TRUE(parts.insert(key(q.id)).second);
    EXPECT_EQ(parts.size(), whole.size());
    for (const QueryPoint& q : whole) EXPECT_EQ(parts.count(key(q.id)), 1u);
  }
}

double wave(void*, double x, double y) {
  return 0.55 + 0.45 * std::sin(700 * x) * std::cos(500 * y);
}

/// The three kinds of density over region p (the image covering it), at `per_tile` points per tile at
/// most; the image's texels live in `texels` and `mip`.
std::vector<QueryParams> three_densities(QueryParams p, DensityImageView& image, std::vector<float>& texels,
                                         std::vector<float>& mip) {
  texels.resize(16 * 16);
  for (int i = 0; i < 16 * 16; ++i) texels[i] = 0.3f + 0.7f * float((i * 37) % 16) / 15.0f;
  image.width = image.height = 16;
  image.x0 = p.x0, image.y0 = p.y0, image.x1 = p.x1, image.y1 = p.y1;
  image.values = texels.data();
  EXPECT_EQ(make_density_max_mip(image, mip), Status::kOk);
  std::vector<QueryParams> out(3, p);
  out[1].density.kind = QueryDensity::Kind::kCallback, out[1].density.callback = wave;
  out[1].density.callback_max = 1;
  out[2].density.kind = QueryDensity::Kind::kImage, out[2].density.image = &image;
  return out;
}

using Bits = std::tuple<std::int64_t, std::int64_t, std::uint32_t, std::uint32_t, double, double>;
std::vector<Bits> sorted_bits(const std::vector<QueryPoint>& points) {
  std::vector<Bits> out;
  for (const QueryPoint& q : points)
    out.emplace_back(q.id.tile_x, q.id.tile_y, q.id.rank, q.id.depth, q.x, q.y);
  std::sort(out.begin(), out.end());
  return out;
}

TEST_P(DescentTest, RandomPartitionsAndThreadsGiveTheSameBitsAtDepthsZeroOneAndThree) {
  // Depths 0, 1 and 3 of the small set (m = 4: depth d's points appear past N_top · 16^(d-1) points per
  // tile), at the origin and 10^9 units from it, for a constant density, a callback and an image: a random
  // grid of cuts, the parts queried through a small buffer, gives the whole region's points bit for bit,
  // and four threads querying at once give a single thread's.
  std::mt19937 rng(7);
  for (const double n : {0.78, 9.0, 256.0 * 5}) {
    const double per_tile = n * top();
    for (const double offset : {0.0, 1e9}) {
      const double side = std::sqrt(12000 / per_tile);
      QueryParams p = uniform(0, per_tile);
      p.x0 = offset + 0.31 * side, p.y0 = -offset - 0.47 * side, p.x1 = p.x0 + side, p.y1 = p.y0 + side;
      p.origin_x = offset, p.origin_y = -offset;
      DensityImageView image;
      std::vector<float> texels, mip;
      for (const QueryParams& whole : three_densities(p, image, texels, mip)) {
        const std::string what = std::to_string(per_tile) + " points per tile, offset " +
                                 std::to_string(offset) + ", density kind " +
                                 std::to_string(int(whole.density.kind));
        const std::vector<QueryPoint> all = query(whole);
        const std::vector<Bits> expected = sorted_bits(all);
        ASSERT_GT(expected.size(), 3000u) << what;
        std::uint32_t deepest = 0;
        for (const QueryPoint& q : all) deepest = std::max(deepest, q.id.depth);
        EXPECT_EQ(deepest, n < 1 ? 0u : n < 16 ? 1u : 3u) << what;
        std::vector<QueryPoint> parts;
        for (const QueryParams& part : testing::random_grid_parts(whole, 3, rng)) {
          const std::vector<QueryPoint> got = query(part, 61);
          parts.insert(parts.end(), got.begin(), got.end());
        }
        EXPECT_TRUE(sorted_bits(parts) == expected) << what;
        std::vector<std::vector<QueryPoint>> threaded(4);
        std::vector<std::thread> threads;
        for (auto& out : threaded) threads.emplace_back([&out, &whole] { out = query(whole, 509); });
        for (std::thread& t : threads) t.join();
        for (const auto& out : threaded) {
          ASSERT_EQ(out.size(), all.size()) << what;
          for (std::size_t i = 0; i < all.size(); ++i)
            ASSERT_TRUE(out[i].id == all[i].id && out[i].x == all[i].x && out[i].y == all[i].y) << what;
        }
      }
    }
  }
}

TEST_P(DescentTest, RaisingTheScaleThroughDepthFourKeepsEveryPoint) {
  // Zoom coherence from depth 3 into depth 4 (whose points appear past N_top · 16^3 points per tile; here
  // 0.7 to 2.5 times that, ×1.1 a step) on a fixed region, for a constant density and a callback: every
  // id emitted at one scale at least two spacings inside the region (a point glides less than one per
  // step) is emitted at the next.
  const double first = top() * 4096 * 0.7, last = top() * 4096 * 2.5;
  QueryParams p = uniform(0, first);
  p.x0 = 0.4, p.y0 = 0.2, p.x1 = p.x0 + std::sqrt(3000 / first), p.y1 = p.y0 + std::sqrt(3000 / first);
  for (const bool constant : {true, false}) {
    if (!constant) p.density.kind = QueryDensity::Kind::kCallback, p.density.callback = wave;
    p.density.callback_max = 1;
    std::set<Key> before;
    std::uint32_t deepest = 0;
    for (double scale = first; scale < last; scale *= 1.1) {
      p.scale = scale;
      std::set<Key> now, inner;
      const double margin = 2 / std::sqrt(0.1 * scale);  // two spacings at density 0.1, the least here
      for (const QueryPoint& q : query(p)) {
        now.insert(key(q.id)), deepest = std::max(deepest, q.id.depth);
        if (q.x > p.x0 + margin && q.x < p.x1 - margin && q.y > p.y0 + margin && q.y < p.y1 - margin)
          inner.insert(key(q.id));
      }
      std::size_t lost = 0;
      for (const Key& k : before) lost += now.count(k) == 0;
      EXPECT_EQ(lost, 0u) << "scale " << scale << (constant ? " constant" : " callback");
      EXPECT_GT(inner.size(), 500u);
      before = std::move(inner);
    }
    EXPECT_EQ(deepest, 4u);
  }
}

TEST_P(DescentTest, BelowTheTopTheDescentGivesTheOrdinaryPathsBits) {
  // The same density (a ramp up to 1, 0.78 N_top points per tile at most) with a bound of 1
  // (every tile takes the ordinary path) and of 50 (every tile takes the descent, which emits the same
  // points: none is past N_top): the same points, ids and position bits (in id order: the ordinary path
  // gives a tile the region meets a small part of cell by cell, the descent in rank order).
  QueryParams p = uniform(0, 0.78 * top());
  p.x0 = -1.3, p.y0 = 0.2, p.x1 = 2.1, p.y1 = 1.9, p.origin_x = 0.6, p.origin_y = -0.3;
  p.density.kind = QueryDensity::Kind::kCallback, p.density.callback = ramp, p.density.callback_max = 1;
  auto by_id = [](std::vector<QueryPoint> points) {
    std::sort(points.begin(), points.end(),
              [](const QueryPoint& a, const QueryPoint& b) { return key(a.id) < key(b.id); });
    return points;
  };
  const std::vector<QueryPoint> ordinary = by_id(query(p));
  p.density.callback_max = 50;
  const std::vector<QueryPoint> descended = by_id(query(p));
  ASSERT_EQ(ordinary.size(), descended.size());
  EXPECT_GT(ordinary.size(), 500u);
  for (std::size_t i = 0; i < ordinary.size(); ++i) {
    ASSERT_TRUE(ordinary[i].id == descended[i].id) << i;
    ASSERT_EQ(ordinary[i].x, descended[i].x) << i;
    ASSERT_EQ(ordinary[i].y, descended[i].y) << i;
  }
}

TEST_P(DescentTest, ClassesPastTheTopLevelTakeTheirShares) {
  // Three constant classes (1 : 2 : 4) over 3 × 3 tiles at 3 and 20 times N_top: each class gets its
  // share of the union's points. A parent's points, classed by their own thresholds, already fill the
  // first classes; the sub-points that appear on their own come after them in the union's order and are
  // classed by the threshold they appear at. Measured: within 2.3% (these quickly baked sets' own counts
  // per tile stray by up to 1%); classed by their subtile thresholds, class 0 had 17–30% too many.
  for (const double n : {3.0, 20.0}) {
    ClassQueryParams q;
    q.query.x1 = q.query.y1 = 3, q.query.scale = n * top() / 7, q.query.mode = QueryMode::kSmooth;
    q.class_count = 3;
    for (int k = 0; k < 3; ++k) q.classes[k].constant = double(1 << k);
    std::vector<QueryPoint> out(1 << 20);
    std::vector<std::uint8_t> classes(out.size());
    std::size_t written = 0;
    QueryCursor cursor;
    ASSERT_EQ(query_classes(small_set(), q, out.data(), classes.data(), out.size(), &written, &cursor),
              Status::kOk);
    double count[3] = {};
    for (std::size_t i = 0; i < written; ++i) count[classes[i]] += 1;
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(count[k] / (double(written) * (1 << k) / 7), 1.0, 0.04) << n << " N_top, class " << k;
  }
}

TEST_P(DescentTest, DeepQueriesAllocateNothing) {
  const Tileset& t = small_set();  // baked and loaded outside the measured window
  QueryParams p = uniform(0.2, top() * 16 * 40);
  p.density.kind = QueryDensity::Kind::kCallback, p.density.callback = ramp, p.density.callback_max = 1;
  std::vector<QueryPoint> buffer(64);  // small: the cursor resumes inside subtiles
  const long before = testing::allocations();
  std::size_t total = 0, written = 0;
  QueryCursor cursor;
  while (query_points(t, p, buffer.data(), buffer.size(), &written, &cursor) == Status::kBufferFull)
    total += written;
  total += written;
  EXPECT_EQ(testing::allocations(), before);
  EXPECT_GT(total, 2000u);  // about 3,750 points, down to depth 3
}

TEST_P(DescentTest, PositionsFarFromTheWorldOriginKeepTheirPrecision) {
  // At 10^12 world units a double's step is 2^-13 ≈ 1.2e-4, about the spacing at depth 4 here: positions
  // summed in world units would land on that grid. Relative to the origin they do not.
  const double far = 1e12, per_tile = top() * 65536 * 0.9;
  QueryParams p = uniform(0, per_tile);
  p.x0 = p.origin_x = far, p.y0 = p.origin_y = far;
  p.x1 = p.y1 = far + std::sqrt(512 / top()) / 64;  // about 7,000 points
  const std::vector<QueryPoint> points = query(p);
  ASSERT_GT(points.size(), 5000u);
  std::size_t off_grid = 0;
  for (const QueryPoint& q : points) off_grid += q.x != std::ldexp(std::round(std::ldexp(q.x, 13)), -13);
  EXPECT_GT(double(off_grid), 0.99 * double(points.size()));
  double closest = HUGE_VAL;
  for (std::size_t i = 0; i < points.size(); ++i)
    for (std::size_t j = i + 1; j < points.size(); ++j)
      closest = std::min(closest, std::hypot(points[i].x - points[j].x, points[i].y - points[j].y));
  EXPECT_GT(closest * std::sqrt(per_tile), 0.2);  // no two points fall together
}

}  // namespace
}  // namespace kdm
