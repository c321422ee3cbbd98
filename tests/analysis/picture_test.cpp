// Pictures of points (tools/common): a disc's coverage is its area at any size, so that a stipple keeps its
// tone whatever the picture's width.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "image_io.h"
#include "picture.h"
#include "point_output.h"

namespace kdm::tools {
namespace {

constexpr double kPi = 3.141592653589793;

double covered(const CoverageImage& layer) {
  double sum = 0;
  for (const std::uint16_t v : layer.values) sum += v / 65535.0;
  return sum;
}

// Every radius, anywhere in a pixel: the coverages sum to π r², to 0.3% below 4 pixels (the partly covered
// pixels scaled to it; measured at most 0.22%, at r = 2) and to 1% from 4 on, where the ramp's π/12 is only
// taken off the radius (measured at most 0.38%, at r = 5, 200 centres each). A disc of a tenth of a pixel
// at a pixel's centre used to cover 0.6 of it, nineteen times its area.
TEST(Picture, ADiscCoversItsAreaAtAnySize) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> offset(0, 1);
  for (const double r : {0.05, 0.1, 0.3, 0.7, 1.2, 2.0, 3.99, 5.0, 11.3}) {
    for (int trial = 0; trial < 20; ++trial) {
      CoverageImage layer(64, 64);
      add_disc(layer, 32 + offset(rng), 32 + offset(rng), r);
      const double area = kPi * r * r;
      EXPECT_NEAR(covered(layer), area, (r < 4 ? 0.003 : 0.01) * area) << "r " << r;
    }
  }
}

// A stipple's picture keeps its tone from dots far under a pixel to dots of several: the same 19,881 points
// at 40 to 1,600 pixels wide, dots sized to cover 30% of the paper. Tone = mean darkness of the PNG. The
// points are a grid jittered by ±0.1 cell, so that no two dots overlap; the 8-bit pixels round each to
// 1/255. Measured: 0.2989 at 40 pixels, 0.3000 from 100 on. The former renderer (each disc's coverage its
// distance to the edge plus half a pixel, painted over the others) gave 0.96, 0.62 and 0.33 at 40, 100
// and 400 pixels.
TEST(Picture, AStippleKeepsItsToneAtAnyWidth) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> jitter(0.4, 0.6);  // ±0.1 cell: no two dots overlap
  PointSet points;
  const int cells = 141;
  for (int y = 0; y < cells; ++y)
    for (int x = 0; x < cells; ++x) {
      points.coords.push_back((x + jitter(rng)) / cells);
      points.coords.push_back((y + jitter(rng)) / cells);
    }
  const std::string path = ::testing::TempDir() + "kdm_picture_tone.png";
  for (const int width : {40, 100, 400, 1600}) {
    DrawStyle style;
    style.width_px = width;
    style.dot_radius_px = std::sqrt(0.3 * width * width / (kPi * points.size()));
    write_points(path, points, {}, style);
    GreyImage image;
    std::string error;
    ASSERT_TRUE(load_grey_image(path, image, error)) << error;
    double dark = 0;
    for (const float v : image.pixels) dark += 1 - v;
    std::printf("%d pixels wide: tone %.4f\n", width, dark / image.pixels.size());
    EXPECT_NEAR(dark / image.pixels.size(), 0.3, 0.01) << width << " pixels wide";
  }
  std::remove(path.c_str());
}

}  // namespace
}  // namespace kdm::tools
