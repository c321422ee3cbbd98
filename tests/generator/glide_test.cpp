// The glide track: keyframes from the baker, its paths kept apart, format round trips, and smooth queries
// (same ids as stable ones, continuous and bounded motion, no close pairs at any density, chunk
// consistency, better blue noise between levels).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "bake/glide_paths.h"
#include "bake/keyframes.h"
#include "kdm/analysis/common.h"
#include "kdm/analysis/empty_circles.h"
#include "kdm/analysis/nearest_neighbour.h"
#include "kdm/analysis/periodogram.h"
#include "kdm/generator/bake.h"
#include "kdm/runtime/query.h"

namespace kdm::gen {
namespace {

constexpr const char* kSmallRecipe =
    "seed 3\nlevels 2\nbase_points 32\nsweeps 30\nkeyframes 16\nglide_sweeps 30\n";

Tileset baked(const std::string& recipe) {
  std::vector<std::uint8_t> bytes;
  EXPECT_EQ(encode_tileset(bake_tileset(BakeRecipe::parse(recipe)), bytes), Status::kOk);
  Tileset t;
  EXPECT_EQ(Tileset::load_memory(bytes.data(), bytes.size(), t), Status::kOk);
  return t;
}

// A small gliding set: two levels (32 and 128 points per tile), 16 keyframes per level between them
// (about 2 s).
const Tileset& small_set() {
  static const Tileset set = baked(kSmallRecipe);
  return set;
}

using Key = std::tuple<std::int64_t, std::int64_t, std::uint32_t>;

std::map<Key, QueryPoint> query(const Tileset& set, double x0, double y0, double x1, double y1, double scale,
                                QueryMode mode, const QueryDensity& density = {}) {
  QueryParams q;
  q.x0 = x0, q.y0 = y0, q.x1 = x1, q.y1 = y1;
  q.scale = scale;
  q.mode = mode;
  q.density = density;
  std::vector<QueryPoint> buffer(1 << 16);
  QueryCursor cursor;
  std::map<Key, QueryPoint> out;
  for (;;) {
    std::size_t n = 0;
    const Status s = query_points(set, q, buffer.data(), buffer.size(), &n, &cursor);
    EXPECT_TRUE(s == Status::kOk || s == Status::kBufferFull) << status_message(s);
    for (std::size_t i = 0; i < n; ++i)
      out[{buffer[i].id.tile_x, buffer[i].id.tile_y, buffer[i].id.rank}] = buffer[i];
    if (s != Status::kBufferFull) break;
  }
  return out;
}

TEST(GlideTest, KeyframesStepGeometricallyThroughEveryLevel) {
  const std::vector<std::uint32_t> nominal = {32, 128, 512, 2048};
  const std::vector<std::uint32_t> k = make_keyframe_nominal(nominal, 8);
  ASSERT_EQ(k.size(), 1 + 3 * 8u);
  for (std::size_t level = 0; level < nominal.size(); ++level) EXPECT_EQ(k[8 * level], nominal[level]);
  for (std::size_t g = 1; g < k.size(); ++g)  // 4^(1/8) = 1.189 per step, up to the rounding to whole points
    EXPECT_NEAR(double(k[g]) / k[g - 1], std::pow(4.0, 1.0 / 8), 0.02) << g;
  EXPECT_TRUE(make_keyframe_nominal(nominal, 0).empty());
}

TEST(GlideTest, BakedTrackHasAnOffsetPerPointAndKeyframeAndRoundTrips) {
  const TilesetData& d = small_set().data();
  ASSERT_TRUE(small_set().has_glide_track());
  const std::vector<std::uint32_t> expected = make_keyframe_nominal({32, 128}, 16);
  EXPECT_EQ(std::vector<std::uint32_t>(d.keyframe_nominal.begin(), d.keyframe_nominal.end()), expected);
  for (const Tile& tile : d.tiles) {
    std::size_t pairs = 0;
    for (std::size_t g = 0; g < d.keyframe_nominal.size(); ++g) pairs += d.offsets_at_keyframe(tile, g);
    EXPECT_EQ(tile.glide.size(), 2 * pairs);
  }
  // Some points glide, none farther than the offsets' range: 3.97 spacings of the first keyframe.
  EXPECT_GT(small_set().glide_reach(), 0.0);
  EXPECT_LE(small_set().glide_reach(), 127 / (kGlideUnitsPerSpacing * std::sqrt(32.0)));
  std::vector<std::uint8_t> bytes;
  ASSERT_EQ(encode_tileset(d, bytes), Status::kOk);
  TilesetData back;
  ASSERT_EQ(decode_tileset(bytes.data(), bytes.size(), back), Status::kOk);
  EXPECT_TRUE(back == d);
}

TEST(GlideTest, SmoothModeEmitsTheStableIdsAtEveryDensity) {
  for (double scale : {20.0, 32.0, 40.0, 64.0, 100.0, 128.0}) {
    const auto stable = query(small_set(), 0, 0, 6, 6, scale, QueryMode::kStable);
    // A margin: points near the region's edge may glide out of it or into it.
    const auto smooth = query(small_set(), -1, -1, 7, 7, scale, QueryMode::kSmooth);
    std::size_t moved = 0;
    for (const auto& [id, p] : stable) {
      const auto it = smooth.find(id);
      ASSERT_NE(it, smooth.end()) << "scale " << scale;
      moved += it->second.x != p.x || it->second.y != p.y;
    }
    if (scale > 32) {  // keyframes were relaxed
      EXPECT_GT(moved, stable.size() / 2) << "scale " << scale;
    }
  }
}

TEST(GlideTest, PointsGlideContinuouslyAcrossKeyframes) {
  // Around every keyframe and between them, a ±0.01% change of density moves no point by more than a
  // hundredth of a point spacing: positions are continuous in the density. Keyframes are 19% apart and a
  // point moves at most about a spacing between two, so the bound is ~0.002; a jump would be ~0.1–1.
  const TilesetData& d = small_set().data();
  for (std::size_t g = 0; g + 1 < d.keyframe_nominal.size(); ++g)
    for (double at : {0.0, 0.5}) {
      const double scale = d.keyframe_nominal[g] + at * (d.keyframe_nominal[g + 1] - d.keyframe_nominal[g]);
      const auto a = query(small_set(), -1, -1, 5, 5, scale * (1 - 1e-4), QueryMode::kSmooth);
      const auto b = query(small_set(), -1, -1, 5, 5, scale * (1 + 1e-4), QueryMode::kSmooth);
      const double spacing = 1 / std::sqrt(scale);
      double worst = 0;
      for (const auto& [id, p] : a) {
        if (const auto it = b.find(id); it != b.end())
          worst = std::max(worst, std::hypot(it->second.x - p.x, it->second.y - p.y) / spacing);
      }
      EXPECT_LT(worst, 1e-2) << "keyframe " << g << " + " << at;
    }
}

// Keyframe g's offset of `rank` in `tile`, in tile sides; `start` = where keyframe g's offsets begin.
void offset_at(const TilesetData& d, const Tile& tile, std::size_t start, std::size_t g, std::uint32_t rank,
               double& x, double& y) {
  x = tile.glide[2 * (start + rank)] * d.glide_unit(g);
  y = tile.glide[2 * (start + rank) + 1] * d.glide_unit(g);
}

TEST(GlideTest, NoPointMovesMoreThanTheCapBetweenKeyframes) {
  // keyframes.cpp caps a step at 0.55 d_hex of the later keyframe; each stored offset is rounded by up to
  // half a unit per axis (1/64 of a spacing 1/√K, 0.0145 d_hex), so a stored step, the difference of two
  // offsets, can exceed it by 2 · √2 · 0.0145 = 0.041.
  const TilesetData& d = small_set().data();
  double worst = 0;
  for (const Tile& tile : d.tiles) {
    std::size_t start = 0;
    for (std::size_t g = 1; g < d.keyframe_nominal.size(); ++g) {
      const std::size_t before = start;
      start += d.offsets_at_keyframe(tile, g - 1);
      const double spacing = analysis::hex_spacing(d.keyframe_nominal[g]);
      for (std::uint32_t i = 0; i < d.offsets_at_keyframe(tile, g - 1); ++i) {
        double ax, ay, bx, by;
        offset_at(d, tile, before, g - 1, i, ax, ay);
        offset_at(d, tile, start, g, i, bx, by);
        worst = std::max(worst, std::hypot(bx - ax, by - ay) / spacing);
      }
    }
  }
  EXPECT_GT(worst, 0.3);  // points do move
  EXPECT_LE(worst, 0.55 + 0.041);
}

// The closest pair in d_hex, over 64 densities per ×4 of `set`'s first ×4 (every keyframe, the quarters
// between them and more), 6×6 tiles.
double closest_pair_at_any_density(const Tileset& set) {
  double worst = HUGE_VAL;
  for (int i = 0; i <= 64; ++i) {
    const double scale = 32 * std::pow(4.0, i / 64.0);
    std::vector<double> coords;
    for (const auto& [id, p] : query(set, 0, 0, 6, 6, scale, QueryMode::kSmooth))
      coords.insert(coords.end(), {p.x / 6, p.y / 6});
    const analysis::NNStats nn = analysis::nn_stats(coords, 2, /*torus=*/false);
    worst = std::min(worst, nn.dmin);
  }
  return worst;
}

TEST(GlideTest, NoTwoPointsComeCloserThanAThirdOfTheSpacingAtAnyDensity) {
  // Against the bar of 0.3 d_hex (the path separation aims at 0.4). Without it, a point entering next to
  // one still moving away came as close as 0.2 d_hex, some at every few densities.
  EXPECT_GE(closest_pair_at_any_density(small_set()), 0.3);
}

TEST(GlideTest, ConsensusMovesAreKeptApartWithoutTheDropPass) {
  // Means of moves that each kept the points apart can bring two points together; the baker parts them
  // again, so glide_separation has nothing to remove. Measured with the drop pass off: seed 3 0.376 d_hex
  // (0.222 with the means left unparted), seeds 4 and 5 0.385 and 0.388.
  const Tileset set = baked(std::string(kSmallRecipe) + "glide_consensus 128\nglide_separation 0\n");
  EXPECT_GE(closest_pair_at_any_density(set), 0.3);
}

TEST(GlidePathsTest, ClosestApproachOfTwoPathsOnATorus) {
  // Two points swapping places through each other meet half-way; one shown only from 0.75 on meets the
  // other there, 0.1 apart; across the torus seam the short way round counts.
  GlidePath p{0.4, 0.5, 0.6, 0.5}, q{0.6, 0.5, 0.4, 0.5};
  double t;
  EXPECT_NEAR(closest_approach(p, q, 1, 1, t), 0.0, 1e-12);
  EXPECT_NEAR(t, 0.5, 1e-12);
  q.appear = 0.75;
  EXPECT_NEAR(closest_approach(p, q, 1, 1, t), 0.1, 1e-12);
  EXPECT_NEAR(t, 0.75, 1e-12);
  const GlidePath a{0.98, 0.5, 0.98, 0.5}, b{0.01, 0.5, 0.01, 0.5};
  EXPECT_NEAR(closest_approach(a, b, 1, 1, t), 0.03, 1e-12);
}

TEST(GlidePathsTest, SeparatingMovesTheMovableEndsOnly) {
  // The swapping pair again, with only the later ends movable: afterwards they pass at least the radius
  // apart, and the earlier ends did not move. A fixed pair too close from its start is left alone.
  std::vector<GlidePath> paths = {
      {0.4, 0.5, 0.6, 0.5}, {0.6, 0.5, 0.4, 0.5}, {0.1, 0.1, 0.1, 0.1}, {0.11, 0.1, 0.11, 0.1}};
  paths[0].move_b = paths[1].move_b = true;
  const double r = 0.05;
  const std::size_t left = separate_paths(
      paths, 1, 1, [&](double) { return r; }, r, [](GlidePath&, std::size_t) {}, 24);
  EXPECT_EQ(left, 0u);
  double t;
  EXPECT_GE(closest_approach(paths[0], paths[1], 1, 1, t), r * 0.999);
  EXPECT_EQ(paths[0].ax, 0.4);
  EXPECT_EQ(paths[1].ax, 0.6);
  EXPECT_EQ(paths[2].bx, 0.1);
  EXPECT_EQ(paths[3].bx, 0.11);
  // An entering point whose entry may move: it need not come near the other at all.
  std::vector<GlidePath> entering = {{0.5, 0.5, 0.5, 0.5}, {0.5, 0.51, 0.5, 0.7}};
  entering[1].appear = 0.2, entering[1].move_a = entering[1].move_b = true;
  separate_paths(
      entering, 1, 1, [&](double) { return r; }, r, [](GlidePath&, std::size_t) {}, 24);
  EXPECT_GE(closest_approach(entering[0], entering[1], 1, 1, t), r * 0.999);
  EXPECT_EQ(entering[0].ax, 0.5);
}

double ramp(void*, double x, double) {
  return 0.2 + 0.8 * std::clamp(x / 6, 0.0, 1.0);
}

TEST(GlideTest, SmoothQueriesAreChunkConsistent) {
  QueryDensity varying;
  varying.kind = QueryDensity::Kind::kCallback;
  varying.callback = ramp;
  varying.callback_max = 1;
  for (const QueryDensity& density : {QueryDensity{}, varying}) {
    const auto whole = query(small_set(), 0, 0, 6, 6, 77, QueryMode::kSmooth, density);
    std::map<Key, QueryPoint> parts;
    for (const auto& [x0, y0, x1, y1] :
         {std::tuple{0.0, 0.0, 2.37, 6.0}, {2.37, 0.0, 6.0, 3.71}, {2.37, 3.71, 6.0, 6.0}}) {
      for (const auto& [id, p] : query(small_set(), x0, y0, x1, y1, 77, QueryMode::kSmooth, density)) {
        EXPECT_TRUE(parts.emplace(id, p).second) << "a point in two parts";
      }
    }
    ASSERT_EQ(parts.size(), whole.size());
    for (const auto& [id, p] : whole) {
      const QueryPoint& q = parts.at(id);
      EXPECT_EQ(q.x, p.x);  // bit for bit
      EXPECT_EQ(q.y, p.y);
    }
  }
}

struct Quality {
  double davg, low_p;
};

Quality quality(QueryMode mode, double scale) {
  const double side = 16;
  std::vector<double> coords;
  for (const auto& [id, p] : query(small_set(), 0, 0, side, side, scale, mode))
    coords.insert(coords.end(), {p.x / side, p.y / side});
  const analysis::NNStats nn = analysis::nn_stats(coords, 2, /*torus=*/false);
  const analysis::SpectrumStats s = analysis::spectrum_stats(analysis::periodogram(coords, 2, 0.6));
  return {nn.davg, s.low_p};
}

TEST(GlideTest, SmoothIsBetterBlueNoiseThanStableBetweenLevels) {
  // Half-way (in log density) between the levels (a keyframe) and between two keyframes, 16×16 tiles,
  // 16,000–18,000 points. Measured with this recipe: stable δavg .71 and .73, lowP .11; smooth δavg .85
  // and .82, lowP .02 and .06. The bar (δavg at least .08 better, lowP lower) leaves room for other seeds.
  for (double scale : {64.0, 70.0}) {
    const Quality stable = quality(QueryMode::kStable, scale), smooth = quality(QueryMode::kSmooth, scale);
    std::printf("scale %g: stable davg %.3f lowP %.3f, smooth davg %.3f lowP %.3f\n", scale, stable.davg,
                stable.low_p, smooth.davg, smooth.low_p);
    EXPECT_GT(smooth.davg, stable.davg + 0.08) << scale;
    EXPECT_LT(smooth.low_p, stable.low_p) << scale;
  }
}

// Empty circles wider than 0.85 d_hex per 10^5 points of a smooth query over side × side tiles, and δavg.
std::pair<double, double> holes_and_davg(const Tileset& set, double scale, double side) {
  tools::PointSet points;
  points.dim = 2;
  for (const auto& [id, p] : query(set, 0, 0, side, side, scale, QueryMode::kSmooth))
    points.coords.insert(points.coords.end(), {p.x / side, p.y / side});
  analysis::EmptyCircleOptions o;
  o.torus = false;
  const analysis::EmptyCircles e = analysis::empty_circles({points}, o);
  return {1e5 * double(e.over_085) / double(points.size()), analysis::nn_stats(points.coords, 2, false).davg};
}

TEST(GlideTest, ConsensusMovesLeaveFewerHolesThanOneRunsMoves) {
  // A shared patch relaxed on its own run's torus moves away from neighbours other tiles do not show, and
  // leaves a hole there in them. Every keyframe and half-way density of the small set, 16 × 16 tiles
  // (8,000–33,000 points).
  const Tileset consensus = baked(std::string(kSmallRecipe) + "glide_consensus 128\n");
  double holes[2] = {0, 0}, worst_davg[2] = {1, 1};
  const Tileset* sets[2] = {&small_set(), &consensus};
  for (int i = 0; i <= 32; ++i)
    for (int k = 0; k < 2; ++k) {
      const auto [h, davg] = holes_and_davg(*sets[k], 32 * std::pow(4.0, i / 32.0), 16);
      holes[k] += h / 33, worst_davg[k] = std::min(worst_davg[k], davg);
    }
  std::printf("holes above 0.85 d_hex per 1e5 (mean), worst davg: one run %.1f %.3f, consensus %.1f %.3f\n",
              holes[0], worst_davg[0], holes[1], worst_davg[1]);
  ASSERT_GE(holes[0], 100.0);  // the control has holes: the test could fail
  EXPECT_LE(holes[1], holes[0] / 2);
  EXPECT_GE(worst_davg[1], worst_davg[0] - 0.01);
}

TEST(GlideTest, CornerConsensusRemovesMostOfTheHoles) {
  // Moving only the corner patches by consensus (the edges and interiors on their own runs) removes most
  // of the holes that one run's moves leave in the tiles that show a corner in another context. A set of
  // 128 and 512 points per tile, its keyframe and half-way densities, 8 × 8 tiles (8,000–33,000 points).
  const std::string recipe = "seed 3\nlevels 2\nbase_points 128\nsweeps 30\nkeyframes 8\nglide_sweeps 30\n";
  const Tileset sets[2] = {baked(recipe), baked(recipe + "glide_corner_consensus 512\n")};
  double holes[2] = {0, 0}, worst_davg[2] = {1, 1};
  for (int i = 0; i <= 16; ++i)
    for (int k = 0; k < 2; ++k) {
      const auto [h, davg] = holes_and_davg(sets[k], 128 * std::pow(4.0, i / 16.0), 8);
      holes[k] += h / 17, worst_davg[k] = std::min(worst_davg[k], davg);
    }
  std::printf("holes above 0.85 d_hex per 1e5 (mean), worst davg: one run %.1f %.3f, corners %.1f %.3f\n",
              holes[0], worst_davg[0], holes[1], worst_davg[1]);
  // Measured with seeds 3, 4 and 5: 421 / 230 / 309 with one run's moves, 164 / 130 / 144 with corner
  // consensus (0.39–0.56 of them; every kind by consensus: 170 / 150 / 99); worst δavg within +0.005 of
  // the control. The bar leaves room for other seeds.
  ASSERT_GE(holes[0], 100.0);  // the control has holes: the test could fail
  EXPECT_LE(holes[1], 0.7 * holes[0]);
  EXPECT_GE(worst_davg[1], worst_davg[0] - 0.01);
}

TEST(GlideTest, BakeProgressCountsConsensusAndEndsAtOne) {
  // The progress bar weighs each keyframe by the tori it relaxes, consensus included, so the pyramid's
  // share of the bar shrinks as consensus grows; the fractions reported rise from 0 to exactly 1.
  const std::size_t keyframes = make_keyframe_nominal({32, 128}, 16).size();  // one report each, last
  double pyramid_share[3] = {0, 0, 0};
  int i = 0;
  for (const char* keys : {"", "glide_corner_consensus 128\n", "glide_consensus 128\n"}) {
    std::vector<double> seen;
    bake_tileset(BakeRecipe::parse(std::string(kSmallRecipe) + keys), 2,
                 [&](double f) { seen.push_back(f); });
    ASSERT_GT(seen.size(), keyframes) << keys;
    EXPECT_GE(seen.front(), 0.0) << keys;
    EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end())) << keys;
    EXPECT_NEAR(seen.back(), 1.0, 1e-9) << keys;
    pyramid_share[i++] = seen[seen.size() - keyframes - 1];
  }
  EXPECT_GT(pyramid_share[0], pyramid_share[1]);
  EXPECT_GT(pyramid_share[1], pyramid_share[2]);
}

TEST(GlideTest, LateArrivalsFindNoPlaceMadeBeforeTheyAppear) {
  // Late in a keyframe interval the points about to appear find their room made by neighbours that glided
  // towards a keyframe relaxed with them; left out of that relaxation (glide_late), their room is made in
  // the next interval, after they appear. 7/8 of the way through every interval of the small set, and at
  // every keyframe, 16 × 16 tiles (8,000–33,000 points).
  const std::string recipe = std::string(kSmallRecipe) + "glide_consensus 128\n";
  const Tileset sets[2] = {baked(recipe), baked(recipe + "glide_late 0.75\n")};
  double late_holes[2] = {0, 0}, keyframe_davg[2] = {0, 0};
  const std::vector<std::uint32_t> k = make_keyframe_nominal({32, 128}, 16);
  for (std::size_t g = 0; g + 1 < k.size(); ++g)
    for (int s = 0; s < 2; ++s) {
      late_holes[s] += holes_and_davg(sets[s], k[g] + 0.875 * (k[g + 1] - k[g]), 16).first / 16;
      keyframe_davg[s] += holes_and_davg(sets[s], k[g + 1], 16).second / 16;
    }
  std::printf(
      "late holes above 0.85 d_hex per 1e5 (mean), keyframe davg (mean): %.1f %.3f, glide_late %.1f %.3f\n",
      late_holes[0], keyframe_davg[0], late_holes[1], keyframe_davg[1]);
  // Measured with seeds 3, 4 and 5: 930 / 1,314 / 1,051 without, 188 / 9 / 38 with (at most a fifth); the
  // keyframes' δavg .873 / .880 / .878 against .858 / .867 / .863 (0.013–0.015 lower: the late arrivals
  // are crowded there, their room still to be made).
  ASSERT_GE(late_holes[0], 300.0);  // the control has them: the test could fail
  EXPECT_LE(late_holes[1], late_holes[0] / 3);
  EXPECT_GE(keyframe_davg[1], keyframe_davg[0] - 0.025);
}

}  // namespace
}  // namespace kdm::gen
