// kdm stipple end to end: its pictures' geometry, the images it reads (standard input, Radiance, NumPy)
// and what it says of its options and tile sets.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cli_fixture.h"

namespace {

using namespace kdm_cli_test;

/// The dots of a stipple's .csv (its lines after the header).
std::size_t csv_dots(const std::string& text) {
  const std::size_t lines = std::size_t(std::count(text.begin(), text.end(), '\n'));
  return lines > 0 ? lines - 1 : 0;
}

const std::string kSphere = "'" + std::string(KDM_SOURCE_DIR) + "/examples/sphere.png'";

// A dot size that is no number is refused as one, not as a negative number.
TEST_F(CliTest, StippleDotSizeMustBeAFiniteNumber) {
  for (const char* size : {"inf", "nan", "-1"}) {
    SCOPED_TRACE(size);
    expect_error("stipple " + kSphere + " --dot-size " + size + " -o '" + path("s.png") + "'",
                 "--dot-size must be a finite number >= 0");
    expect_error("sample -n 10 --dot-size " + std::string(size) + " -o '" + path("s.png") + "'",
                 "--dot-size must be a finite number >= 0");
  }
}

// Header numbers are the shortest that read back: a 4:5 picture's aspect is 0.8, not 0.80000000000000004.
TEST_F(CliTest, StippleHeadersPrintTheShortestNumbers) {
  write_bytes(path("portrait.png"), grey_png(40, 50, 8, std::vector<std::uint16_t>(40 * 50, 100)));
  const std::string image = " '" + path("portrait.png") + "' --points 500";
  for (const std::string format : {"txt", "svg"}) {
    const Outcome run = kdm("stipple" + image + " -o '" + path("s." + format) + "'");
    ASSERT_EQ(run.status, 0) << run.err;
    const std::string text = slurp(path("s." + format));
    EXPECT_NE(text.find(format == "txt" ? "# domain box, aspect 0.8\n" : "<!-- domain box, aspect 0.8 -->"),
              std::string::npos)
        << text.substr(0, 400);
  }
  const Outcome zoom = kdm("stipple" + image + " --region 0.1,0.3,0.7,0.9 -o '" + path("z.txt") + "'");
  ASSERT_EQ(zoom.status, 0) << zoom.err;
  EXPECT_NE(slurp(path("z.txt")).find("# region 0.1,0.3,0.7,0.9\n"), std::string::npos);
}

// An HDR picture's brightest pixel is white unless --white says which luminance is: a strip at 100 on a
// background of 0.5 left the background at 1/200 of white, stippled as black.
TEST_F(CliTest, StippleWhiteSetsAnHdrPicturesWhite) {
  const int w = 32, h = 16;
  std::vector<float> v(w * h, 0.5f);
  for (int y = 0; y < h; ++y) v[y * w] = v[y * w + 1] = 100.0f;  // 2 of 32 columns
  write_bytes(path("spec.hdr"), radiance_hdr(w, h, v));
  const double black = 2000 * double(w) / h;  // --scale 2000: dots per unit area at full darkness
  const std::string run = "stipple '" + path("spec.hdr") + "' --scale 2000 -o '" + path("s.csv") + "'";
  for (const char* colours : {"", " --colours cmyk"}) {
    SCOPED_TRACE(colours);
    Outcome r = kdm(run + colours);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NEAR(double(csv_dots(slurp(path("s.csv")))), black * 30 / 32, 0.05 * black) << "as before";
    r = kdm(run + colours + " --white 1");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NEAR(double(csv_dots(slurp(path("s.csv")))), black * 0.5 * 30 / 32, 0.05 * black);
  }
  // Brighter than --white is white: the strip gets no dots at --white 50 either.
  ASSERT_EQ(kdm(run + " --white 50").status, 0);
  EXPECT_NEAR(double(csv_dots(slurp(path("s.csv")))), black * 0.99 * 30 / 32, 0.05 * black);
  expect_error(run + " --white 0", "--white must be a finite number > 0");
  expect_error(run + " --white nan", "--white must be a finite number > 0");
  expect_error("stipple " + kSphere + " --white 1 -o '" + path("s.csv") + "'",
               "--white sets the luminance that is white in a Radiance .hdr picture");
  const Outcome help = kdm("stipple --help");
  EXPECT_NE(help.out.find("--white"), std::string::npos);
  EXPECT_NE(help.out.find("brightest pixel is white"), std::string::npos);
}

// In colour too an HDR picture's white is its brightest pixel's luminance: a grey 0.5 beside a red strip
// of (4, 0, 0) (luminance 0.85) draws the grey's black ink as the grey reading draws its dots. Its
// brightest channel, 4, made that grey 0.875 dark (0.41 in grey).
TEST_F(CliTest, StippleColourHdrWhiteIsTheBrightestPixelsLuminance) {
  const int w = 32, h = 16;
  std::vector<float> v(w * h, 0.5f);
  for (int y = 0; y < h; ++y) v[y * w] = v[y * w + 1] = 4.0f;
  std::vector<std::uint8_t> hdr = radiance_hdr(w, h, v);
  const std::size_t pixels_at = hdr.size() - 4 * v.size();
  for (int y = 0; y < h; ++y)
    for (int x : {0, 1}) hdr[pixels_at + 4 * (y * w + x) + 1] = hdr[pixels_at + 4 * (y * w + x) + 2] = 0;
  write_bytes(path("red.hdr"), hdr);
  const std::string run = "stipple '" + path("red.hdr") + "' --scale 2000 -o '" + path("s.csv") + "'";
  ASSERT_EQ(kdm(run).status, 0);
  const double grey = double(csv_dots(slurp(path("s.csv"))));
  const double expected = 2000 * double(w) / h * (1 - 0.5 / (0.2126 * 4)) * 30 / 32;
  EXPECT_NEAR(grey, expected, 0.05 * expected);
  ASSERT_EQ(kdm(run + " --colours cmyk").status, 0);
  // The grey's ink, black, holds most dots (inks are numbered by coverage): the strip is drawn in others.
  std::map<int, std::size_t> per_ink;
  std::istringstream rows(slurp(path("s.csv")));
  std::string line;
  std::getline(rows, line);
  ASSERT_EQ(line, "x,y,class,id");
  double x, y;
  int ink;
  while (std::getline(rows, line) && std::sscanf(line.c_str(), "%lf,%lf,%d", &x, &y, &ink) == 3)
    ++per_ink[ink];
  std::size_t black = 0;
  for (const auto& [ink, count] : per_ink) black = std::max(black, count);
  EXPECT_NEAR(double(black), grey, 0.05 * grey);
}

/// A NumPy .npy file of a 2-D float64 array (rows, columns), row-major.
std::string npy_2d(const std::vector<double>& values, int rows, int cols) {
  std::string header = "{'descr': '<f8', 'fortran_order': False, 'shape': (" + std::to_string(rows) + ", " +
                       std::to_string(cols) + "), }";
  header += std::string(63 - (10 + header.size()) % 64, ' ') + "\n";  // to a multiple of 64 bytes
  std::string out = std::string("\x93NUMPY\x01\x00", 8);
  out += char(header.size() & 0xFF), out += char(header.size() >> 8);
  out += header;
  out.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(double));
  return out;
}

// "-" reads the image from standard input, as the README says every input does: a picture, an HDR one or
// a .npy array, told apart by their first bytes, the same dots as from the file; "-o -" is then no
// output over the input. Densities of kdm query and sample read it too; standard input is read once.
TEST_F(CliTest, StippleAndDensitiesReadStandardInput) {
  std::vector<std::uint16_t> ramp(48 * 32);
  std::vector<double> array(48 * 32);
  std::vector<float> light(48 * 32);
  for (std::size_t i = 0; i < ramp.size(); ++i) {
    ramp[i] = std::uint16_t(255 * (i % 48) / 47);
    array[i] = 1 - (i % 48) / 47.0;
    light[i] = 0.02f * float(1 + i % 48);
  }
  write_bytes(path("ramp.png"), grey_png(48, 32, 8, ramp));
  std::ofstream(path("ramp.npy"), std::ios::binary) << npy_2d(array, 32, 48);
  write_bytes(path("ramp.hdr"), radiance_hdr(48, 32, light));
  for (const std::string name : {"ramp.png", "ramp.npy", "ramp.hdr"}) {
    SCOPED_TRACE(name);
    const std::string white = name == "ramp.hdr" ? " --white 0.5" : "";
    const Outcome file =
        kdm("stipple '" + path(name) + "'" + white + " --points 2000 -o '" + path("f.csv") + "'");
    ASSERT_EQ(file.status, 0) << file.err;
    const Outcome piped =
        kdm("stipple -" + white + " --points 2000 -o '" + path("p.csv") + "' < '" + path(name) + "'");
    ASSERT_EQ(piped.status, 0) << piped.err;
    EXPECT_EQ(slurp(path("p.csv")), slurp(path("f.csv")));
    EXPECT_GT(csv_dots(slurp(path("p.csv"))), 1000u);
    // The command with --density NAME, then with --density - fed NAME: the same output file.
    const auto same_piped = [&](const std::string& command, const std::string& rest, const std::string& out) {
      ASSERT_EQ(kdm(command + " --density '" + path(name) + "'" + rest).status, 0);
      const std::string from_file = slurp(path(out));
      const Outcome from_pipe = kdm(command + " --density -" + rest + " < '" + path(name) + "'");
      ASSERT_EQ(from_pipe.status, 0) << from_pipe.err;
      EXPECT_EQ(slurp(path(out)), from_file) << command;
    };
    same_piped("query", " --rect 0,0,1.5,1 --scale 2000 -o '" + path("q.csv") + "'", "q.csv");
    same_piped("sample", " --n 300 -o '" + path("s.csv") + "'", "s.csv");
  }
  // To standard output, in colour, and the header says where the image came from.
  const Outcome png = kdm("stipple - --points 500 -o - --format png < '" + path("ramp.png") + "'");
  ASSERT_EQ(png.status, 0) << png.err;
  EXPECT_EQ(png.out.substr(0, 4), "\x89PNG");
  const Outcome txt =
      kdm("stipple - --points 500 --colours cmyk -o - --format svg < '" + path("ramp.png") + "'");
  ASSERT_EQ(txt.status, 0) << txt.err;
  EXPECT_NE(txt.out.find("image - (standard input)"), std::string::npos);
  // Nothing, no image, or two inputs from the one standard input: said.
  expect_error("stipple - -o '" + path("x.csv") + "' < /dev/null",
               "'-' reads standard input, and it is empty");
  expect_error("stipple - -o '" + path("x.csv") + "' < '" + path("f.csv") + "'",
               "cannot read image 'standard input'");
  expect_error("stipple - --tileset - -o '" + path("x.csv") + "' < '" + path("ramp.png") + "'",
               "standard input is read once: '-' given to the image and to --tileset");
  expect_error("sample --n 10 --class - --class - -o '" + path("x.csv") + "' < '" + path("ramp.png") + "'",
               "standard input is read once");
}

// A .npy array is one ink's density: --colours, which separates a picture's colours, says so by name.
TEST_F(CliTest, StippleColoursRefuseANumPyArrayByName) {
  std::ofstream(path("d.npy"), std::ios::binary) << npy_2d(std::vector<double>(6, 0.5), 2, 3);
  expect_error("stipple '" + path("d.npy") + "' --colours cmyk -o '" + path("x.csv") + "'",
               "'" + path("d.npy") + "' is a NumPy array of densities: stipple it without --colours");
  expect_error("stipple - --colours 3 -o '" + path("x.csv") + "' < '" + path("d.npy") + "'",
               "is a NumPy array of densities");
  ASSERT_EQ(kdm("stipple '" + path("d.npy") + "' -o '" + path("x.csv") + "'").status, 0);
}

// Every picture's sides are 1 to 65536 pixels, an SVG's too (a 3 x 3,000 image at the default width was an
// SVG 1,024,000 pixels high); the message names the option that gets out of it.
TEST_F(CliTest, StipplePictureSidesStayWithinTheirRange) {
  write_bytes(path("tall.png"), grey_png(3, 3000, 8, std::vector<std::uint16_t>(3 * 3000, 100)));
  write_bytes(path("wide.png"), grey_png(3000, 3, 8, std::vector<std::uint16_t>(3 * 3000, 100)));
  for (const char* format : {"svg", "png"}) {
    SCOPED_TRACE(format);
    const std::string out = " -o '" + path(std::string("s.") + format) + "'";
    expect_error("stipple '" + path("tall.png") + "'" + out,
                 "a picture of 1024x1024000 pixels is too tall (sides 1 to 65536 pixels); give --height");
    // The width that --height gives a wide image was cut to 65536, squeezing the picture.
    expect_error("stipple '" + path("wide.png") + "' --height 100" + out,
                 "a picture of 100000x100 pixels is too wide (sides 1 to 65536 pixels); lower --height");
    const Outcome fits = kdm("stipple '" + path("tall.png") + "' --height 30000" + out);
    ASSERT_EQ(fits.status, 0) << fits.err;
  }
  const std::string svg = slurp(path("s.svg"));
  double x0 = 0, drawn_w = 0, drawn_h = 0;  // the picture within a margin of -x0 (a dot's radius)
  ASSERT_EQ(
      std::sscanf(svg.c_str() + svg.find("viewBox=\""), "viewBox=\"%lf %*f %lf %lf", &x0, &drawn_w, &drawn_h),
      3);
  EXPECT_NEAR(drawn_w + 2 * x0, 30, 1e-9);
  EXPECT_NEAR(drawn_h + 2 * x0, 30000, 1e-9);
  // kdm sample has no --height: its way out is a lower --width, said before the points are placed.
  expect_error("sample -n 100 --aspect 0.01 -o '" + path("s.svg") + "'",
               "a picture of 1024x102400 pixels is too tall (sides 1 to 65536 pixels); lower --width");
}

struct Circle {
  double x, y, r;
};

/// An SVG's circles, and its picture's size: its viewBox less the margin it starts at (-margin, -margin).
std::vector<Circle> svg_circles(const std::string& svg, double& w, double& h, double* margin = nullptr) {
  std::vector<Circle> circles;
  double x0 = 0, y0 = 0, drawn_w = 0, drawn_h = 0;
  EXPECT_EQ(std::sscanf(svg.c_str() + svg.find("viewBox=\""), "viewBox=\"%lf %lf %lf %lf", &x0, &y0, &drawn_w,
                        &drawn_h),
            4);
  EXPECT_EQ(x0, y0);
  w = drawn_w + 2 * x0, h = drawn_h + 2 * x0;
  if (margin) *margin = -x0;
  for (std::size_t at = svg.find("<circle "); at != std::string::npos; at = svg.find("<circle ", at + 1)) {
    Circle c{};
    if (std::sscanf(svg.c_str() + at, "<circle cx=\"%lf\" cy=\"%lf\" r=\"%lf\"", &c.x, &c.y, &c.r) == 3)
      circles.push_back(c);
  }
  return circles;
}

// A plotter's SVG keeps whole circles inside the drawing with a margin as wide as the largest dot around
// the picture, each dot at its point: the circles' centres are the points file's positions in the PNG's
// pixels (mapping the centres inward, as once, shrank the drawing by 1-3% and by half with large dots,
// so that it no longer lay over the PNG).
TEST_F(CliTest, StippleSvgDotsLieAtTheirPointsWithinTheMargin) {
  write_bytes(path("grey.png"), grey_png(96, 64, 8, std::vector<std::uint16_t>(96 * 64, 128)));
  for (const char* dot : {"", " --dot-size 40"}) {
    SCOPED_TRACE(dot);
    const std::string run = "stipple '" + path("grey.png") + "' --points 3000";
    ASSERT_EQ(kdm(run + " --width 600" + dot + " -o '" + path("g.svg") + "'").status, 0);
    ASSERT_EQ(kdm(run + " -o '" + path("g.txt") + "'").status, 0);
    double w = 0, h = 0, margin = 0;
    const std::vector<Circle> dots = svg_circles(slurp(path("g.svg")), w, h, &margin);
    EXPECT_NEAR(w, 600, 1e-9);
    EXPECT_NEAR(h, 400, 1e-9);
    std::vector<std::pair<double, double>> rows;  // the points file's positions, normalised to [0, 1]^2
    std::istringstream text(slurp(path("g.txt")));
    for (std::string line; std::getline(text, line);) {
      double x = 0, y = 0;
      if (line[0] != '#' && std::sscanf(line.c_str(), "%lf %lf", &x, &y) == 2) rows.push_back({x, y});
    }
    ASSERT_EQ(dots.size(), rows.size());
    ASSERT_GT(dots.size(), 1000u);
    double largest = 0;
    std::vector<std::pair<double, double>> centres, points;
    for (std::size_t i = 0; i < dots.size(); ++i) {
      const Circle& c = dots[i];
      largest = std::max(largest, c.r);
      EXPECT_GE(std::min({c.x + margin, c.y + margin, w + margin - c.x, h + margin - c.y}), c.r)
          << c.x << ", " << c.y;  // the whole circle inside the drawing
      centres.push_back({c.x, c.y});
      points.push_back({rows[i].first * w, (1 - rows[i].second) * h});  // y up in the points file
    }
    EXPECT_EQ(margin, largest);
    for (std::size_t i = 0; i < points.size(); ++i) {  // a circle at each point, to the 6 digits printed
      double nearest = HUGE_VAL;
      for (const auto& c : centres)
        nearest = std::min(nearest, std::hypot(c.first - points[i].first, c.second - points[i].second));
      ASSERT_LT(nearest, 0.003) << points[i].first << ", " << points[i].second;
    }
  }
}

TEST_F(CliTest, StippleSvgDotsFillALongPictureToItsEnds) {
  write_bytes(path("strip.png"), grey_png(200, 10, 8, std::vector<std::uint16_t>(200 * 10, 128)));
  const Outcome run =
      kdm("stipple '" + path("strip.png") + "' --points 2000 --width 2000 -o '" + path("s.svg") + "'");
  ASSERT_EQ(run.status, 0) << run.err;
  double w = 0, h = 0;
  const std::vector<Circle> dots = svg_circles(slurp(path("s.svg")), w, h);
  ASSERT_GT(dots.size(), 1900u);
  double left = w, right = 0;
  for (const Circle& c : dots) left = std::min(left, c.x - c.r), right = std::max(right, c.x + c.r);
  const double spacing = std::sqrt(w * h / double(dots.size()));
  EXPECT_LE(left, spacing) << "blank at the left end";  // one factor left 76 px of 2000 here
  EXPECT_GE(right, w - spacing) << "blank at the right end";
}

// A dot larger than a quarter of the picture's shorter side is refused by --dot-size's name, in every
// picture: an SVG of 100 such dots drew them all as one circle at its centre.
TEST_F(CliTest, StippleRefusesDotsTooLargeForThePicture) {
  const std::string run = "stipple " + kSphere + " --points 100 --width 200";
  for (const char* format : {"svg", "png"}) {
    SCOPED_TRACE(format);
    const std::string out = " -o '" + path(std::string("s.") + format) + "'";
    expect_error(
        run + " --dot-size 120" + out,
        "--dot-size 120 is more than a quarter of the 200x200 picture's shorter side: at most 50 pixels");
    const Outcome fits = kdm(run + " --dot-size 50" + out);
    ASSERT_EQ(fits.status, 0) << fits.err;
  }
  double w = 0, h = 0;
  std::vector<Circle> dots = svg_circles(slurp(path("s.svg")), w, h);
  ASSERT_GT(dots.size(), 50u);
  std::sort(dots.begin(), dots.end(),
            [](const Circle& a, const Circle& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  for (std::size_t i = 1; i < dots.size(); ++i)
    EXPECT_FALSE(dots[i].x == dots[i - 1].x && dots[i].y == dots[i - 1].y) << dots[i].x << ", " << dots[i].y;
  // Points files have no dot size: one given is refused, not ignored.
  expect_error(run + " --dot-size 120 -o '" + path("s.csv") + "'", "sizes pictures");
}

// A tile set of a narrow density range (2 levels: 1:4) places a picture's light tones under its coarsest
// level, where they come out clumpy: said once, as kdm query says it of a tile size too small. The
// built-in set (1:1024) serves the examples' tones, and says nothing.
TEST_F(CliTest, StippleSaysWhenTheTileSetServesLightTonesUnevenly) {
  std::ofstream(path("small.recipe")) << "seed 3\nlevels 2\nbase_points 32\nsweeps 10\nkeyframes 4\n";
  ASSERT_EQ(kdm("bake '" + path("small.recipe") + "' -o '" + path("small.kdmt") + "'").status, 0);
  std::vector<std::uint16_t> ramp(64 * 32);
  for (std::size_t i = 0; i < ramp.size(); ++i) ramp[i] = std::uint16_t(255 * (i % 64) / 63);
  write_bytes(path("ramp.png"), grey_png(64, 32, 8, ramp));
  const std::string out = " -o '" + path("s.csv") + "'";
  const Outcome small =
      kdm("stipple '" + path("ramp.png") + "' --tileset '" + path("small.kdmt") + "'" + out);
  ASSERT_EQ(small.status, 0) << small.err;
  const std::string said = "than the tile set's coarsest level holds (32), and come out clumpy there";
  EXPECT_NE(small.err.find(said), std::string::npos) << small.err;
  EXPECT_NE(small.err.find("a tile set of more levels"), std::string::npos) << small.err;
  std::size_t warnings = 0;
  for (std::size_t at = small.err.find("warning"); at != std::string::npos;
       at = small.err.find("warning", at + 1))
    ++warnings;
  EXPECT_EQ(warnings, 1u) << small.err;
  for (const char* example : {"sphere.png", "coffee.png"}) {
    const Outcome builtin =
        kdm("stipple '" + std::string(KDM_SOURCE_DIR) + "/examples/" + example + "'" + out);
    ASSERT_EQ(builtin.status, 0) << builtin.err;
    EXPECT_EQ(builtin.err.find("warning"), std::string::npos) << example << ": " << builtin.err;
  }
  const Outcome ramp_builtin = kdm("stipple '" + path("ramp.png") + "'" + out);
  EXPECT_EQ(ramp_builtin.err.find("warning"), std::string::npos) << ramp_builtin.err;
  // A flat tone whose count rounds to the coarsest level's own is no thin tone ("as few as 32 ... (32)").
  write_bytes(path("flat.png"), grey_png(64, 64, 8, std::vector<std::uint16_t>(64 * 64, 128)));
  for (const char* points : {"2000", "3000"}) {
    const Outcome flat = kdm("stipple '" + path("flat.png") + "' --points " + points + " --tileset '" +
                             path("small.kdmt") + "'" + out);
    ASSERT_EQ(flat.status, 0) << flat.err;
    EXPECT_EQ(flat.err.find("clumpy"), std::string::npos) << points << ": " << flat.err;
  }
}

}  // namespace
