// The kdm command line reading images: 8/16-bit, Radiance, palette and BMP pictures, pictures too large
// to decode, corrupt or truncated ones, blank and 1×1 ones. Every failure is one line "kdm: error: ..."
// and exit status 1.
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
#include "picture.h"
#include "point_io.h"

namespace {

using namespace kdm_cli_test;

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

// A PNG's gAMA chunk says how its samples encode light: a linear file (gAMA 1.0, as compositing software
// saves it) is read as the sRGB value a viewer shows for it, not as if it were sRGB-encoded; sRGB's own
// exponent, an sRGB chunk or an ICC profile (which take precedence) leave the values as they are.
TEST_F(CliTest, PngGammaChunksAreReadAsTheyShow) {
  const auto with_chunks = [](std::uint16_t grey,
                              const std::vector<std::pair<std::string, std::uint32_t>>& extra) {
    std::vector<std::uint8_t> png = grey_png(4, 4, 8, std::vector<std::uint16_t>(16, grey));
    std::vector<std::uint8_t> chunks;
    for (const auto& [type, value] : extra) {
      std::vector<std::uint8_t> data;
      if (type == "gAMA") put32(data, value);
      if (type == "sRGB") data.push_back(0);
      if (type == "iCCP") data = {'x', 0, 0, 0x78, 0x9c, 0x03, 0, 0, 0, 0, 1};  // a name, method 0, zlib
      chunk(chunks, type.c_str(), data);
    }
    png.insert(png.begin() + 33, chunks.begin(), chunks.end());  // after the signature and IHDR
    return png;
  };
  const auto value = [&](const std::vector<std::uint8_t>& png) {
    kdm::tools::GreyImage image;
    std::string error;
    EXPECT_TRUE(kdm::tools::load_grey_image_memory(png.data(), png.size(), image, error)) << error;
    return image.pixels.empty() ? -1.0 : double(image.pixels[0]);
  };
  const double encoded = 128.0 / 255;
  EXPECT_NEAR(value(with_chunks(128, {})), encoded, 1e-7);
  EXPECT_NEAR(value(with_chunks(128, {{"gAMA", 100000}})), std::pow(encoded, 1 / 2.2), 1e-6);  // 0.731
  EXPECT_NEAR(value(with_chunks(128, {{"gAMA", 45455}})), encoded, 1e-7);
  EXPECT_NEAR(value(with_chunks(128, {{"gAMA", 100000}, {"sRGB", 0}})), encoded, 1e-7);
  EXPECT_NEAR(value(with_chunks(128, {{"gAMA", 100000}, {"iCCP", 0}})), encoded, 1e-7);
  EXPECT_NEAR(value(with_chunks(0, {{"gAMA", 100000}})), 0.0, 1e-7);  // black and white stay
  EXPECT_NEAR(value(with_chunks(255, {{"gAMA", 100000}})), 1.0, 1e-7);
}

}  // namespace
