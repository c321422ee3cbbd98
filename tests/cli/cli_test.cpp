// The kdm command line on hostile and edge inputs: runtime scales at their limits, output paths that
// cannot be written, bad command lines, recipes and tile sets from standard input, stipple tones,
// byte-identical point files; plus --version and --help. Every failure must be one line "kdm: error: ..." and
// exit status 1.
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

// A full disk behind > fails what a command prints, as it fails -o -: `kdm info SET > info.txt` in a
// Makefile must not leave an empty file behind a success.
TEST_F(CliTest, PrintingToAFullStandardOutputIsAnError) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const std::string set = std::string(KDM_SOURCE_DIR) + "/tilesets/default.kdmt";
  ASSERT_EQ(kdm("sample --n 64 -o '" + path("s.txt") + "'").status, 0);
  for (const std::string& args : {"info '" + set + "'", "sample --n 64 --timing -o '" + path("t.txt") + "'",
                                  "analyze '" + path("s.txt") + "' -o '" + path("an") + "'"}) {
    const std::string command =
        "'" + std::string(KDM_EXECUTABLE) + "' " + args + " >/dev/full 2>'" + path("err") + "'";
    const int raw = std::system(command.c_str());
    EXPECT_EQ(WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, 1) << args;
    EXPECT_NE(slurp(path("err")).find("kdm: error: cannot write to standard output"), std::string::npos)
        << args << ": " << slurp(path("err"));
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
  expect_error("query --rect 0,0,1,1 --width 300" + out, "not expected: --width 300");  // in their order
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
  expect_error("analyze " + reference + " -o ''", "--output: is empty");
  expect_error("analyze " + reference + " --aspect ''", "--aspect: is empty");  // was ignored
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

// An unset shell variable gives an option an empty value, which CLI11 reads as 0 or as no value ("-T $T"
// sampled at temperature 0): every option that takes a value refuses it by name.
TEST_F(CliTest, EmptyValuesAreRefusedByEveryOption) {
  int checked = 0;
  for (const char* sub : {"sample", "stipple", "query", "analyze", "bake", "info", "verify"}) {
    std::istringstream lines(kdm(std::string(sub) + " --help").out);
    for (std::string line; std::getline(lines, line);) {
      if (line.rfind("  -", 0) != 0) continue;
      std::istringstream words(line);
      std::string names, type;
      words >> names >> type;
      type = type.substr(0, type.find_first_of(":="));
      if (type.empty() || !std::all_of(type.begin(), type.end(), [](char c) { return std::isupper(c); }))
        continue;                                                   // a flag
      const std::string name = names.substr(names.rfind(',') + 1);  // "-o,--output": --output
      const Outcome r = kdm(std::string(sub) + " " + name + " ''");
      EXPECT_EQ(r.status, 1) << sub << " " << name;
      // "--scale: is empty", or an option's own refusal ("--mode:  not in {stable,smooth}"), never another
      // option's "is required" (the empty value taken).
      EXPECT_EQ(r.err.rfind("kdm: error: " + name + ": ", 0), 0u) << sub << " " << name << ": " << r.err;
      ++checked;
    }
  }
  EXPECT_GT(checked, 60);  // the commands' value options, all of them read from --help
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
