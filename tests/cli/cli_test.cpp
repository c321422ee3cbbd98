// The kdm command line on hostile and edge inputs: images that are empty, 1×1, 16-bit, corrupt, truncated
// or missing; sampler counts and temperatures at their limits; output paths that cannot be written; plus
// --version, --help and stipple --frames. Every failure must be one line "kdm: error: ..." and exit status 1.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "cli_fixture.h"
#include "image_io.h"
#include "kdm/runtime/tileset.h"
#include "kdm/runtime/tileset_format.h"
#include "kdm/runtime/version.h"
#include "point_io.h"

namespace {

using namespace kdm_cli_test;

/// The first point set of `file` (empty, with a test failure, if it does not read).
kdm::tools::PointSet first_set(const std::string& file) {
  std::vector<kdm::tools::PointSet> sets;
  std::string error;
  EXPECT_TRUE(kdm::tools::read_point_sets(file, sets, error) && !sets.empty()) << file << ": " << error;
  return sets.empty() ? kdm::tools::PointSet{} : sets[0];
}

TEST_F(CliTest, TheTestEncoderWritesImagesTheLoaderReads) {
  write_bytes(path("ramp.png"), ramp_png());
  kdm::tools::GreyImage image;
  std::string error;
  ASSERT_TRUE(kdm::tools::load_grey_image(path("ramp.png"), image, error)) << error;
  EXPECT_EQ(image.width, 64);
  EXPECT_FLOAT_EQ(image.at(10, 5), 40.0f / 255.0f);
}

TEST_F(CliTest, LoadersAverageALargePictureDownToTheKeptPixels) {
  // 90 × 60 grey + alpha, no two neighbours alike, so that any misplaced box shows.
  const int w = 90, h = 60;
  std::vector<std::uint16_t> samples(std::size_t(w) * h * 2);
  for (int i = 0; i < w * h; ++i) {
    samples[2 * i] = static_cast<std::uint16_t>((i * 37 + i / w * 11) % 256);
    samples[2 * i + 1] = static_cast<std::uint16_t>(255 - (i * 53) % 128);
  }
  write_bytes(path("boxes.png"), grey_png(w, h, 8, samples, 2));
  std::string error;
  kdm::tools::GreyImage full, same, thirds, fifths;
  ASSERT_TRUE(kdm::tools::load_grey_image(path("boxes.png"), full, error)) << error;
  const auto keep = [](std::uint64_t n) { return [n](int, int) { return n; }; };
  // As many pixels as it has, or more: every pixel, bit for bit.
  ASSERT_TRUE(
      kdm::tools::load_grey_image(path("boxes.png"), same, error, kdm::tools::kMaxImagePixels, keep(w * h)));
  EXPECT_EQ(same.pixels, full.pixels);
  EXPECT_EQ(same.alpha, full.alpha);
  // A ninth: each kept pixel is the mean of a 3 × 3 box (composited on paper), and so is its alpha.
  ASSERT_TRUE(kdm::tools::load_grey_image(path("boxes.png"), thirds, error, kdm::tools::kMaxImagePixels,
                                          keep(w * h / 9)));
  ASSERT_EQ(thirds.width, 30);
  ASSERT_EQ(thirds.height, 20);
  ASSERT_EQ(thirds.alpha.size(), 600u);
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 30; ++x) {
      double grey = 0, alpha = 0;
      for (int v = 0; v < 3; ++v)
        for (int u = 0; u < 3; ++u) {
          grey += full.at(3 * x + u, 3 * y + v) / 9.0;
          alpha += full.alpha[std::size_t(3 * y + v) * w + 3 * x + u] / 9.0;
        }
      EXPECT_NEAR(thirds.at(x, y), grey, 1e-6) << x << "," << y;
      EXPECT_NEAR(thirds.alpha[std::size_t(y) * 30 + x], alpha, 1e-6) << x << "," << y;
    }
  // Boxes of 2.5 pixels split pixels between two kept ones: the picture's tone stays, and the kept
  // pixels' columns still hold the picture's columns in order (the left third's mean is the left third's).
  ASSERT_TRUE(kdm::tools::load_grey_image(path("boxes.png"), fifths, error, kdm::tools::kMaxImagePixels,
                                          keep(w * h * 4 / 25)));
  ASSERT_EQ(fifths.width, 36);
  ASSERT_EQ(fifths.height, 24);
  const auto mean = [](const kdm::tools::GreyImage& image, int x0, int x1) {
    double sum = 0;
    for (int y = 0; y < image.height; ++y)
      for (int x = x0; x < x1; ++x) sum += image.at(x, y);
    return sum / (double(x1 - x0) * image.height);
  };
  EXPECT_NEAR(mean(fifths, 0, 36), mean(full, 0, 90), 1e-6);
  EXPECT_NEAR(mean(fifths, 0, 12), mean(full, 0, 30), 1e-6);
  // In colour too: a grey picture's three channels are its luminance.
  kdm::tools::ColourImage colour;
  ASSERT_TRUE(kdm::tools::load_colour_image(path("boxes.png"), colour, error, kdm::tools::kMaxImagePixels,
                                            keep(w * h / 9)));
  ASSERT_EQ(colour.width, 30);
  for (std::size_t i = 0; i < thirds.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(colour.pixels[3 * i + c], thirds.pixels[i], 1e-6);
  // A keep of 0 still keeps a pixel.
  ASSERT_TRUE(
      kdm::tools::load_grey_image(path("boxes.png"), same, error, kdm::tools::kMaxImagePixels, keep(0)));
  EXPECT_EQ(same.width * same.height, 1);
  EXPECT_NEAR(same.pixels[0], mean(full, 0, 90), 1e-6);
}

TEST_F(CliTest, PicturesWhoseDecodingPassesTwoGibibytesAreRefusedByName) {
  // A Radiance picture of 16,384 × 10,923 (within a stipple's 2^28 pixels): stb decodes it as three floats
  // a pixel, 2^31 bytes and more, past what its int counts. Each scanline holds runs of one value per
  // channel, so the file is small.
  const int w = 16384, h = 10923;
  std::string file =
      "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " + std::to_string(h) + " +X " + std::to_string(w) + "\n";
  std::string line = {2, 2, char(w >> 8), char(w & 255)};
  for (int channel = 0; channel < 4; ++channel) {
    for (int run = 0; run < w / 127; ++run) line += {char(128 + 127), char(channel == 3 ? 128 : 100)};
    line += {char(128 + w % 127), char(channel == 3 ? 128 : 100)};
  }
  for (int y = 0; y < h; ++y) file += line;
  write_bytes(path("wide.hdr"), std::vector<std::uint8_t>(file.begin(), file.end()));
  kdm::tools::GreyImage image;
  std::string error;
  EXPECT_FALSE(kdm::tools::load_grey_image(path("wide.hdr"), image, error, std::uint64_t(1) << 28));
  EXPECT_NE(error.find("16384x10923 pixels of 3 channels of 32 bits: decoding it takes 2 GiB or more"),
            std::string::npos)
      << error;
  expect_error("stipple '" + path("wide.hdr") + "' -o '" + path("w.svg") + "'", "2 GiB or more");
}

// Fills stack the loader's callees will use with a grey, so that a read of uninitialised stack shows.
__attribute__((noinline)) void dirty_stack() {
  volatile std::uint8_t junk[1 << 18];
  for (std::size_t i = 0; i < sizeof junk; ++i) junk[i] = 0x80;
}

TEST_F(CliTest, PaletteIndicesPastThePaletteAreBlack) {
  // A 4 × 1 palette PNG of 2 bits a pixel whose PLTE holds two entries (both white), its pixels the
  // indices 0, 1, 2 and 3; and the same as a 4-bit BMP. stb reads entries 2 and 3 from its own
  // uninitialised stack: kdm gives it a palette filled up with black.
  std::vector<std::uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  chunk(png, "IHDR", {0, 0, 0, 4, 0, 0, 0, 1, 2, 3, 0, 0, 0});
  chunk(png, "PLTE", {255, 255, 255, 255, 255, 255});
  chunk(png, "IDAT", zlib_stored({0, 0x1B}));
  chunk(png, "IEND", {});
  write_bytes(path("palette.png"), png);
  std::vector<std::uint8_t> bmp = {'B', 'M', 70, 0, 0, 0, 0, 0, 0, 0, 62, 0, 0, 0,         // pixels at 62
                                   40,  0,   0,  0, 4, 0, 0, 0, 1, 0, 0,  0, 1, 0, 4, 0};  // 4 × 1, 4 bits
  bmp.resize(14 + 40, 0);                                                                  // no compression
  bmp.insert(bmp.end(), {255, 255, 255, 0, 255, 255, 255, 0});                             // two entries
  bmp.insert(bmp.end(), {0x01, 0x23, 0, 0});                                               // a row
  write_bytes(path("palette.bmp"), bmp);
  for (const char* name : {"palette.png", "palette.bmp"}) {
    SCOPED_TRACE(name);
    for (int round = 0; round < 2; ++round) {
      kdm::tools::GreyImage image;
      std::string error;
      dirty_stack();
      ASSERT_TRUE(kdm::tools::load_grey_image(path(name), image, error)) << error;
      ASSERT_EQ(image.pixels.size(), 4u);
      EXPECT_EQ(image.pixels, (std::vector<float>{1, 1, 0, 0}));
    }
  }
}

TEST_F(CliTest, TopDownBmpsAreReadAsBottomUpOnes) {
  // A 2 × 2 24-bit BMP stored bottom row first (a positive height), and the same picture stored top row
  // first (a negative height): one picture, black at the top left.
  const auto bmp = [](int height, const std::vector<std::uint8_t>& rows) {
    std::vector<std::uint8_t> b = {'B', 'M', 70, 0, 0, 0, 0, 0, 0, 0, 54, 0, 0, 0, 40, 0, 0, 0, 2, 0, 0, 0};
    for (int i = 0; i < 4; ++i) b.push_back(std::uint8_t(std::uint32_t(height) >> (8 * i)));
    b.insert(b.end(), {1, 0, 24, 0});
    b.resize(54, 0);
    b.insert(b.end(), rows.begin(), rows.end());
    return b;
  };
  const std::vector<std::uint8_t> top = {0, 0, 0, 255, 255, 255, 0, 0},
                                  bottom = {255, 255, 255, 128, 128, 128, 0, 0};
  std::vector<std::uint8_t> up = bottom, down = top;
  up.insert(up.end(), top.begin(), top.end());
  down.insert(down.end(), bottom.begin(), bottom.end());
  write_bytes(path("up.bmp"), bmp(2, up));
  write_bytes(path("down.bmp"), bmp(-2, down));
  kdm::tools::GreyImage a, b;
  std::string error;
  ASSERT_TRUE(kdm::tools::load_grey_image(path("up.bmp"), a, error)) << error;
  ASSERT_TRUE(kdm::tools::load_grey_image(path("down.bmp"), b, error)) << error;
  ASSERT_EQ(b.height, 2);
  EXPECT_EQ(a.pixels, b.pixels);
  EXPECT_EQ(b.at(0, 0), 0.0f);
  EXPECT_NEAR(b.at(1, 1), 128.0f / 255, 1e-6);
}

TEST_F(CliTest, BadImagesGiveOneLineErrors) {
  const std::vector<std::uint8_t> good = ramp_png();
  write_bytes(path("empty0x0.png"), grey_png(0, 0, 8, {}));  // IHDR says 0×0
  write_bytes(path("zero-bytes.png"), {});
  write_bytes(path("truncated.png"), std::vector<std::uint8_t>(good.begin(), good.begin() + good.size() / 2));
  std::vector<std::uint8_t> corrupt =
      good;  // the IDAT's stored-block length no longer matches its complement
  corrupt[8 + 25 + 8 + 3] ^= 0xFF;
  write_bytes(path("corrupt.png"), corrupt);
  write_bytes(path("text.png"), std::vector<std::uint8_t>{'n', 'o', 't', ' ', 'a', 'n', ' ', 'i', 'm', 'g'});
  write_bytes(path("white.png"), grey_png(1, 1, 8, {255}));  // defined, but no ink: no n points to sample
  for (const char* name : {"empty0x0.png", "zero-bytes.png", "truncated.png", "corrupt.png", "text.png",
                           "missing.png", "white.png"}) {
    SCOPED_TRACE(name);
    const std::string image = path(name);
    expect_error("sample --n 100 --density '" + image + "' -o '" + path("s.txt") + "'", name);
    if (std::string(name) != "white.png")  // a blank picture (StippleOfABlankImageIsAnEmptyPicture)
      expect_error("stipple '" + image + "' -o '" + path("s.png") + "'", name);
    if (std::string(name) != "white.png")  // a query of an all-white image is empty, as one of const:0
      expect_error("query --rect 0,0,1,1 --density '" + image + "' -o '" + path("q.txt") + "'", name);
    EXPECT_FALSE(fs::exists(path("s.txt")) || fs::exists(path("s.png")) || fs::exists(path("q.txt")));
  }
  // stipple takes images alone: a missing one is not "a density is a picture, const:V, …", grey or in colour.
  for (const char* colours : {"", " --colours cmyk"})
    expect_error("stipple '" + path("missing.png") + "'" + colours + " -o '" + path("s.png") + "'",
                 "cannot read image '" + path("missing.png") + "': No such file or directory");
  // A header of 100,000 × 100,000 pixels, which stb will not even read: refused by its size, by name.
  std::vector<std::uint8_t> huge = grey_png(1, 1, 8, {0});
  for (int at : {16, 20}) huge[at] = 0, huge[at + 1] = 0x01, huge[at + 2] = 0x86, huge[at + 3] = 0xA0;
  write_bytes(path("huge.png"), huge);
  expect_error("stipple '" + path("huge.png") + "' -o '" + path("s.png") + "'", "100000x100000 pixels");
}

// An image with no ink gives an empty picture, not an error (a blank frame in a batch or an animation), in
// every method and output, grey or in colour; the run says so.
TEST_F(CliTest, StippleOfABlankImageIsAnEmptyPicture) {
  write_bytes(path("white.png"), grey_png(3, 2, 8, {255, 255, 255, 255, 255, 255}));
  write_bytes(path("black.png"), grey_png(3, 2, 8, {0, 0, 0, 0, 0, 0}));
  const std::string white = "stipple '" + path("white.png") + "' -o '";
  for (const std::string& args :
       {white + path("b.csv") + "'", white + path("b.csv") + "' --method full",
        white + path("b.csv") + "' --colours 3",
        "stipple '" + path("black.png") + "' --invert -o '" + path("b.csv") + "'"}) {
    SCOPED_TRACE(args);
    const Outcome o = kdm(args);
    ASSERT_EQ(o.status, 0) << o.err;
    EXPECT_NE(o.err.find("has no ink"), std::string::npos) << o.err;
    const std::string csv = slurp(path("b.csv"));
    EXPECT_EQ(csv.rfind("x,y", 0), 0u) << csv;
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1) << csv;  // the header, no dots
  }
  const Outcome picture = kdm(white + path("b.png") + "' --width 30");
  ASSERT_EQ(picture.status, 0) << picture.err;
  kdm::tools::GreyImage image;
  std::string error;
  ASSERT_TRUE(kdm::tools::load_grey_image(path("b.png"), image, error)) << error;
  EXPECT_EQ(image.width, 30);
  EXPECT_EQ(image.height, 20);
  for (const float v : image.pixels) EXPECT_EQ(v, 1.0f);
  const Outcome svg = kdm(white + path("b.svg") + "' --colours cmyk");  // every pen's layer, none with dots
  ASSERT_EQ(svg.status, 0) << svg.err;
  EXPECT_NE(slurp(path("b.svg")).find("inkscape:label=\"yellow\""), std::string::npos);
  EXPECT_EQ(slurp(path("b.svg")).find("<circle"), std::string::npos);
  const Outcome frames = kdm(white + path("f.png") + "' --region 0.2,0.2,0.6,0.6 --frames 2");
  ASSERT_EQ(frames.status, 0) << frames.err;
  EXPECT_TRUE(fs::exists(path("f_0000.png")) && fs::exists(path("f_0001.png")));
}

TEST_F(CliTest, OneByOneImageIsAConstantDensity) {
  write_bytes(path("grey.png"), grey_png(1, 1, 8, {128}));
  const Outcome sampled =
      kdm("sample --n 300 --density '" + path("grey.png") + "' -o '" + path("s.txt") + "'");
  ASSERT_EQ(sampled.status, 0) << sampled.err;
  EXPECT_EQ(first_set(path("s.txt")).size(), 300u);  // exact count, as for any density
  const Outcome stippled = kdm("stipple '" + path("grey.png") + "' --points 2000 -o '" + path("t.txt") + "'");
  ASSERT_EQ(stippled.status, 0) << stippled.err;
  // The runtime's count for a uniform density over many tiles is the expectation up to the rounding of
  // partly covered edge tiles; 5% is several times that for 2000 dots.
  EXPECT_NEAR(double(first_set(path("t.txt")).size()), 2000.0, 100.0);
}

TEST_F(CliTest, SixteenBitImagesKeepTheirPrecision) {
  // Two samples that 8 bits cannot tell apart (1000 and 1100 of 65535 both round to 4 of 255).
  std::vector<std::uint16_t> v(16 * 16);
  for (int i = 0; i < 16 * 16; ++i) v[i] = i % 16 < 8 ? 1000 : 1100;
  write_bytes(path("deep.png"), grey_png(16, 16, 16, v));
  kdm::tools::GreyImage image;
  std::string error;
  ASSERT_TRUE(kdm::tools::load_grey_image(path("deep.png"), image, error)) << error;
  EXPECT_NEAR(image.at(0, 0), 1000.0 / 65535, 1e-7);
  EXPECT_NEAR(image.at(15, 15), 1100.0 / 65535, 1e-7);
  const Outcome r = kdm("stipple '" + path("deep.png") + "' --points 500 -o '" + path("deep.svg") + "'");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::file_size(path("deep.svg")) > 0);
}

TEST_F(CliTest, RadianceImagesKeepTheirDynamicRange) {
  // 1 : 5,000, the paper's high-dynamic-range example, which 8 or 16 bits cannot hold.
  std::vector<float> v(16 * 16);
  for (int i = 0; i < 16 * 16; ++i) v[i] = i % 16 < 8 ? 3.0f : 3.0f / 5000;
  write_bytes(path("range.hdr"), radiance_hdr(16, 16, v));
  kdm::tools::GreyImage image;
  std::string error;
  ASSERT_TRUE(kdm::tools::load_grey_image(path("range.hdr"), image, error)) << error;
  EXPECT_FLOAT_EQ(image.at(0, 0), 1.0f);                 // scaled by the brightest pixel
  EXPECT_NEAR(image.at(15, 15) * 5000, 1.0, 1.0 / 128);  // an 8-bit mantissa's rounding
  // Bright is dense with --invert: past the texel where the halves blend, the faint part holds 7/15 of
  // 1/5000 of the bright part's density: about one point of 4,000.
  const Outcome r =
      kdm("sample --n 4000 --density '" + path("range.hdr") + "' --invert -o '" + path("r.txt") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const kdm::tools::PointSet set = first_set(path("r.txt"));
  std::size_t faint = 0;
  for (std::size_t i = 0; i < set.size(); ++i) faint += set.coords[2 * i] >= 9.0 / 16;
  EXPECT_LE(faint, 4u);  // read as 8 bits the faint part would be 1/28 as dense: about 120 points
}

// stb reads zeros past a Radiance file's end: every cut of a flat and a run-length file is refused, as are
// the headers stb cannot read, by name.
TEST_F(CliTest, RadianceImagesCutShortOrOtherwiseOrientedAreRefused) {
  for (const char* name : {"flat.hdr", "rle.hdr"}) {
    const std::string whole = slurp(std::string(KDM_SOURCE_DIR) + "/tests/fuzz/corpus/image/" + name);
    kdm::tools::GreyImage image;
    std::string error;
    ASSERT_TRUE(kdm::tools::load_grey_image_memory(whole.data(), whole.size(), image, error, name)) << error;
    EXPECT_GT(image.at(0, 0), 0.0f);
    for (std::size_t cut = whole.find("+X"); cut < whole.size(); ++cut) {
      SCOPED_TRACE(std::string(name) + " cut at " + std::to_string(cut));
      EXPECT_FALSE(kdm::tools::load_grey_image_memory(whole.data(), cut, image, error, name));
      EXPECT_NE(error.find("cut short"), std::string::npos) << error;
    }
  }
  const std::string header = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n";
  const std::string flipped = header + "+Y 1 +X 1\n" + std::string(4, '\x80');
  kdm::tools::GreyImage image;
  std::string error;
  EXPECT_FALSE(kdm::tools::load_grey_image_memory(flipped.data(), flipped.size(), image, error, "f.hdr"));
  EXPECT_NE(error.find("only '-Y height +X width'"), std::string::npos) << error;
  const std::string unformatted = "#?RADIANCE\n\n-Y 1 +X 1\n" + std::string(4, '\x80');
  EXPECT_FALSE(
      kdm::tools::load_grey_image_memory(unformatted.data(), unformatted.size(), image, error, "u.hdr"));
  EXPECT_NE(error.find("FORMAT=32-bit_rle_rgbe"), std::string::npos) << error;
}

// .npy: an (n, d) float64 array of the same numbers as .txt holds, which kdm analyze reads back.
TEST_F(CliTest, SampleWritesNumPyArrays) {
  for (const int dim : {2, 3}) {
    const std::string args = "sample --n 300 --dim " + std::to_string(dim) + " -o '";
    ASSERT_EQ(kdm(args + path("p.npy") + "'").status, 0);
    ASSERT_EQ(kdm(args + path("p.txt") + "'").status, 0);
    std::vector<kdm::tools::PointSet> npy, txt;
    std::string error;
    ASSERT_TRUE(kdm::tools::read_point_sets(path("p.npy"), npy, error)) << error;
    ASSERT_TRUE(kdm::tools::read_point_sets(path("p.txt"), txt, error)) << error;
    EXPECT_EQ(npy.at(0).dim, dim);
    EXPECT_EQ(npy.at(0).coords, txt.at(0).coords);  // .txt's 17 digits give back every bit
    const std::string bytes = slurp(path("p.npy"));
    EXPECT_EQ(bytes.substr(0, 8), std::string("\x93NUMPY\x01\x00", 8));
    EXPECT_EQ(bytes.size(), 128 + 300 * dim * 8u);  // the header padded to 64-byte alignment
  }
  expect_error("sample --n 100 --class const:1 --class const:2 -o '" + path("c.npy") + "'", "not .npy");
  EXPECT_FALSE(fs::exists(path("c.npy")));
}

// --sets K: K sets in one file, each the set --sets 1 writes for its seed (--seed, --seed + 1, ...), read
// back as K sets from .txt ('#' lines between them) and from .npy (a (K, n, dim) array), whatever the
// thread count; what several sets cannot be is refused before any sampling.
TEST_F(CliTest, SampleWritesSeveralSets) {
  for (const int dim : {2, 3}) {
    const std::string d = " --dim " + std::to_string(dim);
    ASSERT_EQ(kdm("sample --n 40 --sets 3 --seed 11 --threads 1" + d + " -o '" + path("s.txt") + "'").status,
              0);
    ASSERT_EQ(kdm("sample --n 40 --sets 3 --seed 11 --threads 2" + d + " -o '" + path("s.npy") + "'").status,
              0);
    std::vector<kdm::tools::PointSet> txt, npy, one;
    std::string error;
    ASSERT_TRUE(kdm::tools::read_point_sets(path("s.txt"), txt, error)) << error;
    ASSERT_TRUE(kdm::tools::read_point_sets(path("s.npy"), npy, error)) << error;
    ASSERT_EQ(txt.size(), 3u);
    ASSERT_EQ(npy.size(), 3u);
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(
          kdm("sample --n 40 --seed " + std::to_string(11 + k) + d + " -o '" + path("one.txt") + "'").status,
          0);
      ASSERT_TRUE(kdm::tools::read_point_sets(path("one.txt"), one, error)) << error;
      EXPECT_EQ(txt[k].dim, dim);
      EXPECT_EQ(txt[k].coords, one.at(0).coords) << "set " << k;
      EXPECT_EQ(npy[k].coords, one.at(0).coords) << "set " << k;
    }
    EXPECT_EQ(slurp(path("s.npy")).size(), 128 + 3 * 40 * dim * 8u);
  }
  const std::string o = " -o '" + path("x.txt") + "'";
  expect_error("sample --n 16 --sets 0" + o, "--sets must be 1 to");
  expect_error("sample --n 16 --sets 1048577" + o, "--sets must be 1 to");
  expect_error("sample --n 1000 --sets 1048576" + o, "points in all");
  expect_error("sample --n 0 --resolution 64 --sets 2" + o, "--sets needs --n > 0");
  expect_error("sample --n 16 --sets 2 -o '" + path("x.csv") + "'", "not .csv");
  expect_error("sample --n 16 --sets 2 -o '" + path("x.png") + "'", "not .png");
  expect_error("sample --n 16 --sets 2 --class const:1 --class const:2" + o, "drop --class");
  expect_error("sample --n 16 --sets 3 --seed 18446744073709551614" + o, "past the largest seed");
  EXPECT_FALSE(fs::exists(path("x.txt")));
}

/// `values` (depth × height × width, in numpy's C order) as np.save writes a 3-D array of `descr` ('<f8',
/// '<f4', big-endian '>f8' or '>f4', or '|u1'); `shape` overrides the header's shape.
std::string npy_volume(const std::vector<double>& values, int depth, int height, int width,
                       const std::string& descr = "<f4", const std::string& shape = "") {
  const std::string dims =
      shape.empty() ? std::to_string(depth) + ", " + std::to_string(height) + ", " + std::to_string(width)
                    : shape;
  std::string header = "{'descr': '" + descr + "', 'fortran_order': False, 'shape': (" + dims + "), }";
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::string bytes = std::string("\x93NUMPY\x01\x00", 8);
  bytes += static_cast<char>(header.size() & 0xff);
  bytes += static_cast<char>(header.size() >> 8);
  bytes += header;
  for (double v : values) {
    const std::size_t at = bytes.size();
    if (descr.substr(1) == "f8") {
      bytes.append(reinterpret_cast<const char*>(&v), 8);  // x86-64: little-endian already
    } else if (descr.substr(1) == "f4") {
      const float f = static_cast<float>(v);
      bytes.append(reinterpret_cast<const char*>(&f), 4);
    } else {
      bytes += static_cast<char>(static_cast<unsigned char>(v));
    }
    if (descr[0] == '>') std::reverse(bytes.begin() + std::ptrdiff_t(at), bytes.end());
  }
  return bytes;
}

/// The fraction of a 3D point file's points with coordinate `axis` below 1/2.
double fraction_below_half(const std::string& file, int axis) {
  std::vector<kdm::tools::PointSet> sets;
  std::string error;
  EXPECT_TRUE(kdm::tools::read_point_sets(file, sets, error)) << error;
  if (sets.empty() || sets[0].dim != 3) return -1;
  std::size_t below = 0;
  for (std::size_t i = 0; i < sets[0].size(); ++i) below += sets[0].coords[3 * i + axis] < 0.5;
  return double(below) / double(sets[0].size());
}

// kdm sample --dim 3 --density vol.npy: a (depth, height, width) array, slice 0 at z near 0 and each
// slice's row 0 at the top (y near 1). An 8³ volume 4× denser in its first 4 slices puts 0.78125 of the
// points below z = 1/2 (the linear fall from 4 to 1 between the two middle voxel centres; measured
// 0.7768-0.7800 at 4,000 points in a cube over seeds 1-8, sd 0.0009: tests/generator/sampler_test.cpp;
// bound ±0.008),
// one 4× denser in its first 4 rows as many above y = 1/2. float64, float32 and uint8 give the same bits,
// and so does big-endian float64.
TEST_F(CliTest, SampleReadsNumPyVolumes) {
  const int s = 8;
  std::vector<double> by_slice(s * s * s, 1.0), by_row(s * s * s, 1.0);
  for (int z = 0; z < s; ++z)
    for (int row = 0; row < s; ++row)
      for (int x = 0; x < s; ++x) {
        if (z < s / 2) by_slice[(z * s + row) * s + x] = 4;
        if (row < s / 2) by_row[(z * s + row) * s + x] = 4;
      }
  std::ofstream(path("z.npy"), std::ios::binary) << npy_volume(by_slice, s, s, s);
  std::ofstream(path("y.npy"), std::ios::binary) << npy_volume(by_row, s, s, s, "<f8");
  std::ofstream(path("y8.npy"), std::ios::binary) << npy_volume(by_row, s, s, s, "|u1");
  std::ofstream(path("yb.npy"), std::ios::binary) << npy_volume(by_row, s, s, s, ">f8");
  const std::string run = "sample --dim 3 --n 4000 --threads 2 --density '";
  ASSERT_EQ(kdm(run + path("z.npy") + "' -o '" + path("z.txt") + "'").status, 0);
  ASSERT_EQ(kdm(run + path("y.npy") + "' -o '" + path("y.txt") + "'").status, 0);
  const Outcome bytes = kdm(run + path("y8.npy") + "' -o '" + path("y8.txt") + "'");
  ASSERT_EQ(bytes.status, 0) << bytes.err;
  const double expected = (4 * 7.0 / 16 + 3.25 / 16) / 2.5;
  EXPECT_NEAR(fraction_below_half(path("z.txt"), 2), expected, 0.008);
  EXPECT_NEAR(1 - fraction_below_half(path("y.txt"), 1), expected, 0.008);
  auto points = [](const std::string& text) { return text.substr(text.find("\n0")); };  // past the header
  EXPECT_EQ(points(slurp(path("y.txt"))), points(slurp(path("y8.txt"))));
  const Outcome big = kdm(run + path("yb.npy") + "' -o '" + path("yb.txt") + "'");
  ASSERT_EQ(big.status, 0) << big.err;
  EXPECT_EQ(points(slurp(path("y.txt"))), points(slurp(path("yb.txt"))));
  // The domain is a box with the volume's voxel counts as sides, as --aspect W:H:D gives it.
  std::ofstream(path("flat.npy"), std::ios::binary)
      << npy_volume(std::vector<double>(2 * 4 * 8, 1.0), 2, 4, 8);
  ASSERT_EQ(
      kdm("sample --dim 3 --n 500 --density '" + path("flat.npy") + "' -o '" + path("f.txt") + "'").status,
      0);
  ASSERT_EQ(kdm("sample --dim 3 --n 500 --domain box --aspect 8:4:2 -o '" + path("a.txt") + "'").status, 0);
  EXPECT_EQ(points(slurp(path("f.txt"))), points(slurp(path("a.txt"))));
  EXPECT_NE(slurp(path("f.txt")).find("domain box, sides 8:4:2"), std::string::npos) << slurp(path("f.txt"));
}

// --aspect X:Y:Z sets a 3D domain's three sides; one number keeps its meaning (x over y and z).
TEST_F(CliTest, SampleTakesThreeSides) {
  const std::string run = "sample --dim 3 --n 600 -o '";
  ASSERT_EQ(kdm(run + path("one.txt") + "' --aspect 2").status, 0);
  ASSERT_EQ(kdm(run + path("three.txt") + "' --aspect 2:1:1").status, 0);
  ASSERT_EQ(kdm(run + path("scaled.txt") + "' --aspect 4:2:2").status, 0);
  ASSERT_EQ(kdm(run + path("other.txt") + "' --aspect 1:2:4").status, 0);
  auto points = [&](const std::string& name) {
    const std::string text = slurp(path(name));
    return text.substr(text.find("\n0"));
  };
  EXPECT_EQ(points("one.txt"), points("three.txt"));
  EXPECT_EQ(points("one.txt"), points("scaled.txt"));  // only the ratios count
  EXPECT_NE(points("one.txt"), points("other.txt"));
  EXPECT_NE(slurp(path("other.txt")).find(", sides 1:2:4"), std::string::npos);
  EXPECT_NE(slurp(path("one.txt")).find(", aspect 2\n"), std::string::npos);
}

// Only a density's shape matters: a .npy array of any scale, values far below or above a float's range too,
// samples as the array divided by its largest value (all 1e-200 is not zero everywhere).
TEST_F(CliTest, SampleTakesNumPyDensitiesAtAnyScale) {
  std::vector<double> values(2 * 3 * 4);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = 1 + double(i % 5);
  auto points = [&](const std::string& name) {
    const std::string text = slurp(path(name));
    return text.substr(text.find("\n0"));
  };
  for (const char* dim : {"2", "3"}) {
    const bool flat = dim[0] == '2';
    const std::string shape = flat ? "6, 4" : "";
    // Values times 2^k over their largest (5 times 2^k) are exactly the values over 5, at any k.
    auto scaled = [&](int k) {
      std::vector<double> out = values;
      for (double& v : out) v = k ? std::ldexp(v, k) : v / 5;
      return out;
    };
    std::ofstream(path("unit.npy"), std::ios::binary) << npy_volume(scaled(0), 2, 3, 4, "<f8", shape);
    const std::string run = std::string("sample --n 300 --seed 2 --dim ") + dim + " --density '";
    const Outcome unit = kdm(run + path("unit.npy") + "' -o '" + path("unit.txt") + "'");
    ASSERT_EQ(unit.status, 0) << unit.err;
    for (int scale : {-660, -116, 116, 996}) {  // about 1e-199, 1e-35, 1e35, 1e300
      std::ofstream(path("s.npy"), std::ios::binary) << npy_volume(scaled(scale), 2, 3, 4, "<f8", shape);
      const Outcome got = kdm(run + path("s.npy") + "' -o '" + path("s.txt") + "'");
      ASSERT_EQ(got.status, 0) << dim << " " << scale << ": " << got.err;
      EXPECT_EQ(points("s.txt"), points("unit.txt")) << dim << " " << scale;
    }
  }
}

// A query counts a density's size: a .npy array's values as it holds them, past a float's range refused by
// name (they were divided by their largest, as the sampler takes them: 1e300 everywhere gave the points of
// 1, and one texel of 1e300 emptied the rest of the map).
TEST_F(CliTest, QueryTakesNumPyDensitiesAtTheirSize) {
  const auto query = [&](double fill, double spike) {
    std::vector<double> values(8 * 8, fill);
    values[0] = spike;
    std::ofstream(path("d.npy"), std::ios::binary) << npy_volume(values, 0, 0, 0, "<f8", "8, 8");
    return kdm("query --rect 0,0,4,4 --scale 100 --density '" + path("d.npy") + "' -o '" + path("d.csv") +
               "'");
  };
  const auto rows = [&] {
    const std::string text = slurp(path("d.csv"));
    return std::count(text.begin(), text.end(), '\n') - 1;
  };
  ASSERT_EQ(query(1, 1).status, 0);
  const auto unit = rows();
  EXPECT_GT(unit, 1500);
  for (double tiny : {1e-40, 1e-300}) {  // below what a query resolves: no points, as in Python
    ASSERT_EQ(query(tiny, tiny).status, 0);
    EXPECT_EQ(rows(), 0) << tiny;
  }
  ASSERT_EQ(query(0.5, 0.5).status, 0);
  EXPECT_NEAR(double(rows()), 0.5 * double(unit), 0.05 * double(unit));
  for (const auto& [fill, spike] : {std::pair{1e300, 1e300}, std::pair{1e39, 1e39}, std::pair{0.5, 1e300}}) {
    const Outcome refused = query(fill, spike);
    EXPECT_EQ(refused.status, 1);
    EXPECT_NE(refused.err.find("at most 3.4e38"), std::string::npos) << refused.err;
  }
}

TEST_F(CliTest, BadVolumesAndSidesGiveOneLineErrors) {
  const std::string out = " -o '" + path("x.txt") + "'";
  std::ofstream(path("v.npy"), std::ios::binary) << npy_volume(std::vector<double>(8, 1.0), 2, 2, 2);
  std::ofstream(path("flat.npy"), std::ios::binary)
      << npy_volume(std::vector<double>(4, 1.0), 0, 0, 0, "<f4", "2, 2");
  std::vector<double> bad(8, 1.0);
  bad[5] = -2;  // [1, 0, 1]
  std::ofstream(path("neg.npy"), std::ios::binary) << npy_volume(bad, 2, 2, 2, "<f8");
  bad[5] = std::nan("");
  std::ofstream(path("nan.npy"), std::ios::binary) << npy_volume(bad, 2, 2, 2, "<f8");
  std::ofstream(path("zero.npy"), std::ios::binary) << npy_volume(std::vector<double>(8, 0.0), 2, 2, 2);
  std::ofstream(path("c.npy"), std::ios::binary) << npy_volume({}, 2, 2, 2, "<c8");  // complex
  std::ofstream(path("short.npy"), std::ios::binary) << npy_volume(std::vector<double>(7, 1.0), 2, 2, 2);
  const std::string v = " --density '" + path("v.npy") + "'";
  expect_error("sample --n 100 --dim 3 --density '" + path("flat.npy") + "'" + out,
               "density '" + path("flat.npy") + "' is a 2-D array (2, 2): drop --dim 3, or give a 3-D array");
  expect_error("sample --n 100" + v + out, "is a 3-D array (2, 2, 2): sample it with --dim 3");
  expect_error("sample --n 100 --dim 3 --density '" + path("neg.npy") + "'" + out,
               "a value of -2.000000 at [1, 0, 1]");
  expect_error("sample --n 100 --dim 3 --density '" + path("nan.npy") + "'" + out,
               "at [1, 0, 1]: densities must be finite");
  expect_error("sample --n 100 --dim 3 --density '" + path("zero.npy") + "'" + out, "zero everywhere");
  // A 2-D array of zeros is an array, not a picture: no talk of white images and ink.
  std::ofstream(path("zero2.npy"), std::ios::binary)
      << npy_volume(std::vector<double>(4, 0.0), 0, 0, 0, "<f4", "2, 2");
  const std::string zeros = "sample --n 100 --density '" + path("zero2.npy") + "'" + out;
  expect_error(zeros, "array '" + path("zero2.npy") + "': its densities are zero everywhere");
  const std::string said = kdm(zeros).err, why = said.substr(std::min(said.size(), said.find("zero2.npy'")));
  EXPECT_EQ(said.find("image '"), std::string::npos) << said;
  EXPECT_EQ(why.find("ink"), std::string::npos) << said;
  expect_error(
      "sample --n 100 --dim 3 --density '" + path("c.npy") + "'" + out,
      "data of type '<c8': expected real numbers (float16, 32 or 64, integers of 8 to 64 bits, bool; "
      "either byte order)");
  expect_error("sample --n 100 --dim 3 --density '" + path("short.npy") + "'" + out, "cut short");
  expect_error("sample --n 100 --dim 3 --gamma 2" + v + out, "--gamma and --invert apply to images only");
  expect_error("sample --n 100 --class '" + path("v.npy") + "'" + out, "3-D volume");
  expect_error("query --rect 0,0,1,1" + v + " -o '" + path("x.csv") + "'", "only the full sampler takes it");
  ASSERT_EQ(kdm("sample --n 100" + out).status, 0);
  expect_error("analyze '" + path("x.txt") + "'" + v, "is a 3-D volume, and the points are 2D");
  expect_error("sample --n 100 --dim 3 --aspect 1:2" + out, "--aspect W:H is a 2D domain's shape");
  expect_error("sample --n 100 --dim 3 --aspect 1:0:2" + out, "three sides X:Y:Z, each > 0; got '1:0:2'");
  expect_error(
      "sample --n 100 --dim 3 --aspect 2:1:0" + out,
      "one number > 0 (the x side over the others) or, in 3D, three sides X:Y:Z, each > 0; got '2:1:0'");
  EXPECT_EQ(kdm("sample --n 100 --dim 3 --aspect 2:1:0" + out).err.find("W:H"), std::string::npos);
  expect_error("sample --n 100 --dim 3 --aspect 1:x:2" + out, "got '1:x:2'");
  expect_error("sample --n 100 --dim 3 --aspect 1::2" + out, "got '1::2'");
  expect_error("sample --n 100 --aspect 1:2:3" + out, "add --dim 3");
  expect_error("sample --n 100 --aspect nan" + out, "--aspect must be a number > 0");
}

TEST_F(CliTest, SamplerCountsAndTemperaturesAtTheirLimits) {
  const std::string out = " -o '" + path("s.txt") + "'";
  expect_error("sample --n 0" + out, "resolution");          // n = 0 means "use --resolution"
  expect_error("sample --n 4000000000" + out, "too large");  // beyond 2^31 points
  // Over max_grid_nodes: the largest count that fits, the same figure whatever was asked (a constant's was
  // the count scaled by the grid's nodes: 8.86e6 from 1e8, 8.48e6 from 2^31 - 1).
  expect_error("sample --n 100000000" + out, "about 8.23e+06 points at most");
  expect_error("sample --n 20000000" + out, "about 8.23e+06 points at most");
  {  // A volume too: one dense voxel said 373 points at n = 5,000, then 14.7 at 373.
    std::vector<double> spike(64 * 64 * 64, 0.0);
    spike[(10 * 64 + 20) * 64 + 30] = 1;
    std::ofstream(path("spike.npy"), std::ios::binary) << npy_volume(spike, 64, 64, 64, "<f8");
    for (const char* n : {"5000", "100000"})
      expect_error(std::string("sample --dim 3 --n ") + n + " --density '" + path("spike.npy") + "'" + out,
                   "about 12 points at most");
  }
  // Over max_grid_nodes by resolution: the largest resolution that fits, not "about 0 points at most".
  expect_error("sample --n 0 --resolution 100000" + out, "a resolution of at most 1");
  expect_error("sample --n 100 --temperature nan" + out, "temperature");
  expect_error("sample --n 100 --temperature -0.5" + out, "temperature");
  expect_error("sample --n 100 --temperature 1e4" + out, "temperature must be at most 1000");
  // A 3D tube under 0.6 point spacings across stalled the sampler for minutes: refused at once.
  expect_error("sample --dim 3 --aspect 30000" + out, "0.51 of a point spacing across");
  expect_error("sample --dim 3 --n 1000 --aspect 7000" + out, "in 3D the sampler needs 0.6");
  expect_error("sample --dim 3 --aspect 0.002" + out, "a short side of at least about 0.35");
  EXPECT_EQ(kdm("sample --dim 3 --n 1000 --aspect 4000" + out).status, 0);
  const Outcome hot = kdm("sample --n 100 --temperature 1000" + out);  // the limit itself is taken
  EXPECT_EQ(hot.status, 0) << hot.err;
  expect_error("sample --n 100 --density const:0" + out, "const:V");  // all-zero density
  expect_error("sample --n 100 --density const:-1" + out, "const:V");
  expect_error("sample --n 100 --vector-lanes 5" + out, "vector-lanes");  // 16, 8 or 4 only
  // A step so large that nearly every move is refused still writes the points, with a warning naming it.
  const Outcome huge_step = kdm("sample --n 1000 --step 1e4" + out);
  EXPECT_EQ(huge_step.status, 0) << huge_step.err;
  EXPECT_NE(huge_step.err.find("--step 10000 is too large"), std::string::npos) << huge_step.err;
  const Outcome small_step = kdm("sample --n 1000 --step 0.1" + out);
  EXPECT_EQ(small_step.err.find("warning"), std::string::npos) << small_step.err;
  const Outcome one = kdm("sample --n 1" + out);
  ASSERT_EQ(one.status, 0) << one.err;
  // Analysing against an all-zero density: named as such, not as the sampler's need.
  const Outcome zero = kdm("analyze '" + path("s.txt") + "' --density const:0 -o '" + path("a") + "'");
  EXPECT_EQ(zero.status, 1);
  EXPECT_NE(zero.err.find("needs V > 0 here (zero everywhere"), std::string::npos) << zero.err;
  EXPECT_EQ(zero.err.find("sampler"), std::string::npos) << zero.err;
  EXPECT_EQ(first_set(path("s.txt")).size(), 1u);
}

// --timing: the throughput line, the model's time, then one line per level (coarsest first, grids doubling)
// whose set-up, burn-in and sweep times add up to no more than the whole run (within the printed rounding).
TEST_F(CliTest, SampleTimingReportsEveryLevel) {
  const Outcome r = kdm("sample --n 4096 --timing -o '" + path("s.txt") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  std::istringstream lines(r.out);
  std::string line;
  double total = -1, model = -1, levels_sum = 0;
  bool balanced = false;
  std::vector<int> grids;
  while (std::getline(lines, line)) {
    long long points = 0;
    int gx = 0, gy = 0, sweeps = 0;
    double seconds = 0, setup = -1, burn_in = -1, sweep_seconds = -1, before = 0, after = 0;
    if (std::sscanf(line.c_str(), "count balance mismatch before %lf after %lf", &before, &after) == 2) {
      EXPECT_LT(after, before) << line;  // the balance runs at 4,096 points too (a 63² coarsest grid)
      balanced = true;
    } else if (std::sscanf(line.c_str(), "points %lld seconds %lf", &points, &seconds) == 2) {
      EXPECT_EQ(points, 4096);
      total = seconds;
    } else if (std::sscanf(line.c_str(), "model seconds %lf", &seconds) == 1) {
      model = seconds;
    } else if (std::sscanf(line.c_str(),
                           "level grid %dx%d points %lld sweeps %d setup %lf burn_in %lf sweeps_seconds %lf",
                           &gx, &gy, &points, &sweeps, &setup, &burn_in, &sweep_seconds) == 7) {
      grids.push_back(gx);
      EXPECT_GT(sweeps, 0) << line;
      EXPECT_GE(setup, 0) << line;
      EXPECT_GE(burn_in, 0) << line;
      EXPECT_GT(sweep_seconds, 0) << line;
      levels_sum += setup + burn_in + sweep_seconds;
    } else {
      ADD_FAILURE() << "unexpected line: " << line;
    }
  }
  ASSERT_GE(grids.size(), 2u) << r.out;
  for (std::size_t l = 1; l < grids.size(); ++l) EXPECT_EQ(grids[l], 2 * grids[l - 1]) << r.out;
  EXPECT_GT(model, 0) << r.out;
  EXPECT_GT(total, 0) << r.out;
  EXPECT_LE(levels_sum + model, total + 5e-4) << r.out;  // each figure printed to 0.1 ms
  EXPECT_TRUE(balanced) << r.out;
}

// Without --threads a run takes its thread count from OMP_NUM_THREADS, else from the CPUs its affinity
// mask allows (what a build tool or container gives it), never from the hardware alone.
TEST_F(CliTest, DefaultThreadsFollowTheEnvironmentAndTheAffinityMask) {
  auto threads_used = [&](const std::string& args, const std::string& prefix) {
    const Outcome r = kdm("sample --n 300 --timing " + args + " -o '" + path("t.txt") + "'", prefix);
    EXPECT_EQ(r.status, 0) << prefix << " kdm " << args << "\n" << r.err;
    int threads = -1;
    const std::size_t at = r.out.find(" threads ");
    if (at != std::string::npos) threads = std::atoi(r.out.c_str() + at + 9);
    return threads;
  };
  EXPECT_EQ(threads_used("", "OMP_NUM_THREADS=3"), 3);
  EXPECT_EQ(threads_used("", "OMP_NUM_THREADS=1,2"), 1);  // a nesting list: its first level
  EXPECT_EQ(threads_used("--threads 2", "OMP_NUM_THREADS=1"), 2);
  EXPECT_EQ(threads_used("", "OMP_NUM_THREADS=1000"), 256);  // capped as --threads is
  if (std::system("taskset -c 0 true >/dev/null 2>&1") == 0) {
    EXPECT_EQ(threads_used("", "env -u OMP_NUM_THREADS taskset -c 0"), 1);
  }
}

TEST_F(CliTest, RuntimeScalesAtTheirLimits) {
  const std::string out = " -o '" + path("q.txt") + "'";
  const Outcome zero = kdm("query --rect 0,0,1,1 --scale 0" + out);  // defined: no points
  EXPECT_EQ(zero.status, 0) << zero.err;
  EXPECT_NE(zero.err.find("kdm query: 0 points"), std::string::npos) << zero.err;
  expect_error("query --rect 0,0,1,1 --scale 1e12" + out, "--scale 32768 or less");  // beyond the top level
  expect_error("query --rect 0,0,1,1 --scale -1" + out, "'--scale' must be >= 0, got -1");
  // An empty value (an unset shell variable) is no scale 0: refused, pointing at the command's own help.
  expect_error("query --rect 0,0,1,1 --scale ''" + out,
               "--scale: is empty (an unset variable?) (see kdm query --help)");
  expect_error("query --rect 0,0,1,1 --tile-size 0" + out,
               "'--tile-size' must be > 0, got 0");  // an error, no warning first
  // The advice can be followed: a limit printed to six digits is rounded down (smooth mode's deepest,
  // 2^55 = 3.6028797e16, rounded to nearest would print as 3.60288e+16, above it).
  const std::string deep = "query --rect 0,0,1e-7,1e-7 --mode smooth" + out + " --scale ";
  const Outcome refused = kdm(deep + "3.60288e+16");
  ASSERT_EQ(refused.status, 1);
  const std::size_t use = refused.err.find("use --scale ");
  ASSERT_NE(use, std::string::npos) << refused.err;
  const std::string advised = refused.err.substr(use + 12, refused.err.find(' ', use + 12) - use - 12);
  const Outcome followed = kdm(deep + advised);
  EXPECT_EQ(followed.status, 0) << advised << ": " << followed.err;
}

// An output that is a symbolic link is written through it, as cp and a shell's > do.
TEST_F(CliTest, OutputsThroughSymbolicLinksReplaceTheirTargets) {
  for (const std::string name : {"s.txt", "s.png", "s.svg"}) {
    const fs::path target = path("target-" + name), link = path(name);
    std::ofstream(target) << "old";
    fs::create_symlink(target, link);
    const Outcome r = kdm("sample --n 50 -o '" + link.string() + "'");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(fs::is_symlink(fs::symlink_status(link))) << name;
    EXPECT_GT(fs::file_size(target), 3u) << name;
  }
}

TEST_F(CliTest, UnwritableOutputsGiveOneLineErrors) {
  // A path below a regular file cannot be created, even by root (CI runs as root).
  write_bytes(path("file"), {'x'});
  const std::string bad = path("file") + "/sub";
  write_bytes(path("grey.png"), grey_png(2, 2, 8, {0, 64, 128, 192}));
  const std::string image = "'" + path("grey.png") + "'";
  std::ofstream(path("r.recipe")) << "levels 2\nbase_points 32\nsweeps 2\n";
  const char* prefix = "cannot";  // "cannot write ...", "cannot create ..."
  expect_error("sample --n 50 -o '" + bad + ".txt'", prefix);
  expect_error("sample --n 50 -o '" + bad + ".png'", prefix);
  expect_error("sample --n 50 -o '" + bad + ".svg'", prefix);
  expect_error("stipple " + image + " -o '" + bad + ".png'", prefix);
  expect_error("stipple " + image + " --region 0,0,.6,.6 --frames 3 -o '" + bad + ".txt'", prefix);
  expect_error("query --rect 0,0,1,1 -o '" + bad + ".csv'", prefix);
  write_bytes(path("pts.txt"),
              {'0', '.', '5', ' ', '0', '.', '5', '\n', '0', '.', '1', ' ', '0', '.', '2', '\n'});
  expect_error("analyze '" + path("pts.txt") + "' -o '" + bad + "'", prefix);
  expect_error("bake '" + path("r.recipe") + "' -o '" + bad + ".kdmt'", prefix);
  // A directory in the way of the output file.
  fs::create_directories(path("dir.txt"));
  expect_error("sample --n 50 -o '" + path("dir.txt") + "'", "dir.txt");
  // Refused before the work, which here would take minutes: a missing directory, an unknown format.
  expect_error("sample --n 100000000 -o '" + path("missing/s.txt") + "'", "directory");
  expect_error("stipple " + image + " --points 30000000 --method full -o '" + path("missing/s.png") + "'",
               "directory");
  expect_error("sample --n 100000000 -o '" + path("s.json") + "'", "unknown output format");
  expect_error("sample --n 99 --class const:1 --class const:1 --dim 3 -o '" + path("c.txt") + "'", "--dim 3");
  // Extensions in any case.
  ASSERT_EQ(kdm("stipple " + image + " -o '" + path("S.PNG") + "'").status, 0);
  EXPECT_TRUE(fs::exists(path("S.PNG")));
}

// kdm verify: a table per level on stdout; exit 0 when every check passes, else a one-line error. One level
// and two reference runs keep it short; the generator test runs the whole thing on the shipped set.
TEST_F(CliTest, VerifyPassesTheShippedSetAndFailsADamagedOne) {
  const std::string shipped = std::string(KDM_SOURCE_DIR) + "/tilesets/default.kdmt";
  const std::string quick = " --level 2 --runs 2 --no-seams";
  const Outcome good = kdm("verify '" + shipped + "'" + quick + " --level 2");  // named twice: judged once
  EXPECT_EQ(good.status, 0) << good.out << good.err;
  const std::size_t header = good.out.find("level 2, 512 points per tile");
  EXPECT_NE(header, std::string::npos) << good.out;
  EXPECT_EQ(good.out.find("level 2, 512 points per tile", header + 1), std::string::npos) << good.out;
  EXPECT_NE(good.out.find("checks passed"), std::string::npos) << good.out;
  // --level limits the glide track too: level 2 holds the keyframes in (128, 512] points per tile.
  EXPECT_NE(good.out.find(" 512.0  keyframe"), std::string::npos) << good.out;
  EXPECT_EQ(good.out.find(" 128.0  keyframe"), std::string::npos) << good.out;
  EXPECT_EQ(good.out.find(" 1024.0  keyframe"), std::string::npos) << good.out;

  kdm::TilesetData set;
  ASSERT_EQ(kdm::load_tileset(shipped, set), kdm::Status::kOk);
  kdm::Tile& tile = set.tiles[3];
  for (std::uint32_t i = tile.level_end[1], j = 0; i < tile.level_end[2]; ++i, ++j)  // a clump in a corner
    tile.points[i] = kdm::TilePoint::from_unit(0.1 + 0.001 * (j % 37), 0.1 + 0.001 * (j / 37));
  // The hand-over names sub-points near each point's old place: drop it.
  set.handover_zone = set.handover_level = set.handover_slack = 0;
  for (kdm::Tile& t : set.tiles) t.handover.clear(), t.appearing.clear();
  ASSERT_EQ(kdm::save_tileset(set, path("bad.kdmt")), kdm::Status::kOk);
  const Outcome bad = kdm("verify '" + path("bad.kdmt") + "'" + quick);
  EXPECT_EQ(bad.status, 2);  // judged and failed; a file that cannot be read is 1
  EXPECT_EQ(bad.err.rfind("kdm: error: ", 0), 0u) << bad.err;
  EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
  EXPECT_NE(bad.err.find("failed"), std::string::npos) << bad.err;
  EXPECT_NE(bad.out.find("FAIL tile 3 level 2"), std::string::npos) << bad.out;
  // A failed density names it as its table row prints it ("552.9", not "552"), so that the row is found.
  std::size_t named = 0;
  for (const char* failed : {"  FAIL at ", "  FAIL gliding at "})
    for (std::size_t at = bad.out.find(failed); at != std::string::npos; at = bad.out.find(failed, at + 1)) {
      const std::string number = bad.out.substr(
          at + std::strlen(failed), bad.out.find(' ', at + std::strlen(failed)) - at - std::strlen(failed));
      EXPECT_NE(number.find('.'), std::string::npos) << number;
      EXPECT_NE(bad.out.find(std::string(11 - std::min<std::size_t>(11, number.size()), ' ') + number + " "),
                std::string::npos)
          << number;
      ++named;
    }
  EXPECT_GT(named, 0u) << bad.out;
  // --quiet (build logs): the failed checks and the count, no tables.
  const Outcome quiet = kdm("verify --quiet '" + path("bad.kdmt") + "'" + quick);
  EXPECT_EQ(quiet.status, 2);
  EXPECT_EQ(kdm("verify '" + path("no-such.kdmt") + "'" + quick).status, 1);  // not judged: unreadable
  EXPECT_NE(quiet.out.find("FAIL tile 3 level 2"), std::string::npos) << quiet.out;
  EXPECT_NE(quiet.out.find(" checks failed\n"), std::string::npos) << quiet.out;
  EXPECT_EQ(quiet.out.find("level 2, 512 points per tile"), std::string::npos) << quiet.out;
  EXPECT_EQ(quiet.out.find("result"), std::string::npos) << quiet.out;  // a table's header
  EXPECT_LT(std::count(quiet.out.begin(), quiet.out.end(), '\n'),
            std::count(bad.out.begin(), bad.out.end(), '\n') / 2)
      << quiet.out;

  expect_error("verify '" + path("missing.kdmt") + "'", "missing.kdmt");
  expect_error("verify '" + shipped + "' --level 9", "level 9");
  expect_error("verify '" + shipped + "' --handover-rows 0", "--handover-rows");
  expect_error("verify '" + shipped + "' --runs 1", "runs");
}

TEST_F(CliTest, BadCommandLinesGiveOneLineErrors) {
  const std::string out = " -o '" + path("x.txt") + "'";
  expect_error("", "subcommand");
  expect_error("frobnicate", "unknown subcommand 'frobnicate'");
  expect_error("sample --n abc" + out, "--n");
  expect_error("sample --n -5" + out, "--n");
  // Counts also in float notation when whole (1e3); a fraction or past 2^63 refused by name.
  expect_error("sample --n 1.5" + out, "--n: must be a whole number, got 1.5");
  expect_error("stipple x.png --points 99999999999999999999" + out, "--points: must be below 2^63");
  const Outcome thousand = kdm("sample --n 1e3" + out);
  ASSERT_EQ(thousand.status, 0) << thousand.err;
  EXPECT_NE(thousand.err.find("1000 points"), std::string::npos) << thousand.err;
  expect_error("sample --n 10", "--output");
  expect_error("sample --n 10 --aspect -1" + out, "--aspect");
  // W:H is the shape W / H; in 3D it is refused, where one number or X:Y:Z says which sides.
  ASSERT_EQ(kdm("sample --n 200 --aspect 3:2 -o '" + path("wh.txt") + "'").status, 0);
  ASSERT_EQ(kdm("sample --n 200 --aspect 1.5 -o '" + path("a.txt") + "'").status, 0);
  EXPECT_EQ(slurp(path("wh.txt")), slurp(path("a.txt")));
  expect_error("sample --dim 3 --n 10 --aspect 2:1" + out, "--aspect W:H is a 2D domain's shape");
  expect_error("sample --n 10 --aspect 1:2:3:4" + out,
               "one number, two sides W:H or three sides X:Y:Z, got 4");
  expect_error("sample --n 10 --width 0 -o '" + path("x.png") + "'", "--width");
  expect_error("sample --n 2000 --aspect 0.0001 -o '" + path("x.png") + "'", "too tall");  // 1024×10^7 px
  expect_error("stipple --frames 2x a.png" + out, "--frames");
  expect_error("query --rect 0,0,1" + out, "--rect");
  // An option that needs a value, followed by another option: named as such, not read as its value.
  expect_error("sample --n 10 --density" + out, "--density needs a value, but is followed by the option -o");
  expect_error("stipple a.png --points --help",
               "--points needs a value, but is followed by the option --help");
  // A density that is no file names the maps it could have meant.
  expect_error("query --rect 0,0,1,1 --density ramp" + out,
               "'ramp': no such file (a density is a picture, const:V");
  expect_error("query --rect 0,0,1,1 --class const:1 --density-rect 0,0,2,2 -o '" + path("x.csv") + "'",
               "(--density or --class)");
  const Outcome negative = kdm("query --rect -1,-1,0,0 --scale 40" + out);  // a value may start with '-'
  EXPECT_EQ(negative.status, 0) << negative.err;
}

// --threads has one limit in every command that takes it, checked before any work: negative counts and
// counts that would exhaust memory (std::bad_alloc) or time (a bake of 10^6 threads took 43 s) are refused.
TEST_F(CliTest, ThreadsAreBoundedInEveryCommand) {
  std::ofstream(path("r.recipe")) << "levels 1\nbase_points 32\ncolours 1\nkeyframes 0\nsweeps 1\n";
  ASSERT_EQ(kdm("bake '" + path("r.recipe") + "' --threads 256 -o '" + path("r.kdmt") + "'").status, 0);
  write_bytes(path("pts.txt"), {'0', '.', '5', ' ', '0', '.', '5', '\n'});
  for (const std::string& command : {"sample -n 10 -o '" + path("s.txt") + "'",
                                     "bake '" + path("r.recipe") + "' -o '" + path("x.kdmt") + "'",
                                     "verify '" + path("r.kdmt") + "' --runs 2",
                                     "analyze '" + path("pts.txt") + "' -o '" + path("a") + "'"})
    for (const char* threads : {"-5", "257", "1000000", "99999999999999999999"}) {
      SCOPED_TRACE(command + " --threads " + threads);
      expect_error(command + " --threads " + threads, "--threads: must be 0 (automatic) or 1 to 256");
    }
  EXPECT_FALSE(fs::exists(path("x.kdmt")) || fs::exists(path("a")));
}

// A PNG that cannot be written whole (here a file size limit, with SIGXFSZ ignored so the write fails with
// EFBIG) is an error and leaves no file, as .csv and .svg already did; it was a truncated PNG and exit 0.
TEST_F(CliTest, TruncatedPngWritesAreErrors) {
  write_bytes(path("grey.png"), grey_png(2, 2, 8, {0, 64, 128, 192}));
  const std::string limit = "trap '' XFSZ; ulimit -f 4;";  // 4 KiB: each picture below is larger
  for (const std::string& command : {"sample -n 2000 -o '" + path("s.png") + "'",
                                     "stipple '" + path("grey.png") + "' -o '" + path("s.png") + "'",
                                     "query --rect 0,0,1,1 --scale 2000 -o '" + path("s.png") + "'"}) {
    SCOPED_TRACE(command);
    const Outcome r = kdm(command, limit);
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_EQ(r.err.rfind("kdm: error: cannot write '" + path("s.png") + "': File too large", 0), 0u)
        << r.err;
    EXPECT_FALSE(fs::exists(path("s.png")));
    EXPECT_FALSE(fs::exists(path("s.png.tmp~")));
  }
  const Outcome whole = kdm("sample -n 2000 -o '" + path("s.png") + "'");  // without the limit: a PNG
  ASSERT_EQ(whole.status, 0) << whole.err;
  kdm::tools::GreyImage image;
  std::string error;
  EXPECT_TRUE(kdm::tools::load_grey_image(path("s.png"), image, error)) << error;
  EXPECT_EQ(image.width, 1024);
}

// A stipple keeps the image's tone: the dots' default size makes their ink cover the image's mean darkness,
// pale or dark, whatever the dot count. Measured 2026-12-06: 0.102 for 0.098 and 0.700 for 0.698 (dots
// that overlap lighten darker tones, antialiasing darkens the smallest dots); the old fixed size drew
// both at 0.20.
TEST_F(CliTest, StippleKeepsTheImagesTone) {
  for (const int grey : {230, 77}) {
    SCOPED_TRACE(grey);
    write_bytes(path("flat.png"),
                grey_png(64, 64, 8, std::vector<std::uint16_t>(64 * 64, std::uint16_t(grey))));
    for (const char* extra : {"", " --points 5000"}) {
      const Outcome run = kdm("stipple '" + path("flat.png") + "'" + extra + " -o '" + path("s.png") + "'");
      ASSERT_EQ(run.status, 0) << run.err;
      kdm::tools::GreyImage picture;
      std::string error;
      ASSERT_TRUE(kdm::tools::load_grey_image(path("s.png"), picture, error)) << error;
      double ink = 0;
      for (float v : picture.pixels) ink += 1 - v;
      EXPECT_NEAR(ink / picture.pixels.size(), 1 - grey / 255.0, 0.02) << extra;
    }
  }
}

// Integers are decimal whatever zeros pad them (CLI11 read "010" as octal 8, and "0800" as no number).
TEST_F(CliTest, ZeroPaddedIntegersAreDecimal) {
  const Outcome ten = kdm("sample -n 010 --seed 007 -o - --format txt");
  ASSERT_EQ(ten.status, 0) << ten.err;
  EXPECT_NE(ten.err.find("10 points"), std::string::npos) << ten.err;
  EXPECT_NE(ten.err.find("seed 7,"), std::string::npos) << ten.err;
  const Outcome eight_hundred = kdm("sample -n 0800 -o - --format txt");
  ASSERT_EQ(eight_hundred.status, 0) << eight_hundred.err;
  EXPECT_NE(eight_hundred.err.find("800 points"), std::string::npos) << eight_hundred.err;
  expect_error("sample -n -05 -o '" + path("x.txt") + "'", "--n must be >= 0");
}

// A tall image has no --width that fits a picture (3 × 4,000 pixels at the default 1,024 wide is 1.4 million
// high): --height sizes it instead, the width following its shape.
TEST_F(CliTest, StippleHeightSizesATallPicture) {
  write_bytes(path("strip.png"), grey_png(3, 4000, 8, std::vector<std::uint16_t>(3 * 4000, 100)));
  expect_error("stipple '" + path("strip.png") + "' -o '" + path("s.png") + "'",
               "give --height (the width follows its shape) or lower --width");
  const Outcome run = kdm("stipple '" + path("strip.png") + "' --height 2000 -o '" + path("s.png") + "'");
  ASSERT_EQ(run.status, 0) << run.err;
  kdm::tools::GreyImage picture;
  std::string error;
  ASSERT_TRUE(kdm::tools::load_grey_image(path("s.png"), picture, error)) << error;
  EXPECT_EQ(picture.height, 2000);
  EXPECT_EQ(picture.width, 2);  // 1.5 rounded
  expect_error("stipple '" + path("strip.png") + "' --height 2000 --width 4 -o '" + path("s.png") + "'",
               "--width excludes --height");
  expect_error("stipple '" + path("strip.png") + "' --height 70000 -o '" + path("s.png") + "'",
               "--height must be 1 to 65536");
  expect_error("stipple '" + path("strip.png") + "' --height 0 -o '" + path("s.png") + "'",
               "--height must be 1 to 65536");
}

// A flat tone is drawn between two keyframes of the glide track, not at one, where the dots that appeared
// late in its interval stand crowded: of 10,000 dots on a flat 50% grey, 0.64-0.94% lay nearer another than
// 0.45 d_hex at a keyframe (seeds 1-3), 0-0.02% between (stable mode 0.03%).
TEST_F(CliTest, StippleFlatTonesKeepTheirDotsApart) {
  write_bytes(path("grey.png"), grey_png(64, 64, 8, std::vector<std::uint16_t>(64 * 64, 128)));
  for (int seed = 1; seed <= 3; ++seed) {
    const Outcome run = kdm("stipple '" + path("grey.png") + "' --points 10000 --seed " +
                            std::to_string(seed) + " -o '" + path("g.csv") + "'");
    ASSERT_EQ(run.status, 0) << run.err;
    std::istringstream in(slurp(path("g.csv")));
    std::string line;
    std::getline(in, line);
    std::vector<double> x, y;
    double px = 0, py = 0;
    while (std::getline(in, line) && std::sscanf(line.c_str(), "%lf,%lf", &px, &py) == 2)
      x.push_back(px), y.push_back(py);
    ASSERT_GT(x.size(), 9000u);
    const double d_hex = std::sqrt(2 / (std::sqrt(3.0) * double(x.size())));
    std::size_t crowded = 0;
    for (std::size_t i = 0; i < x.size(); ++i)
      for (std::size_t j = 0; j < x.size(); ++j)
        if (i != j && std::hypot(x[i] - x[j], y[i] - y[j]) < 0.45 * d_hex) {
          ++crowded;
          break;
        }
    EXPECT_LT(double(crowded) / double(x.size()), 0.002) << seed;
  }
}

// The full sampler cannot place points across a domain too narrow for their count (a short side of one
// grid node): every one of them ended up in its left half. Such aspect ratios, from --aspect or from an
// image's shape, are refused by name; --aspect 0 is no aspect ratio.
TEST_F(CliTest, AspectRatiosTheSamplerCannotFillAreRefused) {
  const std::string out = " -o '" + path("s.csv") + "'";
  for (const char* aspect : {"5000", "0.0002", "1e300", "1e-300"}) {
    SCOPED_TRACE(aspect);
    expect_error(std::string("sample -n 300 --aspect ") + aspect + out, "too narrow for 300 points");
  }
  expect_error("sample -n 100 --aspect 0" + out, "--aspect must be a number > 0");
  std::vector<std::uint16_t> row(4000, 100);
  write_bytes(path("wide.png"), grey_png(4000, 1, 8, row));
  expect_error("sample -n 300 --density '" + path("wide.png") + "'" + out,
               "its long side is 4000 times its short side");
  expect_error("stipple '" + path("wide.png") + "' --method full --points 300" + out,
               "its long side is 4000 times its short side");
  EXPECT_FALSE(fs::exists(path("s.csv")));
}

// -n 0 needs --resolution, and a resolution so coarse that the model puts no point on it is refused too
// (it wrote an empty file and exit 0).
TEST_F(CliTest, ResolutionsThatHoldNoPointAreRefused) {
  const std::string out = " -o '" + path("s.txt") + "'";
  expect_error("sample -n 0 --resolution 1" + out, "resolution must be at least 2");
  expect_error("sample -n 0 --resolution 2" + out, "--resolution 2 is too coarse");
  EXPECT_FALSE(fs::exists(path("s.txt")));
  const Outcome three = kdm("sample -n 0 --resolution 3" + out);
  ASSERT_EQ(three.status, 0) << three.err;
  EXPECT_NE(three.err.find("kdm sample: 1 points"), std::string::npos) << three.err;
}

// stipple --scale, when given, must be a usable dot density: it used to fall back to --points silently.
TEST_F(CliTest, StippleScaleIsChecked) {
  write_bytes(path("grey.png"), grey_png(2, 2, 8, {0, 64, 128, 192}));
  const std::string stipple = "stipple '" + path("grey.png") + "' -o '" + path("s.txt") + "' --scale ";
  for (const char* scale : {"-1", "nan", "0", "inf"}) {
    SCOPED_TRACE(scale);
    expect_error(stipple + scale, "--scale must be a finite number > 0");
  }
  expect_error(stipple + "1e300 --method full", "scale 1e+300 asks for");
  // The tiles: said in dots and scale, not in the tile size derived from them.
  expect_error(stipple + "1e300", "more than one picture holds");
  expect_error(stipple + "1e-308", "too small to place a dot");
  EXPECT_FALSE(fs::exists(path("s.txt")));
  // --scale decides, not --points' default, and counts dots at full darkness: both methods place about
  // scale · mean darkness, the image's mean darkness 0.624 (the runtime's count is within 1% here).
  std::size_t counts[2] = {};
  for (int full = 0; full < 2; ++full) {
    ASSERT_EQ(kdm(stipple + "5000" + (full ? " --method full" : "")).status, 0);
    counts[full] = first_set(path("s.txt")).size();
  }
  const double expected = 5000 * (1 - (0 + 64 + 128 + 192) / (4 * 255.0));
  EXPECT_NEAR(counts[0], expected, 0.02 * expected);
  EXPECT_NEAR(counts[1], expected, 1.0);
}

// --class images cover one domain: images of different shapes (each stretched its own way) are refused;
// images of one shape are fine, at any resolutions.
TEST_F(CliTest, ClassImagesMustShareOneShape) {
  write_bytes(path("a.png"), grey_png(32, 32, 8, std::vector<std::uint16_t>(32 * 32, 100)));
  write_bytes(path("b.png"), grey_png(32, 16, 8, std::vector<std::uint16_t>(32 * 16, 100)));
  write_bytes(path("c.png"), grey_png(16, 16, 8, std::vector<std::uint16_t>(16 * 16, 200)));
  const std::string a = " --class '" + path("a.png") + "'", b = " --class '" + path("b.png") + "'",
                    c = " --class '" + path("c.png") + "'";
  expect_error("sample -n 100" + a + b + " -o '" + path("s.csv") + "'", "b.png' is 32x16");
  expect_error("query --rect 0,0,1,1" + b + a + " -o '" + path("q.csv") + "'", "a.png' is 32x32");
  EXPECT_FALSE(fs::exists(path("s.csv")) || fs::exists(path("q.csv")));
  EXPECT_EQ(kdm("sample -n 100" + a + c + " -o '" + path("s.csv") + "'").status, 0);
  EXPECT_EQ(kdm("query --rect 0,0,1,1" + a + c + " -o '" + path("q.csv") + "'").status, 0);
}

// Smaller refusals that named the wrong thing or nothing: verify's bars below 0 or NaN (silently off), a
// directory as an image ("larger than 2 GiB"), a hand-over zone 2 levels cannot hold ("in [1, 0]"), and
// points with no triangulation (pages of Qhull's internals).
TEST_F(CliTest, SmallRefusalsNameTheRealProblem) {
  const std::string shipped = "'" + std::string(KDM_SOURCE_DIR) + "/tilesets/default.kdmt'";
  expect_error("verify " + shipped + " --hole-largest -1", "--hole-largest must be a number >= 0");
  expect_error("verify " + shipped + " --hole-largest nan", "--hole-largest must be a number >= 0");
  expect_error("verify " + shipped + " --holes-per-1e5 -1", "--holes-per-1e5 must be a number >= 0");
  fs::create_directories(path("dir.png"));
  expect_error("sample -n 10 --density '" + path("dir.png") + "' -o '" + path("s.txt") + "'",
               "dir.png': it is a directory");
  std::ofstream(path("h.recipe")) << "levels 2\nbase_points 32\nkeyframes 2\nhandover_zone 1\n";
  expect_error("bake '" + path("h.recipe") + "' -o '" + path("h.kdmt") + "'",
               "handover_zone 1 needs at least 3 levels: 2 give 2 subtiles per side");
  // The shipped recipe cut to 2 levels, as a first try would: the levels its zone of 3 needs.
  std::ofstream(path("h.recipe")) << "levels 2\nbase_points 32\nkeyframes 2\nhandover_zone 3\n";
  expect_error("bake '" + path("h.recipe") + "' -o '" + path("h.kdmt") + "'",
               "handover_zone 3 needs at least 4 levels");
  // Values that would be silently dropped: a tile size of 0 and an empty -o, --fade for a points file.
  const std::string reference = "'" + std::string(KDM_TEST_DATA_DIR) + "/reference/ref_T0.5_n4096_01.txt'";
  expect_error("analyze " + reference + " --tile-size 0", "--tile-size must be > 0");
  expect_error("analyze " + reference + " -o ''", "-o names no directory");
  expect_error("analyze " + reference + " --aspect ''", "--aspect must be a number > 0");  // was ignored
  expect_error("stipple '" + std::string(KDM_SOURCE_DIR) + "/examples/sphere.png' --fade 0.2 -o '" +
                   path("f.csv") + "'",
               "--fade grows dots in pictures");
  for (const char* picture_only : {"--width 300", "--height 300", "--dot-size 3"})  // were silently ignored
    expect_error(
        "stipple '" + std::string(KDM_SOURCE_DIR) + "/examples/sphere.png' " + picture_only + " -o '" +
            path("f.csv") + "'",
        std::string(picture_only).substr(0, std::string(picture_only).find(' ')) + " sizes pictures");
  {  // A strip 1,000 times wider than high, at the default width: a picture 1 pixel high, said so.
    std::string error;
    ASSERT_TRUE(kdm::tools::write_png(path("strip.png"), kdm::tools::RgbImage(4000, 4, 100), error)) << error;
    const Outcome strip = kdm("stipple '" + path("strip.png") + "' -o '" + path("strip-dots.png") + "'");
    EXPECT_EQ(strip.status, 0) << strip.err;
    EXPECT_NE(strip.err.find("too small to show on the 1024x1 picture"), std::string::npos) << strip.err;
    const Outcome wide =
        kdm("stipple '" + path("strip.png") + "' --width 60000 -o '" + path("strip-dots.png") + "'");
    EXPECT_EQ(wide.err.find("too small"), std::string::npos) << wide.err;
  }
  std::ofstream(path("empty.recipe")) << "# a comment only\n\n  # indented\n";  // not minutes of defaults
  expect_error("bake '" + path("empty.recipe") + "' -o '" + path("e.kdmt") + "'", "gives no key");
  // --gamma named as the option, in every command that takes it (grey and in colour).
  const std::string sphere = "'" + std::string(KDM_SOURCE_DIR) + "/examples/sphere.png'";
  expect_error("sample --n 10 --density " + sphere + " --gamma 0 -o '" + path("g.txt") + "'",
               "--gamma must be a finite number > 0, got 0");
  expect_error("stipple " + sphere + " --colours cmyk --gamma -1 -o '" + path("g.png") + "'",
               "--gamma must be a finite number > 0, got -1");
  // The arguments swapped (a baked set where its recipe belongs), and standard output for a binary file.
  expect_error("bake " + shipped + " -o '" + path("s.kdmt") + "'", "is a tile-set file, not a recipe");
  std::ofstream(path("one.recipe")) << "levels 1\n";
  expect_error("bake '" + path("one.recipe") + "' -o -", "a tile set is written to a file");
  EXPECT_FALSE(fs::exists("-"));
  for (const char* points :
       {"0.5 0.5\n0.5 0.5\n0.5 0.5\n0.5 0.5\n", "0.1 0.5\n0.2 0.5\n0.3 0.5\n0.9 0.5\n"}) {
    // No triangulation: the empty circles are skipped, saying why, and the other measures still made.
    std::ofstream(path("flat.txt")) << points;
    const Outcome r = kdm("analyze '" + path("flat.txt") + "' --box -o '" + path("a") + "'");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("empty circles      skipped: the points are degenerate"), std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("nearest neighbour"), std::string::npos) << r.out;
    EXPECT_NE(slurp(path("a/metrics.json")).find("\"empty_circles_skipped\""), std::string::npos);
  }
  expect_error("verify '" + path("a/metrics.json") + "' --runs 1001", "--runs must be in [2, 1000]");
  // --level is refused by name, as --runs is, not by the parser's "Could not convert".
  expect_error("verify '" + path("a/metrics.json") + "' --level -1",
               "--level must be a level number >= 0 (the first is 0), got -1");
  expect_error("verify '" + path("a/metrics.json") + "' --level 5000000000",
               "--level 5000000000 is not in the tile set");
  // A directory or an endless device where a tile set or a recipe belongs fails at once, saying so.
  expect_error("info '" + path("dir.png") + "'", "is a directory, not a tile set file");
  expect_error("query --tileset '" + path("dir.png") + "' --rect 0,0,1,1 -o '" + path("q.csv") + "'",
               "is a directory");
  // An empty --tileset (an unset shell variable) is refused, as kdm info "" is, not read as the built-in set.
  for (const char* command : {"query --rect 0,0,1,1", "stipple '" KDM_SOURCE_DIR "/examples/sphere.png'"})
    expect_error(std::string(command) + " --tileset '' -o '" + path("q.csv") + "'",
                 "--tileset: is empty: give a tile-set file, or leave the option out for the built-in set");
  expect_error("bake '" + path("dir.png") + "' -o '" + path("d.kdmt") + "'", "cannot read recipe");
  expect_error("bake '" + path("absent.recipe") + "' -o '" + path("d.kdmt") + "'",
               "cannot open recipe '" + path("absent.recipe") + "': No such file or directory");
  if (fs::exists("/dev/zero")) {
    expect_error("info /dev/zero", "bad magic");
    expect_error("bake /dev/zero -o '" + path("z.kdmt") + "'", "not a recipe");
  }
}

// kdm analyze -o - writes metrics.json (labelled points' classes.json inside, as "classes") to standard
// output and the summary to standard error, and makes no directory "-"; several files say they are
// pooled; a class column read as z is pointed out.
TEST_F(CliTest, AnalyzeWritesJsonToStandardOutputAndSaysWhatItPooled) {
  std::ofstream labelled(path("l.csv"));
  labelled << "x,y,class\n";
  for (int i = 0; i < 300; ++i)
    labelled << (i * 0.618034) - std::floor(i * 0.618034) << ',' << (i + 0.5) / 300 << ',' << i % 2 << '\n';
  labelled.close();
  const Outcome r = kdm("analyze '" + path("l.csv") + "' --no-energy -o -", "cd '" + dir_.string() + "' &&");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.rfind("{\n  \"inputs\":", 0), 0u) << r.out.substr(0, 80);
  EXPECT_NE(r.out.find("\"coincident_points\":0"), std::string::npos);
  EXPECT_NE(r.out.find("\"classes\": {\"cross_class_closest\""), std::string::npos);
  EXPECT_EQ(r.out.substr(r.out.size() - 4), "}\n}\n");  // one JSON document
  EXPECT_EQ(r.out.find("nearest neighbour"), std::string::npos);
  EXPECT_NE(r.err.find("nearest neighbour"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("class 1 alone"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "-"));
  EXPECT_FALSE(fs::exists(dir_ / "points.png"));

  const Outcome two = kdm("analyze '" + path("l.csv") + "' '" + path("l.csv") + "' --no-energy");
  ASSERT_EQ(two.status, 0) << two.err;
  EXPECT_EQ(two.out.rfind("2 files pooled into one report", 0), 0u) << two.out;
  EXPECT_NE(two.out.find("2 set(s) of 300 2D points, torus distances (the set wraps around; --box"),
            std::string::npos)
      << two.out;
  EXPECT_EQ(kdm("analyze '" + path("l.csv") + "' --no-energy").out.find("pooled"), std::string::npos);

  std::ofstream(path("unnamed.csv")) << "0.1,0.2,0\n0.3,0.4,1\n0.5,0.7,1\n0.8,0.1,0\n";
  const Outcome z = kdm("analyze '" + path("unnamed.csv") + "' --no-energy");
  ASSERT_EQ(z.status, 0) << z.err;
  EXPECT_NE(z.err.find("kdm: warning: " + path("unnamed.csv") + ": 3D points whose z is 0 or 1"),
            std::string::npos)
      << z.err;
  std::ofstream(path("class2.csv")) << "0.1,0.2,0\n0.3,0.4,2\n";
  expect_error("analyze '" + path("class2.csv") + "'", "a class column needs the header line x,y,class");
  const Outcome help = kdm("analyze --help");
  EXPECT_NE(help.out.find("pooled into one report"), std::string::npos) << help.out;
  EXPECT_NE(help.out.find("no density test"), std::string::npos) << help.out;
  EXPECT_NE(help.out.find("NumPy .npy"), std::string::npos) << help.out;
}

/// Every number after `key` ("rms_z", "z") in a JSON text, in order.
std::vector<double> json_numbers(const std::string& json, const std::string& key) {
  std::vector<double> out;
  const std::string quoted = "\"" + key + "\":";
  for (std::size_t at = json.find(quoted); at != std::string::npos; at = json.find(quoted, at + 1))
    out.push_back(std::strtod(json.c_str() + at + quoted.size(), nullptr));
  return out;
}

// A set kdm sample drew 2:1 is measured in its rectangle (its header says the shape), and says so; --aspect
// overrides it (1: the unit square, where it reads squeezed); files of different shapes are refused.
TEST_F(CliTest, AnalyzeMeasuresASetInTheDomainItWasDrawnIn) {
  const std::string wide = "'" + path("wide.txt") + "'", square = "'" + path("square.txt") + "'";
  ASSERT_EQ(kdm("sample --n 2000 --aspect 2 --seed 4 -o " + wide).status, 0);
  ASSERT_EQ(kdm("sample --n 2000 --seed 4 -o " + square).status, 0);
  const Outcome own = kdm("analyze " + wide + " --no-energy -o -");
  ASSERT_EQ(own.status, 0) << own.err;
  EXPECT_NE(own.err.find("domain from the file header: aspect 2"), std::string::npos) << own.err;
  EXPECT_NE(own.err.find("1.414 × 0.7071 rectangle (aspect 2"), std::string::npos) << own.err;
  EXPECT_NE(own.out.find("\"sides\":[1.414213562,0.7071067812]"), std::string::npos)
      << own.out.substr(0, 400);
  const Outcome forced = kdm("analyze " + wide + " --aspect 1 --no-energy -o -");
  ASSERT_EQ(forced.status, 0) << forced.err;
  EXPECT_NE(forced.err.find("was sampled with aspect 2; measured with --aspect 1"), std::string::npos)
      << forced.err;
  EXPECT_EQ(forced.out.find("\"sides\""), std::string::npos);
  const Outcome flat = kdm("analyze " + square + " --no-energy -o -");
  ASSERT_EQ(flat.status, 0) << flat.err;
  EXPECT_EQ(flat.err.find("domain"), std::string::npos) << flat.err;  // the square's summary as it was
  // δavg (the first "davg"): the rectangle's reads as the square set's, the squeezed one far below (the
  // sampler's 2,000-point sets spread by about 0.003 between seeds).
  const double in_rectangle = json_numbers(own.out, "davg").at(0),
               in_square = json_numbers(flat.out, "davg").at(0),
               squeezed = json_numbers(forced.out, "davg").at(0);
  EXPECT_NEAR(in_rectangle, in_square, 0.02);
  EXPECT_LT(squeezed, in_square - 0.1);
  const Outcome given = kdm("analyze " + square + " --aspect 2 --no-energy");
  ASSERT_EQ(given.status, 0) << given.err;
  EXPECT_NE(given.out.find("domain from --aspect: aspect 2"), std::string::npos) << given.out;

  expect_error("analyze " + wide + " " + square, "sampled in different domains");
  EXPECT_EQ(kdm("analyze " + wide + " " + square + " --aspect 2 --no-energy").status, 0);
  expect_error("analyze " + wide + " --tile-size 0.25", "square tiles of the unit square");
  expect_error("analyze " + wide + " --aspect 2:1:1", "the points are 2D");
  expect_error("analyze " + wide + " --aspect 0", "--aspect must be a number > 0");
  expect_error("analyze " + wide + " --aspect 1:2:3:4", "two sides W:H or three sides X:Y:Z, got 4");
  // A 3D set: W:H refused as kdm sample --dim 3 refuses it (it was read as an aspect), and the tiling
  // diagnostics said to be skipped are skipped (they printed a seam test of a set that has no tiles).
  ASSERT_EQ(kdm("sample --dim 3 --n 400 -o '" + path("c3.txt") + "'").status, 0);
  expect_error("analyze '" + path("c3.txt") + "' --aspect 2:1", "the points are 3D");
  const Outcome untiled = kdm("analyze '" + path("c3.txt") + "' --tile-size 0.25 --no-energy");
  ASSERT_EQ(untiled.status, 0) << untiled.err;
  EXPECT_NE(untiled.err.find("tiling diagnostics are 2D only; skipped"), std::string::npos) << untiled.err;
  EXPECT_EQ(untiled.out.find("tiling"), std::string::npos) << untiled.out;
  EXPECT_EQ(untiled.out.find("seams"), std::string::npos) << untiled.out;
  // W:H is the number W / H.
  const Outcome colon = kdm("analyze " + wide + " --aspect 4:2 --no-energy");
  ASSERT_EQ(colon.status, 0) << colon.err;
  EXPECT_NE(colon.out.find("domain from --aspect: aspect 2"), std::string::npos) << colon.out;

  // 3D: the box's three sides from the header.
  const std::string box = "'" + path("box.txt") + "'";
  ASSERT_EQ(kdm("sample --dim 3 --n 1000 --aspect 2:1:0.5 --seed 4 -o " + box).status, 0);
  const Outcome boxed = kdm("analyze " + box + " --no-energy");
  ASSERT_EQ(boxed.status, 0) << boxed.err;
  EXPECT_NE(boxed.out.find("domain from the file header: sides 2:1:0.5"), std::string::npos) << boxed.out;
  EXPECT_NE(boxed.out.find("2 × 1 × 0.5 box"), std::string::npos) << boxed.out;
  EXPECT_NE(boxed.out.find("--aspect 1 measures in the unit cube"), std::string::npos) << boxed.out;
  // The same sides in other numbers are the same box, not an override.
  const Outcome same = kdm("analyze " + box + " --aspect 4:2:1 --no-energy");
  EXPECT_EQ(same.out.find("measured with --aspect"), std::string::npos) << same.out;

  // Standard input's header tells its shape too (kdm sample ... -o - | kdm analyze -).
  const Outcome piped = kdm("analyze - --no-energy -o - <" + wide);
  ASSERT_EQ(piped.status, 0) << piped.err;
  EXPECT_NE(piped.err.find("domain from the file header: aspect 2"), std::string::npos) << piped.err;
  EXPECT_EQ(json_numbers(piped.out, "davg").at(0), in_rectangle);
}

// A bounded set is measured as one: kdm sample --domain box, kdm query and kdm stipple say "domain box" in
// their .txt headers, and kdm analyze takes box distances from it (torus ones would join points across the
// walls), said in the summary; --torus overrides; a box and a torus file
// are not pooled.
TEST_F(CliTest, AnalyzeMeasuresABoundedSetAsOneFromItsHeader) {
  const std::string box = "'" + path("box.txt") + "'", torus = "'" + path("torus.txt") + "'";
  ASSERT_EQ(kdm("sample --n 2000 --domain box --seed 4 -o " + box).status, 0);
  ASSERT_EQ(kdm("sample --n 2000 --seed 4 -o " + torus).status, 0);
  EXPECT_NE(slurp(path("box.txt")).find("# density const:1, domain box\n"), std::string::npos);
  const Outcome own = kdm("analyze " + box + " --no-energy -o -");
  ASSERT_EQ(own.status, 0) << own.err;
  EXPECT_NE(own.err.find("domain from the file header: a bounded box (--torus overrides)"), std::string::npos)
      << own.err;
  EXPECT_NE(own.out.find("\"domain\":\"box\""), std::string::npos) << own.out.substr(0, 300);
  const Outcome flagged = kdm("analyze " + box + " --box --no-energy -o -");
  EXPECT_EQ(json_numbers(own.out, "davg").at(0), json_numbers(flagged.out, "davg").at(0));
  const Outcome forced = kdm("analyze " + box + " --torus --no-energy -o -");
  ASSERT_EQ(forced.status, 0) << forced.err;
  EXPECT_NE(forced.out.find("\"domain\":\"torus\""), std::string::npos);
  // A torus distance is never longer than the box's, and a box sample's points are not kept apart across
  // its walls: measured as a torus, points by the walls find nearer neighbours there.
  EXPECT_LT(json_numbers(forced.out, "davg").at(0), json_numbers(own.out, "davg").at(0));
  expect_error("analyze " + box + " " + torus, "sampled in different domains (a box and a torus)");
  EXPECT_EQ(kdm("analyze " + box + " " + torus + " --box --no-energy").status, 0);

  // A query's and a stipple's points: a box in their rectangle's shape.
  ASSERT_EQ(kdm("query --rect 0,0,4,2 --scale 300 -o '" + path("q.txt") + "'").status, 0);
  EXPECT_NE(slurp(path("q.txt")).find("# coordinates normalised to the rect, domain box, aspect 2\n"),
            std::string::npos);
  const Outcome query = kdm("analyze '" + path("q.txt") + "' --no-energy");
  ASSERT_EQ(query.status, 0) << query.err;
  EXPECT_NE(query.out.find("a bounded box"), std::string::npos) << query.out;
  EXPECT_NE(query.out.find("rectangle (aspect 2"), std::string::npos) << query.out;
  ASSERT_EQ(kdm("stipple '" + std::string(KDM_SOURCE_DIR) + "/examples/coffee.png' --points 3000 -o '" +
                path("s.txt") + "'")
                .status,
            0);
  const Outcome stipple = kdm("analyze '" + path("s.txt") + "' --no-energy");
  ASSERT_EQ(stipple.status, 0) << stipple.err;
  EXPECT_NE(stipple.out.find("a bounded box"), std::string::npos) << stipple.out;
  EXPECT_NE(stipple.out.find("rectangle (aspect 1.5"), std::string::npos) << stipple.out;
  // Standard input's header as a file's.
  const Outcome piped = kdm("analyze - --no-energy <" + box);
  EXPECT_NE(piped.out.find("a bounded box"), std::string::npos) << piped.out;
}

// A file without a domain header (CSV, .npy: a box sample, query or stipple among them) is measured as a
// square torus by default: analyze says so on standard error once, and not when --box, --torus or a .txt
// header settles it.
TEST_F(CliTest, AnalyzeNotesAFileWithoutADomainHeader) {
  const std::string csv = "'" + path("box.csv") + "'", txt = "'" + path("box.txt") + "'";
  ASSERT_EQ(kdm("sample --n 1000 --domain box --aspect 1.5 --seed 4 -o " + csv).status, 0);
  ASSERT_EQ(kdm("sample --n 1000 --domain box --aspect 1.5 --seed 4 -o " + txt).status, 0);
  EXPECT_EQ(slurp(path("box.csv")).rfind("x,y\n", 0), 0u);  // plain CSV, no comment lines
  const std::string note = "kdm: note: " + path("box.csv") + " has no domain header";
  const Outcome plain = kdm("analyze " + csv + " --no-energy");
  ASSERT_EQ(plain.status, 0) << plain.err;
  EXPECT_NE(plain.err.find(note), std::string::npos) << plain.err;
  EXPECT_EQ(plain.err.find("kdm: note:"), plain.err.rfind("kdm: note:")) << plain.err;  // once
  for (const char* said : {"measured as a torus in the unit square", "--box for a bounded set",
                           "--aspect for its shape", "--torus to keep the torus"})
    EXPECT_NE(plain.err.find(said), std::string::npos) << said << "\n" << plain.err;
  EXPECT_EQ(plain.out.find("kdm: note:"), std::string::npos) << plain.out;  // the summary stays clean
  // With the shape given, the note names the domain alone.
  const Outcome shaped = kdm("analyze " + csv + " --aspect 1.5 --no-energy");
  ASSERT_EQ(shaped.status, 0) << shaped.err;
  EXPECT_NE(shaped.err.find(note), std::string::npos) << shaped.err;
  EXPECT_EQ(shaped.err.find("--aspect for its shape"), std::string::npos) << shaped.err;
  EXPECT_EQ(shaped.err.find("unit square"), std::string::npos) << shaped.err;
  for (const std::string& settled : {csv + " --box", csv + " --torus", txt}) {
    const Outcome r = kdm("analyze " + settled + " --no-energy");
    ASSERT_EQ(r.status, 0) << settled << "\n" << r.err;
    EXPECT_EQ(r.err.find("kdm: note:"), std::string::npos) << settled << "\n" << r.err;
  }
  // Standard input without a header, and a refusal: the error stays its one line.
  const Outcome piped = kdm("analyze - --no-energy <" + csv);
  EXPECT_NE(piped.err.find("kdm: note: standard input has no domain header"), std::string::npos) << piped.err;
  expect_error("analyze " + csv + " --aspect 1.5 --tile-size 0.25", "square tiles of the unit square");
}

// --class-density: each class of a labelled set against its own density, the whole set against their
// sum, the classes' counts against their shares; refusals name the numbers.
TEST_F(CliTest, AnalyzeJudgesEachClassAgainstItsOwnDensity) {
  const std::string file = "'" + path("c.csv") + "'";
  ASSERT_EQ(kdm("sample --n 2000 --class const:1 --class ramp:20 --seed 3 -o " + file).status, 0);
  const std::string own = " --class-density const:1 --class-density ramp:20";
  const Outcome r = kdm("analyze " + file + own + " --no-energy -o -");
  ASSERT_EQ(r.status, 0) << r.err;
  // The whole set's, then class 0's and class 1's. Seeds 1..6: class 1's RMS z 0.24–0.42 against its
  // ramp, 4.31–4.40 against one uniform --density (as every class was judged before); bars between.
  const std::vector<double> z = json_numbers(r.out, "rms_z");
  ASSERT_EQ(z.size(), 3u) << r.out;
  for (double v : z) EXPECT_LT(v, 0.7);
  const Outcome uniform = kdm("analyze " + file + " --density const:1 --no-energy -o -");
  ASSERT_EQ(json_numbers(uniform.out, "rms_z").size(), 3u) << uniform.err;
  EXPECT_GT(json_numbers(uniform.out, "rms_z")[2], 2.5);
  EXPECT_NE(r.err.find("all classes together, against the sum of the --class-density densities"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("class 1 alone, against --class-density ramp:20:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(of the --class-density sum)"), std::string::npos) << r.err;
  // Shares: the sampler splits its points by the same integrals (|z| ≪ 1); const:3 for class 0 predicts
  // more of them than it has (z about −22 at this split; binomial sd about 20 points).
  const std::vector<double> shares = json_numbers(r.out, "z");
  ASSERT_EQ(shares.size(), 2u) << r.out;
  for (double v : shares) EXPECT_LT(std::abs(v), 0.5);
  const Outcome scaled =
      kdm("analyze " + file + " --class-density const:3 --class-density ramp:20 --no-energy -o -");
  ASSERT_EQ(json_numbers(scaled.out, "z").size(), 2u) << scaled.err;
  EXPECT_LT(json_numbers(scaled.out, "z")[0], -10);
  // With --density too, that judges the whole set alone (seeds 1..6: RMS z 1.12–1.17 against const:1,
  // 0.20–0.26 against the sum); the classes keep theirs.
  const Outcome both = kdm("analyze " + file + own + " --density const:1 --no-energy -o -");
  ASSERT_EQ(json_numbers(both.out, "rms_z").size(), 3u) << both.err;
  EXPECT_GT(json_numbers(both.out, "rms_z")[0], 0.7);
  EXPECT_LT(json_numbers(both.out, "rms_z")[2], 0.7);
  EXPECT_NE(both.err.find("all classes together, against --density"), std::string::npos) << both.err;
  // Without --class-density nothing about shares is written.
  EXPECT_EQ(uniform.out.find("shares"), std::string::npos);

  expect_error("analyze " + file + " --class-density const:1",
               "1 --class-density given, but the points' classes run 0 to 1 (2 classes)");
  // A class after the last label holds no points, as kdm sample --class const:0 leaves it: counted as 0.
  const Outcome empty_last = kdm("analyze " + file + own + " --class-density const:0 --no-energy -o -");
  ASSERT_EQ(empty_last.status, 0) << empty_last.err;
  EXPECT_NE(empty_last.out.find("{\"class\": 2, \"share\": 0, \"count\": 0, \"expected\": 0,"),
            std::string::npos)
      << empty_last.out;
  expect_error("analyze " + file + " --class-density const:1 --class-density nothing:2",
               "--class-density for class 1: density 'nothing:2'");
  expect_error("analyze " + file + " --class-density const:0 --class-density ramp:20",
               "class 0's density is zero everywhere, but the class has");
  EXPECT_EQ(kdm("analyze " + file + " --class-density const:0 --class-density ramp:20").out, "");  // at once
  ASSERT_EQ(kdm("sample --n 200 -o '" + path("u.txt") + "'").status, 0);
  expect_error("analyze '" + path("u.txt") + "'" + own, "--class-density needs labelled points");
  EXPECT_NE(kdm("analyze --help").out.find("--class-density"), std::string::npos);
}

// '-' is standard input for a recipe and for a tile set; a recipe where a tile set belongs, and a set
// where a recipe belongs, are named as such; a damaged size field is a damaged header, not a cut file.
TEST_F(CliTest, RecipesAndTileSetsComeFromStandardInputAndAreToldApart) {
  std::ofstream(path("r.recipe"))
      << "# a first comment longer than the tile-set header's 64 fixed bytes, so "
         "that a reader sees no key in them\nlevels 1\nbase_points 32\ncolours 1\n"
         "sweeps 1\n";
  const Outcome baked = kdm("bake - --threads 1 -o '" + path("r.kdmt") + "' < '" + path("r.recipe") + "'");
  ASSERT_EQ(baked.status, 0) << baked.err;
  const Outcome info = kdm("info - < '" + path("r.kdmt") + "'");
  EXPECT_EQ(info.status, 0) << info.err;
  EXPECT_NE(info.out.find("(standard input) (" + std::to_string(fs::file_size(path("r.kdmt"))) + " bytes)"),
            std::string::npos)
      << info.out;
  EXPECT_NE(info.out.find("  levels 1\n"), std::string::npos) << info.out;
  const Outcome verified = kdm("verify - --runs 2 --no-seams < '" + path("r.kdmt") + "'");
  EXPECT_EQ(verified.status, 0) << verified.out << verified.err;
  EXPECT_NE(verified.out.find("checks passed"), std::string::npos) << verified.out;
  for (const char* command : {"info", "verify"}) {
    SCOPED_TRACE(command);
    expect_error(
        std::string(command) + " '" + path("r.recipe") + "'",
        "bad magic): file does not start with KDMTILES; it looks like a recipe: bake it with kdm bake '" +
            path("r.recipe") + "' -o FILE.kdmt");
  }
  expect_error("query --tileset '" + path("r.recipe") + "' --rect 0,0,1,1 -o '" + path("q.csv") + "'",
               "it looks like a recipe: bake it with kdm bake");
  // kdm query reads its tile set from standard input as info and verify do: the same points as the file.
  const std::string query = " --rect 0,0,4,4 --scale 30 --format csv -o -";
  const Outcome piped = kdm("query --tileset -" + query + " < '" + path("r.kdmt") + "'");
  ASSERT_EQ(piped.status, 0) << piped.err;
  EXPECT_GT(std::count(piped.out.begin(), piped.out.end(), '\n'), 100) << piped.out;
  EXPECT_EQ(piped.out, kdm("query --tileset '" + path("r.kdmt") + "'" + query).out);
  expect_error("query --tileset -" + query + " < '" + path("r.recipe") + "'",
               "standard input: not a kdm tile set (bad magic)");
  expect_error("verify '" + path("r.kdmt") + "' --spectrum-budget -1",
               "--spectrum-budget must be a point count >= 0 (0: no spectra), got -1");
  expect_error("info - < '" + path("r.recipe") + "'", "standard input: not a kdm tile set (bad magic)");
  std::ofstream(path("notes.txt")) << "shopping list\n";  // not a recipe: no hint
  const Outcome notes = kdm("info '" + path("notes.txt") + "'");
  EXPECT_EQ(notes.err.find("looks like a recipe"), std::string::npos) << notes.err;
  expect_error("bake - -o '" + path("x.kdmt") + "' < '" + path("r.kdmt") + "'",
               "standard input is a tile-set file, not a recipe (its recipe: kdm info -)");
  std::ofstream(path("eq.recipe")) << "levels = 2\n";
  expect_error("bake '" + path("eq.recipe") + "' -o '" + path("x.kdmt") + "'",
               "recipe line 1: '=' is not used: write 'levels 2'");
  EXPECT_FALSE(fs::exists(path("x.kdmt")));
  std::string damaged = slurp(path("r.kdmt"));
  damaged[20] = static_cast<char>(damaged[20] ^ (1 << 4));  // the payload size's high bytes
  std::ofstream(path("damaged.kdmt"), std::ios::binary) << damaged;
  expect_error("info '" + path("damaged.kdmt") + "'",
               "tile-set header checksum mismatch: header bytes are damaged");
}

TEST_F(CliTest, VersionNamesTheLibraryAndTheFormat) {
  const Outcome r = kdm("--version");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find(std::string("kdm ") + kdm::version_string()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("tile-set format " + std::to_string(kdm::kTilesetFormatVersion)), std::string::npos)
      << r.out;
}

TEST_F(CliTest, HelpDescribesEveryOption) {
  for (const char* sub : {"", "sample", "stipple", "query", "analyze", "bake", "info", "verify"}) {
    const Outcome r = kdm(std::string(sub) + " --help");
    EXPECT_EQ(r.status, 0) << sub;
    // CLI11 prints "  --name TYPE  description"; an option without a description ends its line at the type.
    std::istringstream lines(r.out);
    std::vector<std::string> all;
    for (std::string line; std::getline(lines, line);) all.push_back(line);
    for (std::size_t i = 0; i < all.size(); ++i) {
      std::string line = all[i];
      if (line.rfind("  -", 0) != 0) continue;
      if (i + 1 < all.size() && all[i + 1].rfind("      ", 0) == 0) line += all[i + 1];  // wrapped text
      std::istringstream words(line);
      std::vector<std::string> w{std::istream_iterator<std::string>(words), {}};
      const bool has_text = std::any_of(w.begin(), w.end(), [](const std::string& s) {
        return s.size() > 1 && std::islower(static_cast<unsigned char>(s[0])) && s[0] != '-';
      });
      EXPECT_TRUE(has_text) << "kdm " << sub << " --help: option without a description: " << line;
      // An option that takes a value (a TYPE word after its name) shows its default or is required.
      const std::string type = w.size() > 1 ? w[1].substr(0, w[1].find_first_of(":=")) : "";
      const bool takes_value = !type.empty() && std::all_of(type.begin(), type.end(), [](char c) {
        return std::isupper(static_cast<unsigned char>(c));
      });
      const bool default_shown =
          takes_value && (w[1].find('=') != std::string::npos || line.find("default") != std::string::npos ||
                          line.find("REQUIRED") != std::string::npos);
      EXPECT_TRUE(!takes_value || default_shown) << "kdm " << sub << " --help: no default: " << line;
    }
  }
}

// Every density a NumPy .npy array can give says so in its command's help, and the command reads one.
TEST_F(CliTest, HelpNamesNpyWhereADensityReadsOne) {
  std::vector<double> values(4 * 6);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = i % 6 < 3 ? 4 : 1;  // dense on the left
  std::ofstream(path("d.npy"), std::ios::binary) << npy_volume(values, 1, 4, 6, "<f8", "4, 6");
  const std::string d = " '" + path("d.npy") + "'";
  struct Case {
    const char *sub, *option;
    std::string run;
  };
  for (const Case& c :
       {Case{"query", "--density",
             "query --rect 0,0,2,1 --scale 400 --density" + d + " -o '" + path("q.txt") + "'"},
        Case{"sample", "--density", "sample --n 400 --density" + d + " -o '" + path("s.txt") + "'"},
        Case{"stipple", "image", "stipple" + d + " --points 400 -o '" + path("p.txt") + "'"},
        Case{"analyze", "--density", "analyze '" + path("s.txt") + "' --no-energy --density" + d}}) {
    const Outcome run = kdm(c.run);
    EXPECT_EQ(run.status, 0) << c.run << "\n" << run.err;
    std::istringstream lines(kdm(std::string(c.sub) + " --help").out);
    std::string help;  // the option's line, and the lines its text wraps onto
    for (std::string line; std::getline(lines, line);)
      if (line.rfind(std::string("  ") + c.option + " ", 0) == 0 ||
          (!help.empty() && line.rfind("      ", 0) == 0))
        help += line;
      else if (!help.empty())
        break;
    EXPECT_NE(help.find("NumPy .npy"), std::string::npos)
        << "kdm " << c.sub << " --help, " << c.option << ": " << help;
  }
  // The query's points follow the array: four times as dense on its left half.
  const kdm::tools::PointSet set = first_set(path("q.txt"));
  std::size_t left = 0;
  for (std::size_t i = 0; i < set.size(); ++i) left += set.coords[2 * i] < 0.5;
  EXPECT_GT(left, 3 * (set.size() - left)) << left << " of " << set.size();
}

// Reads a frame written by `stipple --frames`: its points in image UV and its rectangle (from the header).
struct Frame {
  double region[4] = {0, 0, 0, 0};
  std::vector<double> uv;
};

Frame read_frame(const std::string& path) {
  Frame f;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);)
    if (line.rfind("# region ", 0) == 0)
      std::sscanf(line.c_str(), "# region %lf,%lf,%lf,%lf", &f.region[0], &f.region[1], &f.region[2],
                  &f.region[3]);
  std::vector<kdm::tools::PointSet> sets;
  std::string error;
  EXPECT_TRUE(kdm::tools::read_point_sets(path, sets, error)) << error;
  if (sets.empty()) return f;
  for (std::size_t i = 0; i < sets[0].size(); ++i)
    for (int k = 0; k < 2; ++k)
      f.uv.push_back(f.region[k] + sets[0].coords[2 * i + k] * (f.region[k + 2] - f.region[k]));
  return f;
}

TEST_F(CliTest, StippleFramesZoomCoherently) {
  const std::string image = std::string(KDM_SOURCE_DIR) + "/examples/sphere.png";
  // Stable mode: a dot stays where it is as the zoom raises the density (smooth mode glides them).
  const Outcome r =
      kdm("stipple '" + image + "' --points 4000 --region 0.3,0.35,0.85,0.9 --frames 4 --mode stable -o '" +
          path("zoom.txt") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(fs::exists(path("zoom.txt")));
  EXPECT_FALSE(fs::exists(path("zoom_0004.txt")));
  std::vector<Frame> frames;
  for (int i = 0; i < 4; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "zoom_%04d.txt", i);
    ASSERT_TRUE(fs::exists(path(name))) << name;
    frames.push_back(read_frame(path(name)));
  }
  EXPECT_EQ(std::vector<double>(frames[0].region, frames[0].region + 4), (std::vector<double>{0, 0, 1, 1}));
  EXPECT_EQ(std::vector<double>(frames[3].region, frames[3].region + 4),
            (std::vector<double>{0.3, 0.35, 0.85, 0.9}));
  for (int i = 0; i + 1 < 4; ++i) {
    const Frame &a = frames[i], &b = frames[i + 1];
    // Geometric zoom: the extents shrink by the same factor every frame (0.55^(1/3) here).
    EXPECT_NEAR((b.region[2] - b.region[0]) / (a.region[2] - a.region[0]), std::cbrt(0.55), 1e-9);
    // Coherence: every dot of frame i inside frame i+1's rectangle (away from its edges by more than the
    // .txt rounding) is a dot of frame i+1 at the same place (to float precision: the runtime writes floats).
    std::size_t kept = 0;
    for (std::size_t p = 0; p < a.uv.size(); p += 2) {
      const double x = a.uv[p], y = a.uv[p + 1], eps = 1e-9;
      if (!(x > b.region[0] + eps && x < b.region[2] - eps && y > b.region[1] + eps && y < b.region[3] - eps))
        continue;
      bool found = false;
      for (std::size_t q = 0; q < b.uv.size() && !found; q += 2)
        found = std::fabs(b.uv[q] - x) < 1e-6 && std::fabs(b.uv[q + 1] - y) < 1e-6;  // float positions
      EXPECT_TRUE(found) << "frame " << i << " dot (" << x << ", " << y << ") is gone from frame " << i + 1;
      kept += found;
    }
    EXPECT_GT(kept, 500u) << "frame " << i;                            // the check above is not vacuous
    EXPECT_GT(b.uv.size() / 2, kept + kept / 5) << "frame " << i + 1;  // the zoom adds dots (~1.7×)
  }
}

// --fade: a dot's area grows from 0 where it appears to full a fraction F of density later, so about
// F / (1 + F) of the dots are partly grown (1/6 at F = 0.2: the dots whose thresholds lie within the last
// 1/1.2 of the count; measured 0.172) and the picture lightens by about F / (2 + 2F) (0.083; measured 0.092).
TEST_F(CliTest, StippleFadeGrowsAppearingDots) {
  const std::string image = "'" + std::string(KDM_SOURCE_DIR) + "/examples/sphere.png'";
  const auto radii = [&](const std::string& name) {
    std::vector<double> r;
    const std::string svg = slurp(path(name));
    for (std::size_t at = svg.find(" r=\""); at != std::string::npos; at = svg.find(" r=\"", at + 1))
      r.push_back(std::atof(svg.c_str() + at + 4));
    return r;
  };
  ASSERT_EQ(kdm("stipple " + image + " --points 20000 -o '" + path("plain.svg") + "'").status, 0);
  const Outcome faded = kdm("stipple " + image + " --points 20000 --fade 0.2 -o '" + path("fade.svg") + "'");
  ASSERT_EQ(faded.status, 0) << faded.err;
  const std::vector<double> plain = radii("plain.svg"), fade = radii("fade.svg");
  ASSERT_GT(plain.size(), 19000u);
  const double full = plain.front();
  EXPECT_TRUE(std::all_of(plain.begin(), plain.end(), [&](double r) { return r == full; }));
  EXPECT_NE(faded.err.find(std::to_string(plain.size()) + " dots"), std::string::npos)
      << faded.err;  // the same dots
  double ink = 0;
  std::size_t grown = 0;
  for (double r : fade) {
    ASSERT_GT(r, 0);
    ASSERT_LE(r, full * (1 + 1e-5));
    ink += (r / full) * (r / full);
    grown += r >= full * (1 - 1e-5);
  }
  // Every dot present is drawn: its weight, read at its stable position where the query reads the
  // density, is above 0 (read where it had glided to, some were 0).
  EXPECT_EQ(fade.size(), plain.size());
  const double partial = 1 - double(grown) / double(plain.size());  // dots of size 0 are not drawn
  EXPECT_GT(partial, 0.12);
  EXPECT_LT(partial, 0.22);
  EXPECT_NEAR(1 - ink / double(plain.size()), 0.09, 0.03);
  expect_error("stipple " + image + " --fade -1 -o '" + path("x.png") + "'", "--fade");
  expect_error("stipple " + image + " --fade 0.2 --method full -o '" + path("x.png") + "'", "--method tiles");
}

// A zoomed region keeps the whole image's dot size whether --points or --scale counts the dots, and a
// picture's comments stay comments whatever the image is called ("--" ends an XML comment).
TEST_F(CliTest, StippleRegionsKeepTheDotSizeAndPathsStayComments) {
  const std::string image = path("a--b&<c>.png");
  fs::copy_file(std::string(KDM_SOURCE_DIR) + "/examples/sphere.png", image);
  auto radius = [&](const std::string& options) {
    const Outcome r = kdm("stipple '" + image + "' " + options + " -o '" + path("s.svg") + "'");
    EXPECT_EQ(r.status, 0) << r.err;
    const std::string svg = slurp(path("s.svg"));
    for (std::size_t at = svg.find("<!--"); at != std::string::npos; at = svg.find("<!--", at + 4)) {
      const std::size_t end = svg.find("-->", at + 4);
      EXPECT_NE(end, std::string::npos);
      EXPECT_EQ(svg.substr(at + 4, end - at - 4).find("--"), std::string::npos) << svg.substr(at, end - at);
    }
    const std::size_t r_at = svg.find(" r=\"");
    return r_at == std::string::npos ? 0.0 : std::atof(svg.c_str() + r_at + 4);
  };
  for (const char* count : {"--points 8000", "--scale 50000"}) {
    SCOPED_TRACE(count);
    const double whole = radius(count);
    EXPECT_GT(whole, 0);
    EXPECT_DOUBLE_EQ(radius(std::string(count) + " --region 0.25,0.25,0.75,0.75"), whole);
  }
}

// A region's zoom is 1 / its width (the picture keeps its width), whatever its shape: on a uniform grey
// the dots per unit of picture area stay those of the whole image. The runtime's count for a uniform
// density is the expectation up to partly covered edge tiles; 5% is several times that at these counts.
TEST_F(CliTest, StippleRegionsOfAnyShapeKeepTheDotDensity) {
  write_bytes(path("grey.png"), grey_png(1, 1, 8, {128}));
  const auto dots = [&](const std::string& region) {
    const Outcome r = kdm("stipple '" + path("grey.png") + "' --points 2000 --region " + region + " -o '" +
                          path("r.txt") + "'");
    EXPECT_EQ(r.status, 0) << r.err;
    return double(first_set(path("r.txt")).size());
  };
  EXPECT_NEAR(dots("0,0,0.25,1"), 8000.0, 400.0);  // 4× the density over a quarter of the image
  EXPECT_NEAR(dots("0,0,1,0.25"), 500.0, 25.0);    // the whole image's size, a quarter as tall
  EXPECT_NEAR(dots("0.2,0.3,0.7,0.8"), 2000.0, 100.0);
}

// Frames of a zoom into a region of another shape than the image's all have the region's shape: the first
// holds the whole image with blank paper beside it (no dot there), and the zoom is geometric.
TEST_F(CliTest, StippleFramesOfAnotherShapeKeepTheRegionsShape) {
  write_bytes(path("grey.png"), grey_png(1, 1, 8, {128}));
  const Outcome r = kdm("stipple '" + path("grey.png") +
                        "' --points 2000 --region 0,0,0.5,1 --frames 3 -o '" + path("f.txt") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  std::vector<Frame> frames;
  for (int i = 0; i < 3; ++i) frames.push_back(read_frame(path("f_000" + std::to_string(i) + ".txt")));
  EXPECT_EQ(std::vector<double>(frames[0].region, frames[0].region + 4),
            (std::vector<double>{0, -0.5, 1, 1.5}));
  EXPECT_EQ(std::vector<double>(frames[2].region, frames[2].region + 4), (std::vector<double>{0, 0, 0.5, 1}));
  for (const Frame& f : frames) {
    EXPECT_NEAR((f.region[2] - f.region[0]) / (f.region[3] - f.region[1]), 0.5, 1e-12);
    for (std::size_t p = 1; p < f.uv.size(); p += 2) ASSERT_TRUE(f.uv[p] >= 0 && f.uv[p] < 1) << f.uv[p];
  }
  EXPECT_NEAR((frames[1].region[2] - frames[1].region[0]), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(double(frames[0].uv.size() / 2), 2000.0, 100.0);  // the whole image at its own zoom
  EXPECT_NEAR(double(frames[2].uv.size() / 2), 4000.0, 200.0);  // half of it at twice the zoom
}

// Transparent pixels are paper: white under dark dots, black under --invert's bright ones, so neither
// puts dots there. The image: its left half opaque mid-grey, its right half transparent.
TEST_F(CliTest, StippleLeavesTransparentPixelsEmpty) {
  std::vector<std::uint16_t> samples;
  for (int x = 0; x < 8; ++x) samples.insert(samples.end(), {128, std::uint16_t(x < 4 ? 255 : 0)});
  write_bytes(path("half.png"), grey_png(8, 1, 8, samples, 2));
  for (const char* invert : {"", " --invert"}) {
    SCOPED_TRACE(invert);
    const Outcome r =
        kdm("stipple '" + path("half.png") + "' --points 2000" + invert + " -o '" + path("h.txt") + "'");
    ASSERT_EQ(r.status, 0) << r.err;
    const kdm::tools::PointSet set = first_set(path("h.txt"));
    ASSERT_GT(set.size(), 1500u);
    std::size_t right = 0;  // past the last opaque texel's centre, where bilinear reaches zero
    for (std::size_t i = 0; i < set.size(); ++i) right += set.coords[2 * i] > 4.5 / 8;
    EXPECT_EQ(right, 0u);
  }
  expect_error("stipple '" + path("half.png") + "' -o '" + path("half.png") + "'", "is the input image");
  expect_error("stipple '" + path("half.png") + "' --colours cmyk -o '" + path("c.txt") + "'", ".csv");
}

// Inverted, the tone is the luminance on black paper, transparent black: black at any opacity has no ink
// (the composited grey's float rounding once left invisible dots where opacity was not 1/2), and white
// at opacity a has a tone of a, so that dots follow the opacity.
TEST_F(CliTest, StippleInvertedLaysTransparencyOnBlack) {
  std::vector<std::uint16_t> black, black64, white;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 256; ++x) {
      black.insert(black.end(), {0, std::uint16_t(x)});
      black64.insert(black64.end(), {0, 64});
      white.insert(white.end(), {255, std::uint16_t(x)});
    }
  for (const auto& [name, samples] : {std::pair{"black.png", black}, std::pair{"black64.png", black64}}) {
    SCOPED_TRACE(name);
    write_bytes(path(name), grey_png(256, 8, 8, samples, 2));
    const Outcome o = kdm("stipple '" + path(name) + "' --points 4000 --invert -o '" + path("b.csv") + "'");
    ASSERT_EQ(o.status, 0) << o.err;
    EXPECT_NE(o.err.find("has no ink"), std::string::npos) << o.err;
    const std::string csv = slurp(path("b.csv"));
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1) << csv.substr(0, 200);  // the header alone
  }
  write_bytes(path("white.png"), grey_png(256, 8, 8, white, 2));
  const Outcome o =
      kdm("stipple '" + path("white.png") + "' --points 4000 --invert -o '" + path("w.txt") + "'");
  ASSERT_EQ(o.status, 0) << o.err;
  const kdm::tools::PointSet set = first_set(path("w.txt"));
  std::size_t left = 0, right = 0;  // mean opacity 1/4 and 3/4
  for (std::size_t i = 0; i < set.size(); ++i) (set.coords[2 * i] < 0.5 ? left : right) += 1;
  EXPECT_NEAR(double(left + right), 4000.0, 200.0);
  EXPECT_NEAR(double(right) / double(left), 3.0, 0.3) << left << " " << right;
}

TEST_F(CliTest, StippleFramesRejectBadCounts) {
  const std::string image = "'" + std::string(KDM_SOURCE_DIR) + "/examples/sphere.png'";
  const std::string out = " -o '" + path("z.png") + "'";
  expect_error("stipple " + image + " --frames 1 --region 0,0,.5,.5" + out, "--frames");
  expect_error("stipple " + image + " --frames -3 --region 0,0,.5,.5" + out, "--frames");
  // Refused before anything loops over the frames (2·10^9 checked every frame's path first: minutes), and
  // past an int by name too.
  expect_error("stipple " + image + " --frames 2000000000 --region 0,0,.5,.5" + out, "from 2 to 10000");
  expect_error("stipple " + image + " --frames 2147483648 --region 0,0,.5,.5" + out, "from 2 to 10000");
  expect_error("stipple " + image + " --frames 5" + out, "--region");
  // A frame's printed region draws that frame again, though the first reach past the image; a zoom's end
  // must lie in it, and a region anywhere must meet it.
  const Outcome zoom =
      kdm("stipple " + image + " --region 0.2,0.3,0.6,0.5 --frames 3 -o '" + path("z.csv") + "'");
  ASSERT_EQ(zoom.status, 0) << zoom.err;
  const std::size_t at = zoom.err.find("region ") + 7;
  const std::string first = zoom.err.substr(at, zoom.err.find(' ', at) - at);
  EXPECT_EQ(first.rfind("-0.333", 0), 0u) << first;  // past the image's left side
  ASSERT_EQ(kdm("stipple " + image + " --region " + first + " -o '" + path("again.csv") + "'").status, 0);
  EXPECT_EQ(slurp(path("again.csv")), slurp(path("z_0000.csv")));
  expect_error("stipple " + image + " --region " + first + " --frames 3" + out, "for --frames");
  expect_error("stipple " + image + " --region 1.5,0,2,1" + out, "must meet the image");
  // Sides equal within rounding (0.75 - 0.55, 0.55 - 0.35) zoom out to the image exactly.
  const Outcome square =
      kdm("stipple " + image + " --region 0.55,0.35,0.75,0.55 --frames 2 -o '" + path("s.csv") + "'");
  EXPECT_NE(square.err.find("region 0,0,1,1 "), std::string::npos) << square.err;
  expect_error("stipple " + image + " --frames 5 --region 0,0,.2,.2 --mode stable" + out, "2× (");
  // Smooth mode descends into the built-in set's m × m subtiles, four depths deep: 2 · m^4 ×.
  const double m = kdm::Tileset::builtin().data().subtiles_per_side();
  char deepest[32];
  std::snprintf(deepest, sizeof deepest, "%g× (", 2 * m * m * m * m);
  expect_error("stipple " + image + " --frames 5 --region 0,0,1e-7,1e-7" + out, deepest);
  expect_error("stipple " + image + " --frames 5 --region 0,0,.5,.5 --method full" + out, "--method tiles");
  // A picture too large is said before any dot is placed (a sliver of the image at the default width).
  expect_error("stipple " + image + " --region 0.499,0,0.5,1" + out, "pixels is too tall");
  // Options of the tiles alone, which the full sampler would ignore.
  expect_error("stipple " + image + " --method full --mode stable" + out, "--mode applies to --method tiles");
  expect_error("stipple " + image + " --method full --tileset '" + std::string(KDM_SOURCE_DIR) +
                   "/tilesets/default.kdmt'" + out,
               "--tileset applies to --method tiles");
  EXPECT_FALSE(fs::exists(path("z_0000.png")));  // refused before any frame is written
}

// Users diff and commit point files: the same command must write the same bytes (no times, no dates).
TEST_F(CliTest, PointFilesAreByteIdenticalAcrossRuns) {
  const std::string image = "'" + std::string(KDM_SOURCE_DIR) + "/examples/sphere.png'";
  const std::vector<std::pair<std::string, std::string>> commands = {
      {"sample --n 3000 --seed 4 --threads 2", "sample"},
      {"sample --n 500 --density " + image + " --seed 2", "sample_image"},
      {"query --rect 0,0,4,4 --scale 300", "query"},
      {"query --rect 0,0,4,4 --scale 300 --density " + image, "query_image"},
      {"stipple " + image + " --points 4000", "stipple_tiles"},
      {"stipple " + image + " --points 1000 --method full", "stipple_full"},
  };
  for (const auto& [args, name] : commands)
    for (const char* ext : {".txt", ".csv", ".svg", ".png"}) {
      std::string bytes[2];
      for (int run = 0; run < 2; ++run) {
        const std::string file = path(name + std::to_string(run) + ext);
        const Outcome r = kdm(args + " -o '" + file + "'");
        ASSERT_EQ(r.status, 0) << "kdm " << args << "\nstderr: " << r.err;
        bytes[run] = slurp(file);
      }
      EXPECT_GT(bytes[0].size(), 100u) << name << ext;
      EXPECT_EQ(bytes[0], bytes[1]) << "kdm " << args << " -o X" << ext << " wrote different bytes twice";
    }
}

}  // namespace

namespace {

// The bytes a background reader copied out of a pipe, once the writer has closed it (the reader may still
// be copying when kdm returns: up to 10 s for `min_bytes`).
std::string drain(const std::string& copy, std::size_t min_bytes) {
  std::string bytes;
  for (int i = 0; i < 1000 && bytes.size() < min_bytes; ++i) {
    bytes = slurp(copy);
    if (bytes.size() < min_bytes) std::system("sleep 0.01");
  }
  return bytes;
}

}  // namespace

// Output into a pipe (or a device such as /dev/null) is written into it, as a shell's > does; an atomic
// rename would replace it with a regular file. And a bake never writes over its own recipe.
TEST_F(CliTest, OutputsGoIntoPipesAndABakeKeepsItsRecipe) {
  namespace fs = std::filesystem;
  const std::string pipe = path("points.csv"), copy = path("copy.csv");
  ASSERT_EQ(std::system(("mkfifo '" + pipe + "'").c_str()), 0);
  const Outcome q =
      kdm("query --rect 0,0,1,1 --scale 200 -o '" + pipe + "'", "cat '" + pipe + "' >'" + copy + "' & ");
  ASSERT_EQ(q.status, 0) << q.err;
  EXPECT_TRUE(fs::is_fifo(pipe));
  const std::string csv = drain(copy, 2000);
  EXPECT_EQ(csv.rfind("x,y,", 0), 0u) << csv.substr(0, 80);
  EXPECT_GT(std::count(csv.begin(), csv.end(), '\n'), 150);  // ~200 points and a header

  std::ofstream(path("r.recipe")) << "levels 1\ncolours 1\nsweeps 2\n";
  const std::string set_pipe = path("set.kdmt"), set_copy = path("set_copy.kdmt");
  ASSERT_EQ(std::system(("mkfifo '" + set_pipe + "'").c_str()), 0);
  const Outcome b = kdm("bake '" + path("r.recipe") + "' --threads 1 -o '" + set_pipe + "'",
                        "cat '" + set_pipe + "' >'" + set_copy + "' & ");
  ASSERT_EQ(b.status, 0) << b.err;
  EXPECT_TRUE(fs::is_fifo(set_pipe));
  EXPECT_FALSE(fs::exists(set_pipe + ".partial"));
  const std::string bytes = drain(set_copy, 64);
  kdm::Tileset loaded;
  EXPECT_EQ(kdm::Tileset::load_memory(bytes.data(), bytes.size(), loaded), kdm::Status::kOk);

  expect_error("bake '" + path("r.recipe") + "' -o '" + path("r.recipe") + "'", "is the recipe");
  EXPECT_EQ(slurp(path("r.recipe")), "levels 1\ncolours 1\nsweeps 2\n");
  // A name of another format gets its tile set, with a warning; a .kdmt name (above) none.
  EXPECT_EQ(b.err.find("warning"), std::string::npos) << b.err;
  const Outcome txt = kdm("bake '" + path("r.recipe") + "' --threads 1 -o '" + path("r.txt") + "'");
  ASSERT_EQ(txt.status, 0) << txt.err;
  EXPECT_NE(txt.err.find("kdm bake: warning: '" + path("r.txt") + "' receives a tile set"), std::string::npos)
      << txt.err;
  const std::string written = slurp(path("r.txt"));
  kdm::Tileset baked;
  EXPECT_EQ(kdm::Tileset::load_memory(written.data(), written.size(), baked), kdm::Status::kOk);
}

// A set baked without a glide track: smooth mode gives its stable positions, and both commands that query
// it say so (points right, only not gliding); without a hand-over its zoom stops at its top level, and a
// deeper --region is refused for that reason, not for how deep subtiles go.
TEST_F(CliTest, ASetWithoutGlideTrackOrHandOverIsSaidToBeOne) {
  std::ofstream(path("r.recipe")) << "levels 2\nbase_points 32\ncolours 1\nkeyframes 0\nsweeps 1\n";
  ASSERT_EQ(kdm("bake '" + path("r.recipe") + "' -o '" + path("r.kdmt") + "'").status, 0);
  const std::string set = " --tileset '" + path("r.kdmt") + "' ";
  const std::string sphere = "stipple '" + std::string(KDM_SOURCE_DIR) + "/examples/sphere.png'" + set;
  const char* warning = "warning: the tile set has no glide track: smooth mode gives stable positions";
  const Outcome query =
      kdm("query" + set + "--rect 0,0,2,2 --scale 40 --mode smooth -o '" + path("q.csv") + "'");
  ASSERT_EQ(query.status, 0) << query.err;
  EXPECT_NE(query.err.find(std::string("kdm query: ") + warning), std::string::npos) << query.err;
  const Outcome smooth = kdm(sphere + "--points 2000 -o '" + path("s.csv") + "'");
  ASSERT_EQ(smooth.status, 0) << smooth.err;
  EXPECT_NE(smooth.err.find(std::string("kdm stipple: ") + warning), std::string::npos) << smooth.err;
  const Outcome stable = kdm(sphere + "--points 2000 --mode stable -o '" + path("t.csv") + "'");
  ASSERT_EQ(stable.status, 0) << stable.err;
  EXPECT_EQ(stable.err.find(warning), std::string::npos) << stable.err;
  EXPECT_EQ(slurp(path("s.csv")), slurp(path("t.csv")));  // stable positions, as said
  expect_error(
      sphere + "--region 0.4,0.4,0.6,0.6 -o '" + path("z.csv") + "'",
      "--region zooms more than 2× (the tile set has no hand-over to subtiles, so smooth mode stops");
  // The built-in set has one: its smooth limit is the subtiles' depth.
  expect_error("stipple '" + std::string(KDM_SOURCE_DIR) +
                   "/examples/sphere.png' --region 0,0,1e-9,1e-9 -o '" + path("z.csv") + "'",
               "(smooth mode: as deep as the tile set's subtiles go)");
}
