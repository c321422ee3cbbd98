// The quality targets for what the runtime emits from the built-in tile set (16 corner tiles, levels of
// 32·4^k points per tile): uniform density over 32×32 tiles at complete levels and between them (δavg,
// NN1%, lowP, links across tile edges, periodicity at the tile-lattice frequencies), and spatially varying
// densities (a step, a 1:1000 radial map and a photograph: window z-scores and global bias). The ramp is
// in query_test.cpp.
//
// Every figure is printed. A target that the set meets is asserted as stated. A bar
// it does not meet (the periodicity ratio everywhere; δavg and lowP between some levels) is asserted at the
// measured value plus a margin of several times its spread, so a regression fails; each such place names
// the target and the measured value. The spreads quoted below come from the same measurement on 7
// disjoint 32×32-tile regions (origins (0,0), (32,0), (0,32), (32,32), (1000,−2000), (−64,96),
// (12345,678)); the test itself uses [0,32)², the region of docs/quality.md's command. With only 16 tiles
// every region shows every corner configuration many times, so the spreads are small.
//
// Procedure, as `kdm query --rect 0,0,32,32 --scale S -o u.txt && kdm analyze u.txt --box --tile-size 0.03125
// --fmax 0.6 -o a` does it: coordinates normalised to the rectangle, NN statistics with box distances
// (the assembled region is not a torus: the vertex colours along its left and right edges are independent
// hashes, so `kdm analyze`'s default --torus would join points across the domain edge that are no
// neighbours in the tiling; measured at complete levels, it counts such links as seam links and drags seam
// NN1% to .53–.60 of d_hex, 0.83 × interior NN1%, under the bar of 0.9), the periodogram on integer
// frequencies of the unit square up to f = 0.6 (docs/quality.md's fmax; it covers lowP's band f < 0.5 and the
// first lattice rings), the periodicity ratio over the lattice frequencies k = 32·(i, j) inside those rings.
// On integer frequencies a uniform density has no window leakage (its transform vanishes there), so a box
// set's lowP only gains the edge effects, which are small: complete levels give lowP .006–.009.
//
// Spectra cost O(n · kmax²) with kmax ≈ 0.6·√n, i.e. O(n²): 0.1 s for 32 points per tile (33k points),
// 1.7 s for 128 (131k), 25–50 s for 512 (524k) on this 2-core machine. The default run computes them for
// regions of up to kSpectrumBudget points (128 points per tile); -DKDM_SLOW_TESTS=ON computes them up to
// 2^20 points (896 points per tile; about 3 minutes in all). Beyond that (2.1M points at 2048 per tile:
// 15 minutes or more) they are never computed. NN statistics are cheap and cover every density up to
// 2048 points per tile in both runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "image_io.h"
#include "kdm/analysis/common.h"
#include "kdm/analysis/density.h"
#include "kdm/analysis/nearest_neighbour.h"
#include "kdm/analysis/periodogram.h"
#include "kdm/analysis/tiling.h"
#include "kdm/runtime/query.h"

namespace kdm {
namespace {

#ifdef KDM_SLOW_TESTS
constexpr std::size_t kSpectrumBudget = std::size_t(1) << 20;
#else
constexpr std::size_t kSpectrumBudget = 150000;
#endif
constexpr int kTiles = 32;          // region side in tiles (at least 32×32)
constexpr double kFmax = 0.6;       // periodogram limit, as in docs/quality.md's command
constexpr double kSeamRatio = 0.9;  // target: NN1% of links across tile edges ≥ 0.9 × interior NN1%

/// Every point of `q`, in the query's fixed order.
std::vector<QueryPoint> query_all(const QueryParams& q) {
  std::vector<QueryPoint> out, buffer(1 << 16);
  QueryCursor cursor;
  for (;;) {
    std::size_t written = 0;
    const Status s = query_points(Tileset::builtin(), q, buffer.data(), buffer.size(), &written, &cursor);
    out.insert(out.end(), buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(written));
    if (s != Status::kBufferFull) {
      EXPECT_EQ(s, Status::kOk) << status_message(s);
      return out;
    }
  }
}

/// Positions (relative to the query origin, which is the rectangle's corner) divided by the rectangle's
/// sides, into [0,1)² as `kdm query` writes them.
std::vector<double> normalised(const std::vector<QueryPoint>& points, double w, double h) {
  std::vector<double> coords;
  coords.reserve(2 * points.size());
  for (const QueryPoint& p : points)
    coords.insert(coords.end(),
                  {std::min(p.x / w, std::nextafter(1.0, 0.0)), std::min(p.y / h, std::nextafter(1.0, 0.0))});
  return coords;
}

// One uniform density: its expected points per tile and the bars it is held to. Where the set meets the
// target, the bar is the target; elsewhere it is the measured value with a margin (see each table).
struct UniformCase {
  double points_per_tile;
  const char* what;
  double davg_min;         // δavg ≥
  double low_p_max;        // lowP ≤ (kNoSpectrum: too many points to compute the spectrum in any run)
  double periodicity_max;  // periodicity ratio ≤
};
constexpr double kNoSpectrum = -1;

struct UniformResult {
  std::size_t n = 0;
  analysis::NNStats nn, seam, interior;
  bool has_spectrum = false;
  double low_p = 0;
  analysis::PeriodicityResult periodicity;
};

UniformResult measure_uniform(double points_per_tile, bool spectrum) {
  QueryParams q;
  q.x1 = q.y1 = kTiles;
  q.scale = points_per_tile;  // tile_size 1: points per tile = points per unit area
  const std::vector<double> coords = normalised(query_all(q), kTiles, kTiles);
  UniformResult r;
  r.n = coords.size() / 2;
  const analysis::NearestNeighbours nn = analysis::nearest_neighbours(coords, 2, /*torus=*/false);
  const double spacing = analysis::hex_spacing(r.n);
  std::vector<double> all, seam, interior;
  for (double d : nn.distance) all.push_back(d / spacing);
  analysis::split_by_seam(coords, 2, nn, 1.0 / kTiles, seam, interior);
  r.nn = analysis::summarise_nn(all, 1.0);
  r.seam = analysis::summarise_nn(seam, 1.0);
  r.interior = analysis::summarise_nn(interior, 1.0);
  if (spectrum) {
    const analysis::Periodogram p = analysis::periodogram(coords, 2, kFmax);
    const analysis::SpectrumStats stats = analysis::spectrum_stats(p);
    r.has_spectrum = true;
    r.low_p = stats.low_p;
    r.periodicity = analysis::periodicity_ratio(p, stats, 1.0 / kTiles);
  }
  return r;
}

void check_uniform(const UniformCase& c) {
  const bool spectrum =
      c.low_p_max != kNoSpectrum && c.points_per_tile * kTiles * kTiles <= double(kSpectrumBudget);
  const UniformResult r = measure_uniform(c.points_per_tile, spectrum);
  const double seam_ratio = r.seam.nn1 / r.interior.nn1;
  std::printf(
      "%-22s %6.0f/tile %8zu points: δmin %.3f δavg %.4f NN1%% %.4f | seams %zu links δavg %.4f NN1%% %.4f, "
      "interior δavg %.4f NN1%% %.4f, ratio %.3f",
      c.what, c.points_per_tile, r.n, r.nn.dmin, r.nn.davg, r.nn.nn1, r.seam.count, r.seam.davg, r.seam.nn1,
      r.interior.davg, r.interior.nn1, seam_ratio);
  if (r.has_spectrum)
    std::printf(" | lowP %.5f, periodicity ratio %.2f over %zu frequencies\n", r.low_p, r.periodicity.ratio,
                r.periodicity.frequencies);
  else if (c.low_p_max != kNoSpectrum)
    std::printf(" | spectrum skipped (over the default budget; -DKDM_SLOW_TESTS=ON)\n");
  else
    std::printf(" | spectrum not computed (too many points)\n");
  SCOPED_TRACE(std::string(c.what) + ", " + std::to_string(c.points_per_tile) + " points per tile");
  EXPECT_GT(r.n, 0.97 * c.points_per_tile * kTiles * kTiles);
  EXPECT_GE(r.nn.davg, c.davg_min);
  ASSERT_GT(r.seam.count, 1000u);
  EXPECT_GE(seam_ratio, kSeamRatio);
  if (r.has_spectrum) {
    EXPECT_LE(r.low_p, c.low_p_max);
    EXPECT_GT(r.periodicity.frequencies, 0u);
    EXPECT_LE(r.periodicity.ratio, c.periodicity_max);
  }
}

// The periodicity target is a ratio < 1.5 at the tile-lattice frequencies. NOT MET: every vertex of
// the tiling shows one of two corner patches (2 colours), so the lattice frequencies carry 47–119 times
// the radial mean (a strictly periodic tile would give about 1024, the number of tiles). Each case below
// asserts its measured ratio on [0,32)² × 1.1; over the 7 regions the ratio deviates from that value by
// −2.1% … +3.4% (at 32 points per tile 47.2 … 49.0 for 47.4; measured up to 128 points per tile).

TEST(RuntimeQualityTest, UniformAtCompleteLevels) {
  // Targets at complete levels: δavg ≥ .85 and lowP ≤ .01 — both met. Measured on [0,32)² (spread over
  // the 7 regions in brackets): δavg .876 [.8756–.8765] at 32 per tile, .878 [.8774–.8779] at 128, .878 at
  // 512, .876 at 2048; lowP .0090 [.0090–.0095] at 32, .0075 [.0074–.0076] at 128, .0063 at 512. Seam
  // NN1% / interior NN1% 1.04 at 32, 1.20 at 128, 1.03 at 512, 1.11 at 2048 (bar 0.9: met).
  // Periodicity ratio (bar 1.5, not met): 47.4 at 32, 71.5 at 128, 90.3 at 512.
  const UniformCase cases[] = {
      {32, "complete level 0", 0.85, 0.01, 1.1 * 47.4},
      {128, "complete level 1", 0.85, 0.01, 1.1 * 71.5},
      {512, "complete level 2", 0.85, 0.01, 1.1 * 90.3},
      {2048, "complete level 3", 0.85, kNoSpectrum, 0},
  };
  for (const UniformCase& c : cases) check_uniform(c);
}

TEST(RuntimeQualityTest, UniformBetweenLevels) {
  // Targets between levels: δavg ≥ .80 and lowP ≤ .1. Measured on [0,32)² a quarter, half and three
  // quarters of the way between levels k and k+1 (spread over the 7 regions: δavg ±.0007; lowP ±1.5%,
  // measured up to 128 points per tile):
  //   32→128:    δavg .690 / .739 / .810, lowP .120 / .118 / .107
  //   128→512:   δavg .692 / .748 / .816, lowP .088 / .101 / .102
  //   512→2048:  δavg .695 / .750 / .816, lowP .074 / – / – (1.3M and 1.7M points: no spectra)
  // δavg: met at three quarters only (a partly emitted level is less even than a complete one; kdm verify
  // gives .69/.75/.81 on the generator's 2×2 tori). NOT MET a quarter and half way: asserted at
  // measured − .01 (14× the spread).
  // lowP: met a quarter of the way from 128 to 512 and from 512 to 2048. NOT MET elsewhere (.101–.120: over
  // 32×32 tiles the spectrum reaches lower frequencies than on a 2×2 torus, where kdm verify measured ≤
  // .100): asserted at measured × 1.1 (7× the spread). Seam NN1% / interior NN1% 0.96–1.12 everywhere (bar
  // 0.9: met). Periodicity (bar 1.5, not met): 82–119, asserted at measured × 1.1.
  const UniformCase cases[] = {
      {56, "32→128, 1/4", 0.690 - 0.01, 1.1 * 0.120, 1.1 * 83.1},
      {80, "32→128, 1/2", 0.739 - 0.01, 1.1 * 0.118, 1.1 * 82.4},
      {104, "32→128, 3/4", 0.80, 1.1 * 0.107, 1.1 * 97.3},
      {224, "128→512, 1/4", 0.692 - 0.01, 0.1, 1.1 * 92.5},
      {320, "128→512, 1/2", 0.748 - 0.01, 1.1 * 0.101, 1.1 * 103.6},
      {416, "128→512, 3/4", 0.80, 1.1 * 0.102, 1.1 * 111.9},
      {896, "512→2048, 1/4", 0.695 - 0.01, 0.1, 1.1 * 118.5},
      {1280, "512→2048, 1/2", 0.750 - 0.01, kNoSpectrum, 0},
      {1664, "512→2048, 3/4", 0.80, kNoSpectrum, 0},
  };
  for (const UniformCase& c : cases) check_uniform(c);
}

// Density accuracy of the points of the world square [x0, x0 + side)² for `density` (world coordinates):
// window z-scores against `density_unit` (the same density on the unit square), with the expected total
// given (so the bias is measured, not normalised away).
analysis::DensityAccuracy accuracy(const QueryParams& q, const analysis::DensityFunction& density_unit,
                                   double expected_total, int raster = 0) {
  const double side = q.x1 - q.x0;
  const std::vector<double> coords = normalised(query_all(q), side, side);
  analysis::DensityOptions o;
  o.expected_total = expected_total;
  o.raster = raster;
  return analysis::density_accuracy(coords, 2, density_unit, o);
}

const char* mode_name(QueryMode mode) {
  return mode == QueryMode::kStable ? "stable" : "smooth";
}

constexpr QueryMode kModes[] = {QueryMode::kStable, QueryMode::kSmooth};

// Targets for spatially varying densities: window z-scores RMS ≤ 0.5 and global bias ≤ 0.5%.
constexpr double kRmsZ = 0.5, kBias = 0.005;

// The regions each density test runs on (world origins of its square): translating the region changes the
// corner colours, so each region sees a different arrangement of tiles. The spreads quoted are over these.
constexpr double kOrigins[][2] = {{0, 0},        {8, 0},    {0, 8},       {-40, 24},
                                  {1000, -3000}, {-77, -5}, {12345, 678}, {3, -300}};

double step_density(void* user, double x, double) {
  return x < *static_cast<const double*>(user) ? 0.1 : 1.0;
}

TEST(RuntimeQualityTest, FollowsADensityStep) {
  // A 1:10 step over 8×8 tiles, 3.5 tiles from the left edge (through the middle of a tile column, so
  // tiles are cut by it). Scale 6000: 600 points per tile on the left (between levels 2 and 3), 6000 on
  // the right (between levels 3 and 4). The step sits on a raster edge of the analysis (3.5/8 = 896/2048),
  // so the windows' expected counts are exact. 233,000 points, 8192 windows; measured: RMS z .310–.315,
  // bias −0.055%…+0.051% (bars 0.5 and 0.5%: met); smooth mode RMS z .281–.285, bias −0.058%…+0.044%.
  constexpr double kSide = 8, kStep = 3.5, kScale = 6000;
  for (const QueryMode mode : kModes) {
    for (const auto& origin : kOrigins) {
      double step_x = origin[0] + kStep;
      QueryParams q;
      q.mode = mode;
      q.x0 = q.origin_x = origin[0], q.y0 = q.origin_y = origin[1];
      q.x1 = q.x0 + kSide, q.y1 = q.y0 + kSide;
      q.scale = kScale;
      q.density.kind = QueryDensity::Kind::kCallback;
      q.density.callback = step_density;
      q.density.user = &step_x;
      q.density.callback_max = 1;
      const double expected = kScale * kSide * (kStep * 0.1 + (kSide - kStep) * 1.0);  // scale × ∫ρ
      const analysis::DensityAccuracy acc = accuracy(
          q, [](double x, double) { return x < kStep / kSide ? 0.1 : 1.0; }, expected, 2048);
      std::printf(
          "step 1:10, %s mode, at (%g, %g): %zu points (expected %.0f), %zu windows, RMS z %.3f, max |z| "
          "%.2f, "
          "bias %+.5f\n",
          mode_name(mode), origin[0], origin[1], acc.points, expected, acc.windows, acc.rms_z, acc.max_abs_z,
          acc.bias);
      EXPECT_LE(acc.rms_z, kRmsZ);
      EXPECT_LE(std::fabs(acc.bias), kBias);
    }
  }
}

// Queries a w×h density image spread over the side × side square at `origin` (bilinear between texels)
// and measures the emitted points against it, printing the figures under `label`.
analysis::DensityAccuracy image_accuracy(const char* label, const std::vector<float>& values, int w, int h,
                                         const double* origin, double side, double scale, double expected,
                                         QueryMode mode) {
  std::vector<float> mip;
  DensityImageView image;
  image.width = w, image.height = h;
  image.x0 = origin[0], image.y0 = origin[1], image.x1 = origin[0] + side, image.y1 = origin[1] + side;
  image.values = values.data();
  EXPECT_EQ(make_density_max_mip(image, mip), Status::kOk);
  QueryParams q;
  q.x0 = q.origin_x = origin[0], q.y0 = q.origin_y = origin[1];
  q.x1 = q.x0 + side, q.y1 = q.y0 + side;
  q.scale = scale;
  q.density.kind = QueryDensity::Kind::kImage;
  q.density.image = &image;
  q.mode = mode;
  const analysis::DensityAccuracy acc = accuracy(
      q, [&](double x, double y) { return image.at(image.x0 + side * x, image.y0 + side * y); }, expected);
  std::printf(
      "%s, %s mode, at (%g, %g): %zu points (expected %.0f), %zu windows, RMS z %.3f, max |z| %.2f, bias "
      "%+.5f, %zu at zero density\n",
      label, mode_name(mode), origin[0], origin[1], acc.points, expected, acc.windows, acc.rms_z,
      acc.max_abs_z, acc.bias, acc.zero_density);
  return acc;
}

// image_accuracy in both modes on every region of kOrigins, against the bars; with `white_stays_empty`,
// neither mode may emit a point where the image is 0.
void check_image(const char* label, const std::vector<float>& values, int w, int h, double side, double scale,
                 double expected, bool white_stays_empty) {
  for (const QueryMode mode : kModes)
    for (const auto& origin : kOrigins) {
      const analysis::DensityAccuracy acc =
          image_accuracy(label, values, w, h, origin, side, scale, expected, mode);
      EXPECT_LE(acc.rms_z, kRmsZ);
      EXPECT_LE(std::fabs(acc.bias), kBias);
      if (white_stays_empty) {
        EXPECT_EQ(acc.zero_density, 0u);
      }
    }
}

TEST(RuntimeQualityTest, FollowsAPhotograph) {
  // examples/sphere.png (320×320, 8-bit grey, CC0) as `kdm query --density` reads it: darkness is the
  // density (gamma 1), the picture's top row at the top of the region, bilinear between texels, over 8×8
  // tiles at scale 20000 (up to 20,000 points per tile, 221,000 in all). Its white background has density
  // 0, and its shading spans the grey levels. 8138 windows; measured: RMS z .317–.323, bias
  // −0.013%…+0.051% (bars 0.5 and 0.5%: met). Smooth mode: RMS z .301–.304, bias −0.030%…+0.036%; without
  // the test of the density at glided positions, 267 of the 8 regions' 1.8 million points glided onto white.
  tools::GreyImage picture;
  std::string error;
  ASSERT_TRUE(tools::load_grey_image(std::string(KDM_SOURCE_DIR) + "/examples/sphere.png", picture, error))
      << error;
  const int w = picture.width, h = picture.height;
  std::vector<float> values(static_cast<std::size_t>(w) * h);
  double sum = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      // DensityImageView row 0 is at the bottom of its rectangle; the picture's row 0 is its top.
      const float v = static_cast<float>(1.0 - picture.at(x, h - 1 - y));
      values[static_cast<std::size_t>(y) * w + x] = v;
      sum += v;
    }
  constexpr double kSide = 8, kScale = 20000;
  // Bilinear interpolation clamped at the edges integrates to exactly texel area × Σ texels.
  const double expected = kScale * (kSide / w) * (kSide / h) * sum;
  check_image("sphere.png", values, w, h, kSide, kScale, expected, /*white_stays_empty=*/true);
}

TEST(RuntimeQualityTest, FollowsARadial1To1000Map) {
  // The 1:1000 radial falloff of query_test's FollowsADensityImage (density 1000^−r/R, R half the side,
  // 16 texels per tile, bilinear), here over 8×8 tiles at scale 30000 with the bias checked too (bars 0.5
  // and 0.5%: met). Why 8×8:
  // at 4×4 tiles and scale 14000 (7,400 points) the bias spreads −0.50%…+0.02% over the regions, too
  // noisy to judge a 0.5% bar; here (63,000 points) it spreads −0.18%…+0.01%, RMS z .303–.319 (smooth
  // mode: −0.18%…+0.00%, .290–.297).
  constexpr int kTexelsPerTile = 16;
  constexpr double kSide = 8, kScale = 30000;
  const int n = kTexelsPerTile * static_cast<int>(kSide);
  std::vector<float> values(static_cast<std::size_t>(n) * n);
  double sum = 0;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const double r =
          std::hypot((x + 0.5) / kTexelsPerTile - kSide / 2, (y + 0.5) / kTexelsPerTile - kSide / 2);
      const float v = static_cast<float>(std::pow(1000.0, -std::min(1.0, r / (kSide / 2))));
      values[static_cast<std::size_t>(y) * n + x] = v;
      sum += v;
    }
  // Bilinear interpolation clamped at the edges integrates to exactly texel area × Σ texels.
  const double expected = kScale * sum / (kTexelsPerTile * kTexelsPerTile);
  check_image("radial 1:1000", values, n, n, kSide, kScale, expected, /*white_stays_empty=*/false);
}

TEST(RuntimeQualityTest, SmoothModeKeepsDotsApartWhereTheDensityChangesFromDotToDot) {
  // A 200×200 image of independent texels, density uniform in [0.1, 1], over 4×4 tiles at scale 25000: a
  // texel about 0.8 of a point's spacing, so neighbouring points see different densities. A pair is close
  // below 0.25 d_hex at the larger of its two densities. Stable mode has none. Smooth mode with
  // glide_together, measured over 5 such images (seeds 1–5): 0.22–0.38% of the points in a close pair
  // (bar 0.75%); without it, each point gliding by its own density, 2.5–3.0% (asserted above 1.5%: the
  // option is what keeps them apart). Then smooth mode again past the top level: tiles of side 8 hold
  // 5–50 times its count, so every point is a depth-1 subtile's: 0.20–0.31% together, 2.5–2.9% alone.
  constexpr int kSide = 200;
  constexpr double kScale = 25000;
  std::vector<float> values(std::size_t(kSide) * kSide), mip;
  std::uint64_t state = 5;
  for (float& v : values) {  // splitmix64
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull, z = (z ^ (z >> 27)) * 0x94d049bb133111ebull, z ^= z >> 31;
    v = static_cast<float>(0.1 + 0.9 * double(z >> 11) / double(1ull << 53));
  }
  DensityImageView image;
  image.width = image.height = kSide, image.x1 = image.y1 = 1, image.values = values.data();
  ASSERT_EQ(make_density_max_mip(image, mip), Status::kOk);
  for (const double tile_size : {0.25, 8.0})
    for (const int run : {0, 1, 2}) {  // stable; smooth; smooth gliding together
      const QueryMode mode = run == 0 ? QueryMode::kStable : QueryMode::kSmooth;
      if (tile_size > 1 && mode == QueryMode::kStable) continue;
      QueryParams q;
      q.x1 = q.y1 = 1, q.tile_size = tile_size, q.scale = kScale, q.mode = mode, q.glide_together = run == 2;
      q.density.kind = QueryDensity::Kind::kImage, q.density.image = &image;
      const std::vector<QueryPoint> points = query_all(q);
      ASSERT_GT(points.size(), 13000u);
      const std::vector<double> coords = normalised(points, 1, 1);
      const analysis::NearestNeighbours nn = analysis::nearest_neighbours(coords, 2, /*torus=*/false);
      std::size_t close = 0;
      for (std::size_t i = 0; i < points.size(); ++i) {
        const QueryPoint &a = points[i], &b = points[nn.index[i]];
        const double rho = std::max(image.at(a.x, a.y), image.at(b.x, b.y));
        close += nn.distance[i] < 0.25 * std::sqrt(2 / (std::sqrt(3.0) * rho * kScale));
      }
      const double share = double(close) / double(points.size());
      std::printf("tile %g %s mode%s: %zu points, %.3f%% in a pair closer than 0.25 d_hex\n", tile_size,
                  mode_name(mode), run == 2 ? " gliding together" : "", points.size(), 100 * share);
      if (run == 1)
        EXPECT_GT(share, 0.015);
      else
        EXPECT_LT(share, run == 0 ? 1e-9 : 0.0075) << mode_name(mode);
    }
}

}  // namespace
}  // namespace kdm
