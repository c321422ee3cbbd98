// The kdm command line on hostile and edge inputs: images that are empty, 1×1, 16-bit, corrupt, truncated
// or missing; sampler counts and temperatures at their limits; output paths that cannot be written; plus
// --version and stipple --frames. Every failure must be one line "kdm: error: ..." and exit status 1.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "image_io.h"
#include "kdm/runtime/tileset.h"
#include "kdm/runtime/tileset_format.h"
#include "kdm/runtime/version.h"
#include "point_io.h"

namespace {

namespace fs = std::filesystem;

struct Outcome {
  int status = -1;  // exit status, or -1 if the process did not exit normally (a crash)
  std::string out, err;
};

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(KDM_CLI_TEST_DIR) / ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  // Runs `PREFIX kdm ARGS` (ARGS already shell-quoted where needed; PREFIX e.g. an environment or
  // `taskset`), capturing stdout and stderr.
  Outcome kdm(const std::string& args, const std::string& prefix = "") const {
    const std::string out = path("stdout"), err = path("stderr");
    const std::string command =
        prefix + " '" + KDM_EXECUTABLE + "' " + args + " >'" + out + "' 2>'" + err + "'";
    const int raw = std::system(command.c_str());
    Outcome r;
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
  }

  // Asserts the one-line error contract and that the message mentions `naming` (the problem or the file).
  void expect_error(const std::string& args, const std::string& naming) const {
    const Outcome r = kdm(args);
    EXPECT_EQ(r.status, 1) << "kdm " << args << "\nstderr: " << r.err;
    EXPECT_EQ(r.err.rfind("kdm: error: ", 0), 0u) << "kdm " << args << "\nstderr: " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "kdm " << args << "\nstderr: " << r.err;
    EXPECT_NE(r.err.find(naming), std::string::npos) << "kdm " << args << "\nstderr: " << r.err;
  }

  fs::path dir_;
};

// ---- A minimal PNG encoder (stb_image_write cannot write 16-bit or broken files): zlib stored blocks.

std::uint32_t crc32(const std::uint8_t* p, std::size_t n, std::uint32_t crc = 0) {
  crc = ~crc;
  for (std::size_t i = 0; i < n; ++i) {
    crc ^= p[i];
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

void put32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<std::uint8_t>(v >> s));
}

void chunk(std::vector<std::uint8_t>& png, const char type[5], const std::vector<std::uint8_t>& data) {
  put32(png, static_cast<std::uint32_t>(data.size()));
  const std::size_t start = png.size();
  png.insert(png.end(), type, type + 4);
  png.insert(png.end(), data.begin(), data.end());
  put32(png, crc32(&png[start], png.size() - start));
}

// A greyscale PNG of `depth` bits (8 or 16); `samples` row-major, top row first.
std::vector<std::uint8_t> grey_png(std::uint32_t w, std::uint32_t h, int depth,
                                   const std::vector<std::uint16_t>& samples) {
  std::vector<std::uint8_t> raw;  // filter byte 0 per row, then big-endian samples
  for (std::uint32_t y = 0; y < h; ++y) {
    raw.push_back(0);
    for (std::uint32_t x = 0; x < w; ++x) {
      const std::uint16_t v = samples[y * w + x];
      if (depth == 16) raw.push_back(static_cast<std::uint8_t>(v >> 8));
      raw.push_back(static_cast<std::uint8_t>(v));
    }
  }
  std::vector<std::uint8_t> z = {0x78, 0x01};  // zlib header, then stored blocks of up to 65535 bytes
  std::size_t at = 0;
  do {
    const std::size_t n = std::min<std::size_t>(65535, raw.size() - at);
    z.push_back(at + n == raw.size() ? 1 : 0);
    z.insert(z.end(), {static_cast<std::uint8_t>(n), static_cast<std::uint8_t>(n >> 8),
                       static_cast<std::uint8_t>(~n), static_cast<std::uint8_t>(~n >> 8)});
    z.insert(z.end(), raw.begin() + at, raw.begin() + at + n);
    at += n;
  } while (at < raw.size());
  std::uint32_t a = 1, b = 0;  // Adler-32
  for (std::uint8_t c : raw) a = (a + c) % 65521, b = (b + a) % 65521;
  put32(z, (b << 16) | a);
  std::vector<std::uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  std::vector<std::uint8_t> ihdr;
  put32(ihdr, w);
  put32(ihdr, h);
  ihdr.insert(ihdr.end(), {static_cast<std::uint8_t>(depth), 0, 0, 0, 0});  // greyscale, no interlace
  chunk(png, "IHDR", ihdr);
  chunk(png, "IDAT", z);
  chunk(png, "IEND", {});
  return png;
}

void write_bytes(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream f(path, std::ios::binary);
  f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(f.good()) << path;
}

// A 64×64 8-bit horizontal ramp: a valid image to cut and damage.
std::vector<std::uint8_t> ramp_png() {
  std::vector<std::uint16_t> v(64 * 64);
  for (int i = 0; i < 64 * 64; ++i) v[i] = static_cast<std::uint16_t>(4 * (i % 64));
  return grey_png(64, 64, 8, v);
}

TEST_F(CliTest, TheTestEncoderWritesImagesTheLoaderReads) {
  write_bytes(path("ramp.png"), ramp_png());
  kdm::tools::GreyImage image;
  std::string error;
  ASSERT_TRUE(kdm::tools::load_grey_image(path("ramp.png"), image, error)) << error;
  EXPECT_EQ(image.width, 64);
  EXPECT_FLOAT_EQ(image.at(10, 5), 40.0f / 255.0f);
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
  write_bytes(path("white.png"), grey_png(1, 1, 8, {255}));  // defined, but no ink: nothing to stipple
  for (const char* name : {"empty0x0.png", "zero-bytes.png", "truncated.png", "corrupt.png", "text.png",
                           "missing.png", "white.png"}) {
    SCOPED_TRACE(name);
    const std::string image = path(name);
    expect_error("sample --n 100 --density '" + image + "' -o '" + path("s.txt") + "'", name);
    expect_error("stipple '" + image + "' -o '" + path("s.png") + "'", name);
    if (std::string(name) != "white.png")  // a query of an all-white image is empty, as one of const:0
      expect_error("query --rect 0,0,1,1 --density '" + image + "' -o '" + path("q.txt") + "'", name);
    EXPECT_FALSE(fs::exists(path("s.txt")) || fs::exists(path("s.png")) || fs::exists(path("q.txt")));
  }
  // A header of 100,000 × 100,000 pixels, which stb will not even read: refused by its size, by name.
  std::vector<std::uint8_t> huge = grey_png(1, 1, 8, {0});
  for (int at : {16, 20}) huge[at] = 0, huge[at + 1] = 0x01, huge[at + 2] = 0x86, huge[at + 3] = 0xA0;
  write_bytes(path("huge.png"), huge);
  expect_error("stipple '" + path("huge.png") + "' -o '" + path("s.png") + "'", "100000x100000 pixels");
}

TEST_F(CliTest, OneByOneImageIsAConstantDensity) {
  write_bytes(path("grey.png"), grey_png(1, 1, 8, {128}));
  const Outcome sampled =
      kdm("sample --n 300 --density '" + path("grey.png") + "' -o '" + path("s.txt") + "'");
  ASSERT_EQ(sampled.status, 0) << sampled.err;
  std::vector<kdm::tools::PointSet> sets;
  std::string error;
  ASSERT_TRUE(kdm::tools::read_point_sets(path("s.txt"), sets, error)) << error;
  EXPECT_EQ(sets.at(0).size(), 300u);  // exact count, as for any density
  const Outcome stippled = kdm("stipple '" + path("grey.png") + "' --points 2000 -o '" + path("t.txt") + "'");
  ASSERT_EQ(stippled.status, 0) << stippled.err;
  ASSERT_TRUE(kdm::tools::read_point_sets(path("t.txt"), sets, error)) << error;
  // The runtime's count for a uniform density over many tiles is the expectation up to the rounding of
  // partly covered edge tiles; 5% is several times that for 2000 dots.
  EXPECT_NEAR(double(sets.at(0).size()), 2000.0, 100.0);
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

TEST_F(CliTest, SamplerCountsAndTemperaturesAtTheirLimits) {
  const std::string out = " -o '" + path("s.txt") + "'";
  expect_error("sample --n 0" + out, "resolution");          // n = 0 means "use --resolution"
  expect_error("sample --n 4000000000" + out, "too large");  // beyond 2^31 points
  expect_error("sample --n 100000000" + out, "limit");       // the grid would exceed max_grid_nodes
  expect_error("sample --n 100 --temperature nan" + out, "temperature");
  expect_error("sample --n 100 --temperature -0.5" + out, "temperature");
  expect_error("sample --n 100 --density const:0" + out, "const:V");  // all-zero density
  expect_error("sample --n 100 --density const:-1" + out, "const:V");
  expect_error("sample --n 100 --vector-lanes 5" + out, "vector-lanes");  // 16, 8 or 4 only
  const Outcome one = kdm("sample --n 1" + out);
  ASSERT_EQ(one.status, 0) << one.err;
  // Analysing against an all-zero density: named as such, not as the sampler's need.
  const Outcome zero = kdm("analyze '" + path("s.txt") + "' --density const:0 -o '" + path("a") + "'");
  EXPECT_EQ(zero.status, 1);
  EXPECT_NE(zero.err.find("needs V > 0 here (zero everywhere"), std::string::npos) << zero.err;
  EXPECT_EQ(zero.err.find("sampler"), std::string::npos) << zero.err;
  std::vector<kdm::tools::PointSet> sets;
  std::string error;
  ASSERT_TRUE(kdm::tools::read_point_sets(path("s.txt"), sets, error)) << error;
  EXPECT_EQ(sets.at(0).size(), 1u);
}

// --timing: the throughput line, the model's time, then one line per level (coarsest first, grids doubling)
// whose set-up, burn-in and sweep times add up to no more than the whole run (within the printed rounding).
TEST_F(CliTest, SampleTimingReportsEveryLevel) {
  const Outcome r = kdm("sample --n 4096 --timing -o '" + path("s.txt") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  std::istringstream lines(r.out);
  std::string line;
  double total = -1, model = -1, levels_sum = 0;
  std::vector<int> grids;
  while (std::getline(lines, line)) {
    long long points = 0;
    int gx = 0, gy = 0, sweeps = 0;
    double seconds = 0, setup = -1, burn_in = -1, sweep_seconds = -1;
    if (std::sscanf(line.c_str(), "points %lld seconds %lf", &points, &seconds) == 2) {
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
  expect_error("query --rect 0,0,1,1 --scale -1" + out, "'--scale' = -1");
  expect_error("query --rect 0,0,1,1 --tile-size 0" + out,
               "'--tile-size' = 0");  // an error, no warning first
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
  set.handover_zone = 0;  // the hand-over names sub-points near each point's old place: drop it
  for (kdm::Tile& t : set.tiles) t.handover.clear(), t.appearing.clear();
  ASSERT_EQ(kdm::save_tileset(set, path("bad.kdmt")), kdm::Status::kOk);
  const Outcome bad = kdm("verify '" + path("bad.kdmt") + "'" + quick);
  EXPECT_EQ(bad.status, 1);
  EXPECT_EQ(bad.err.rfind("kdm: error: ", 0), 0u) << bad.err;
  EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
  EXPECT_NE(bad.err.find("failed"), std::string::npos) << bad.err;
  EXPECT_NE(bad.out.find("FAIL tile 3 level 2"), std::string::npos) << bad.out;

  expect_error("verify '" + path("missing.kdmt") + "'", "missing.kdmt");
  expect_error("verify '" + shipped + "' --level 9", "level 9");
  expect_error("verify '" + shipped + "' --runs 1", "runs");
}

TEST_F(CliTest, BadCommandLinesGiveOneLineErrors) {
  const std::string out = " -o '" + path("x.txt") + "'";
  expect_error("", "subcommand");
  expect_error("frobnicate", "unknown subcommand 'frobnicate'");
  expect_error("sample --n abc" + out, "--n");
  expect_error("sample --n -5" + out, "--n");
  expect_error("sample --n 10", "--output");
  expect_error("sample --n 10 --aspect -1" + out, "--aspect");
  expect_error("sample --n 10 --width 0 -o '" + path("x.png") + "'", "--width");
  expect_error("sample --n 2000 --aspect 0.0001 -o '" + path("x.png") + "'", "too large");  // 1024×10^7 px
  expect_error("stipple --frames 2x a.png" + out, "--frames");
  expect_error("query --rect 0,0,1" + out, "--rect");
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
    expect_error(stipple + scale, "--scale must be a number > 0");
  }
  expect_error(stipple + "1e300 --method full", "scale 1e+300 asks for");
  // The tiles: said in dots and scale, not in the tile size derived from them.
  expect_error(stipple + "1e300", "more than one picture holds");
  expect_error(stipple + "1e-308", "too small to place a dot");
  EXPECT_FALSE(fs::exists(path("s.txt")));
  // --scale decides, not --points' default, and counts dots at full darkness: both methods place about
  // scale · mean darkness, the image's mean darkness 0.624 (the runtime's count is within 1% here).
  std::vector<kdm::tools::PointSet> sets;
  std::string error;
  std::size_t counts[2] = {};
  for (int full = 0; full < 2; ++full) {
    ASSERT_EQ(kdm(stipple + "5000" + (full ? " --method full" : "")).status, 0);
    ASSERT_TRUE(kdm::tools::read_point_sets(path("s.txt"), sets, error)) << error;
    counts[full] = sets.at(0).size();
  }
  const double expected = 5000 * (1 - (0 + 64 + 128 + 192) / (4 * 255.0));
  EXPECT_NEAR(counts[0], expected, 0.02 * expected);
  EXPECT_NEAR(counts[1], expected, 1.0);
}

// --class images cover one domain: images of different sizes (each stretched its own way) are refused;
// images of one size are fine.
TEST_F(CliTest, ClassImagesMustShareOneSize) {
  write_bytes(path("a.png"), grey_png(32, 32, 8, std::vector<std::uint16_t>(32 * 32, 100)));
  write_bytes(path("b.png"), grey_png(32, 16, 8, std::vector<std::uint16_t>(32 * 16, 100)));
  const std::string a = " --class '" + path("a.png") + "'", b = " --class '" + path("b.png") + "'";
  expect_error("sample -n 100" + a + b + " -o '" + path("s.csv") + "'", "b.png' is 32x16");
  expect_error("query --rect 0,0,1,1" + b + a + " -o '" + path("q.csv") + "'", "a.png' is 32x32");
  EXPECT_FALSE(fs::exists(path("s.csv")) || fs::exists(path("q.csv")));
  EXPECT_EQ(kdm("sample -n 100" + a + a + " -o '" + path("s.csv") + "'").status, 0);
  EXPECT_EQ(kdm("query --rect 0,0,1,1" + a + a + " -o '" + path("q.csv") + "'").status, 0);
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
               "handover_zone needs at least 3 levels");
  for (const char* points :
       {"0.5 0.5\n0.5 0.5\n0.5 0.5\n0.5 0.5\n", "0.1 0.5\n0.2 0.5\n0.3 0.5\n0.9 0.5\n"}) {
    std::ofstream(path("flat.txt")) << points;
    expect_error("analyze '" + path("flat.txt") + "' -o '" + path("a") + "'", "degenerate");
  }
  // A directory or an endless device where a tile set or a recipe belongs fails at once, saying so.
  expect_error("info '" + path("dir.png") + "'", "is a directory, not a tile set file");
  expect_error("query --tileset '" + path("dir.png") + "' --rect 0,0,1,1 -o '" + path("q.csv") + "'",
               "is a directory");
  expect_error("bake '" + path("dir.png") + "' -o '" + path("d.kdmt") + "'", "cannot read recipe");
  if (fs::exists("/dev/zero")) {
    expect_error("info /dev/zero", "bad magic");
    expect_error("bake /dev/zero -o '" + path("z.kdmt") + "'", "not a recipe");
  }
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

TEST_F(CliTest, StippleFramesRejectBadCounts) {
  const std::string image = "'" + std::string(KDM_SOURCE_DIR) + "/examples/sphere.png'";
  const std::string out = " -o '" + path("z.png") + "'";
  expect_error("stipple " + image + " --frames 1 --region 0,0,.5,.5" + out, "--frames");
  expect_error("stipple " + image + " --frames -3 --region 0,0,.5,.5" + out, "--frames");
  expect_error("stipple " + image + " --frames 5" + out, "--region");
  expect_error("stipple " + image + " --frames 5 --region 0,0,.2,.2 --mode stable" + out, "2× (");
  // Smooth mode descends into the built-in set's 32 × 32 subtiles, four depths deep: 2 · 32^4 ×.
  expect_error("stipple " + image + " --frames 5 --region 0,0,1e-7,1e-7" + out, "2.09715e+06× (");
  expect_error("stipple " + image + " --frames 5 --region 0,0,.5,.5 --method full" + out, "--method tiles");
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

// Data lines of a query's .csv (its header checked and dropped), sorted.
std::vector<std::string> sorted_rows(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "x,y,tile_x,tile_y,rank,level");
  std::vector<std::string> rows;
  while (std::getline(in, line)) rows.push_back(line);
  std::sort(rows.begin(), rows.end());
  return rows;
}

// kdm query writes world coordinates with each point's id and level, so the files of a partition of a
// region hold exactly the region's lines; an image placed by --density-rect keeps that true.
TEST_F(CliTest, QueryPartitionsConcatenateToTheWhole) {
  const std::string image = "'" + std::string(KDM_SOURCE_DIR) + "/examples/sphere.png'";
  for (const std::string& density : {std::string("const:0.7"), image + " --density-rect -1,-2,9,8"}) {
    const std::string common = " --scale 200 --tile-size 0.5 --density " + density + " -o '";
    ASSERT_EQ(kdm("query --rect 0,0,6,5" + common + path("whole.csv") + "'").status, 0);
    ASSERT_EQ(kdm("query --rect 0,0,2.3,5" + common + path("left.csv") + "'").status, 0);
    ASSERT_EQ(kdm("query --rect 2.3,0,6,1.7" + common + path("right_low.csv") + "'").status, 0);
    ASSERT_EQ(kdm("query --rect 2.3,1.7,6,5" + common + path("right_high.csv") + "'").status, 0);
    const std::vector<std::string> whole = sorted_rows(slurp(path("whole.csv")));
    std::vector<std::string> parts;
    for (const char* part : {"left.csv", "right_low.csv", "right_high.csv"})
      for (const std::string& row : sorted_rows(slurp(path(part)))) parts.push_back(row);
    std::sort(parts.begin(), parts.end());
    EXPECT_GT(whole.size(), 1000u) << density;
    EXPECT_EQ(parts, whole) << density;
    // Rows are world positions inside the rectangle, then the id and a level of the built-in set.
    double x = -1, y = -1;
    long long tx = 0, ty = 0;
    unsigned rank = 0, level = 99;
    ASSERT_EQ(std::sscanf(whole.front().c_str(), "%lf,%lf,%lld,%lld,%u,%u", &x, &y, &tx, &ty, &rank, &level),
              6);
    EXPECT_TRUE(x >= 0 && x < 6 && y >= 0 && y < 5 && level < 6) << whole.front();
    EXPECT_EQ(tx, static_cast<long long>(std::floor(x / 0.5)));
  }
}

TEST_F(CliTest, QueryWritesJsonAndAcceptsAZeroDensity) {
  ASSERT_EQ(kdm("query --rect 1,1,3,2 --scale 100 -o '" + path("q.json") + "'").status, 0);
  const std::string json = slurp(path("q.json"));
  EXPECT_EQ(json.rfind("{\"rect\": [1, 1, 3, 2], \"normalised\": false, \"points\": [", 0), 0u)
      << json.substr(0, 80);
  EXPECT_NE(json.find("\"tile_x\": 1, \"tile_y\": 1, \"rank\": 0, \"level\": 0"), std::string::npos);
  EXPECT_EQ(json.substr(json.size() - 4), "\n]}\n");
  // Normalised: the same rows, each position relative to the rectangle's corner over its sides.
  ASSERT_EQ(kdm("query --rect 1,1,3,2 --scale 100 --normalised -o '" + path("n.csv") + "'").status, 0);
  ASSERT_EQ(kdm("query --rect 1,1,3,2 --scale 100 -o '" + path("w.csv") + "'").status, 0);
  const std::vector<std::string> unit = sorted_rows(slurp(path("n.csv")));
  std::vector<std::string> world = sorted_rows(slurp(path("w.csv")));
  ASSERT_EQ(unit.size(), world.size());
  ASSERT_GT(unit.size(), 100u);
  auto id_of = [](const std::string& row) { return row.substr(row.find(',', row.find(',') + 1)); };
  std::map<std::string, std::string> world_by_id;
  for (const std::string& row : world) world_by_id[id_of(row)] = row;
  for (const std::string& row : unit) {
    const double x = std::atof(row.c_str()), y = std::atof(row.c_str() + row.find(',') + 1);
    const std::string& w = world_by_id[id_of(row)];
    ASSERT_FALSE(w.empty()) << row;
    const double wx = std::atof(w.c_str()), wy = std::atof(w.c_str() + w.find(',') + 1);
    EXPECT_NEAR(x, (wx - 1) / 2, 1e-12) << row;
    EXPECT_NEAR(y, wy - 1, 1e-12) << row;
  }
  // No density, two ways: const:0 and an all-white image (no ink) both give an empty result.
  write_bytes(path("white.png"), grey_png(2, 2, 8, {255, 255, 255, 255}));
  for (const std::string& none : {std::string("const:0"), "'" + path("white.png") + "'"}) {
    const Outcome zero = kdm("query --rect 0,0,4,4 --density " + none + " -o '" + path("z.csv") + "'");
    ASSERT_EQ(zero.status, 0) << zero.err;
    EXPECT_TRUE(sorted_rows(slurp(path("z.csv"))).empty()) << none;
    fs::remove(path("z.csv"));
  }
  // A test map is a density the runtime follows too: ramp:4 over the rectangle, 4^(-x/4), puts 4^(3/4)
  // times as many points on the left quarter as on the right one (about 1,340 and 475). The tolerance is
  // three standard deviations of the ratio for Poisson counts; blue-noise counts vary far less.
  const Outcome ramp = kdm("query --rect 0,0,4,4 --scale 400 --density ramp:4 -o '" + path("r.csv") + "'");
  ASSERT_EQ(ramp.status, 0) << ramp.err;
  double left = 0, right = 0;
  for (const std::string& row : sorted_rows(slurp(path("r.csv")))) {
    const double x = std::atof(row.c_str());
    left += x < 1, right += x >= 3;
  }
  ASSERT_GT(right, 300);
  EXPECT_NEAR(left / right, std::pow(4.0, 0.75), 0.15);
  expect_error("query --rect 0,0,4,4 --density const:-1 -o '" + path("z.csv") + "'", ">= 0");
  expect_error("query --rect 0,0,4,4 --density-rect 0,0,1,1 -o '" + path("z.csv") + "'", "--density-rect");
  expect_error("query --rect 0,0,10,10 --scale 100000 -o '" + path("z.csv") + "'", "--tile-size 0.572433");
  expect_error("sample --n 100 --density const:0 -o '" + path("z.txt") + "'", "> 0");
}

// --class, repeated: one query, each row with its class; class 0's rows are the one-class query's at its
// density, the rows of every class together the one-class query's at the sum.
TEST_F(CliTest, QueryClassesWriteAClassColumnAndOneGroupPerClass) {
  const std::string common = " --rect 0,0,3,2 --scale 150 -o '";
  ASSERT_EQ(kdm("query --class const:1 --class const:2 --class ramp:4" + common + path("c.csv") + "'").status,
            0);
  ASSERT_EQ(kdm("query --density const:1" + common + path("one.csv") + "'").status, 0);
  std::istringstream in(slurp(path("c.csv")));
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "x,y,tile_x,tile_y,rank,level,class");
  std::vector<std::string> zero;
  std::size_t counts[3] = {};
  while (std::getline(in, line)) {
    const std::size_t comma = line.rfind(',');
    const int cls = std::atoi(line.c_str() + comma + 1);
    ASSERT_TRUE(cls >= 0 && cls < 3) << line;
    ++counts[cls];
    if (cls == 0) zero.push_back(line.substr(0, comma));
  }
  std::sort(zero.begin(), zero.end());
  EXPECT_EQ(zero, sorted_rows(slurp(path("one.csv"))));
  EXPECT_NEAR(double(counts[1]) / double(counts[0]), 2.0, 0.05);  // rank prefixes: counts within a few points
  ASSERT_EQ(kdm("query --class const:1 --class const:2" + common + path("c.svg") + "'").status, 0);
  const std::string svg = slurp(path("c.svg"));
  EXPECT_NE(svg.find("<g id=\"class-0\""), std::string::npos);
  EXPECT_NE(svg.find("<g id=\"class-1\""), std::string::npos);
  ASSERT_EQ(kdm("query --class const:1 --class const:2" + common + path("c.json") + "'").status, 0);
  EXPECT_NE(slurp(path("c.json")).find("\"level\": 0, \"class\": 0}"), std::string::npos);
  expect_error("query --density const:1 --class const:1" + common + path("z.csv") + "'", "not both");
  std::string nine;
  for (int k = 0; k < 9; ++k) nine += " --class const:1";
  expect_error("query" + nine + common + path("z.csv") + "'", "at most 8 classes");
  expect_error("query --class const:1 --class const:-1" + common + path("z.csv") + "'", ">= 0");
  // kdm analyze reads the labelled .csv (normalised): each class alone, and the cross-class closest pair,
  // which the union's spacing bounds from below (no two points of the built-in set come within 0.3 d_hex).
  ASSERT_EQ(kdm("query --class const:1 --class const:2 --rect 0,0,3,3 --scale 150 --normalised -o '" +
                path("n.csv") + "'")
                .status,
            0);
  const Outcome analyzed = kdm("analyze '" + path("n.csv") + "' --no-energy -o '" + path("a") + "'");
  ASSERT_EQ(analyzed.status, 0) << analyzed.err;
  EXPECT_NE(analyzed.out.find("class 1 alone"), std::string::npos) << analyzed.out;
  const std::string json = slurp(path("a") + "/classes.json");
  const std::size_t at = json.find("\"cross_class_closest\": ");
  ASSERT_NE(at, std::string::npos) << json.substr(0, 200);
  EXPECT_GT(std::atof(json.c_str() + at + 23), 0.3);
  EXPECT_NE(json.find("{\"class\": 1, \"metrics\": {"), std::string::npos);
  // Without -o the same summary is printed and nothing is written.
  const auto files_before = std::distance(fs::directory_iterator(dir_), fs::directory_iterator());
  const Outcome printed = kdm("analyze '" + path("n.csv") + "' --no-energy");
  ASSERT_EQ(printed.status, 0) << printed.err;
  const auto untimed = [](const std::string& text) {  // the lines but the analysis time
    std::string kept;
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);)
      if (line.rfind("analysis time", 0) != 0) kept += line + "\n";
    return kept;
  };
  EXPECT_EQ(untimed(printed.out), untimed(analyzed.out));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), files_before);
  // A class too small to analyse is said so and left out of the list, which stays valid JSON.
  std::ofstream(path("few.csv")) << "x,y,class\n0.5,0.5,0\n0.6,0.6,1\n0.7,0.1,1\n";
  const Outcome few = kdm("analyze '" + path("few.csv") + "' --no-energy -o '" + path("f") + "'");
  ASSERT_EQ(few.status, 0) << few.err;
  EXPECT_NE(few.out.find("class 0 alone: fewer than 2 points"), std::string::npos) << few.out;
  const std::string listed = slurp(path("f") + "/classes.json");
  EXPECT_NE(listed.find("\"classes\": [{\"class\": 1, "), std::string::npos) << listed.substr(0, 200);
}

// kdm stipple --colours: one class per ink, an SVG group per ink, a class column in .csv; a grey picture
// needs black alone; bad schemes and formats that cannot carry inks are refused.
TEST_F(CliTest, StippleColoursSeparateInksIntoClasses) {
  const std::string coffee = "'" + std::string(KDM_SOURCE_DIR) + "/examples/coffee.png'";
  const std::string sphere = "'" + std::string(KDM_SOURCE_DIR) + "/examples/sphere.png'";
  ASSERT_EQ(kdm("stipple " + coffee + " --colours cmyk --points 8000 -o '" + path("c.svg") + "'").status, 0);
  const std::string svg = slurp(path("c.svg"));
  for (const char* ink : {"black", "cyan", "magenta", "yellow"})
    EXPECT_NE(svg.find("<g id=\"" + std::string(ink) + "\""), std::string::npos) << ink;
  ASSERT_EQ(kdm("stipple " + sphere + " --colours cmyk -o '" + path("s.svg") + "'").status, 0);
  const std::string grey = slurp(path("s.svg"));
  EXPECT_NE(grey.find("<g id=\"black\""), std::string::npos);
  EXPECT_EQ(grey.find("<g id=\"cyan\""), std::string::npos);  // a grey picture has no colour to separate
  ASSERT_EQ(kdm("stipple " + coffee + " --colours 3 --points 8000 -o '" + path("c.csv") + "'").status, 0);
  std::istringstream in(slurp(path("c.csv")));
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "x,y,class");
  std::size_t counts[3] = {}, rows = 0;
  while (std::getline(in, line)) {
    const int k = std::atoi(line.c_str() + line.rfind(',') + 1);
    ASSERT_TRUE(k >= 0 && k < 3) << line;
    ++counts[k], ++rows;
  }
  EXPECT_NEAR(double(rows), 8000, 80);  // the dots of all inks together
  for (std::size_t c : counts) EXPECT_GT(c, 100u);
  ASSERT_EQ(kdm("stipple " + coffee + " --colours rgb --points 2000 -o '" + path("rgb.svg") + "'").status, 0);
  EXPECT_NE(slurp(path("rgb.svg")).find("fill=\"#000000\"/>"), std::string::npos);  // black paper
  expect_error("stipple " + coffee + " --colours 9 -o '" + path("x.png") + "'", "from 2 to 8");
  expect_error("stipple " + coffee + " --colours cmy -o '" + path("x.png") + "'", "cmyk, rgb");
  expect_error("stipple " + coffee + " --colours cmyk -o '" + path("x.txt") + "'", ".csv");
  // The full sampler's inks: every dot with its ink's class, all of them the count asked for.
  ASSERT_EQ(
      kdm("stipple " + coffee + " --colours cmyk --method full --points 3000 -o '" + path("f.csv") + "'")
          .status,
      0);
  std::istringstream full(slurp(path("f.csv")));
  std::getline(full, line);
  EXPECT_EQ(line, "x,y,class");
  std::size_t full_rows = 0, inks_seen[4] = {};
  while (std::getline(full, line))
    ++full_rows, ++inks_seen[std::atoi(line.c_str() + line.rfind(',') + 1) & 3];
  EXPECT_EQ(full_rows, 3000u);
  EXPECT_LT(inks_seen[0], inks_seen[2]);  // the ink that covers least (of those over a tenth) first
  EXPECT_GT(inks_seen[2], 0u);
  expect_error("stipple " + coffee + " --colours cmyk --invert -o '" + path("x.png") + "'", "--invert");
}

// kdm sample --class: exact counts per class by the densities' integrals, a class column in .csv.
TEST_F(CliTest, SampleClassesSplitTheCountByTheDensities) {
  ASSERT_EQ(
      kdm("sample --n 700 --class const:1 --class const:2 --class const:4 -o '" + path("c.csv") + "'").status,
      0);
  std::istringstream in(slurp(path("c.csv")));
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "x,y,class");
  std::size_t counts[3] = {};
  while (std::getline(in, line)) ++counts[std::atoi(line.c_str() + line.rfind(',') + 1) % 3];
  EXPECT_EQ(counts[0], 100u);
  EXPECT_EQ(counts[1], 200u);
  EXPECT_EQ(counts[2], 400u);
  expect_error("sample --n 100 --density const:1 --class const:1 -o '" + path("z.csv") + "'", "not both");
  expect_error("sample --n 0 --resolution 64 --class const:1 -o '" + path("z.csv") + "'", "--n > 0");
  expect_error("sample --n 100 --class const:1 -o '" + path("z.txt") + "'", ".csv");
  // A class too faint for a float (1e-46 rounds to 0) has no points, as a class of 0 has.
  ASSERT_EQ(kdm("sample --n 100 --class const:1 --class const:1e-46 -o '" + path("f.csv") + "'").status, 0);
  const std::string faint = slurp(path("f.csv"));
  EXPECT_EQ(std::count(faint.begin(), faint.end(), '\n'), 101);
  EXPECT_EQ(faint.find(",1\n"), std::string::npos);
}

TEST_F(CliTest, SmallFrictions) {
  expect_error("analyze '" + std::string(KDM_TEST_DATA_DIR) + "/reference/ref_T0.5_n4096_01.txt' -o '" +
                   path("metrics.json") + "'",
               "output directory");
  EXPECT_FALSE(fs::exists(path("metrics.json")));
  const Outcome sampled = kdm("sample -n 200 -o '" + path("s.txt") + "'");
  ASSERT_EQ(sampled.status, 0) << sampled.err;
  EXPECT_NE(slurp(path("s.txt")).find("kdm sample: 200 points"), std::string::npos);
  const Outcome info = kdm("info '" + std::string(KDM_SOURCE_DIR) + "/tilesets/default.kdmt'");
  ASSERT_EQ(info.status, 0) << info.err;
  EXPECT_NE(info.out.find("  band 0.35\n"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find(" bytes ("), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("format         version " +
                          std::to_string(kdm::tileset_format_version_for(kdm::Tileset::builtin().data())) +
                          " (header "),
            std::string::npos)
      << info.out;
  // Tiles too small for a point each are said, not refused: also where the count underflows to 0.
  for (const char* tiny : {"0.001", "1e-300"}) {
    const Outcome sparse =
        kdm(std::string("query --rect 0,0,1,1 --tile-size ") + tiny + " -o '" + path("t.csv") + "'");
    ASSERT_EQ(sparse.status, 0) << sparse.err;
    EXPECT_NE(sparse.err.find("warning: at most"), std::string::npos) << tiny << ": " << sparse.err;
  }
}

// The per-band bias table users check their own maps with: a ramp sampled and analysed by the same spec
// holds its target in every band that expects enough points (the sampler's own tolerance is tested in
// density_bias_test; here the table's plumbing and the spec's errors).
TEST_F(CliTest, AnalyzeReportsTheBiasOfEveryDensityBand) {
  const Outcome sampled = kdm("sample -n 3000 --density ramp:100 -o '" + path("ramp.txt") + "'");
  ASSERT_EQ(sampled.status, 0) << sampled.err;
  EXPECT_NE(slurp(path("ramp.txt")).find("domain box"), std::string::npos);  // a ramp's edges do not meet
  const Outcome analysed =
      kdm("analyze '" + path("ramp.txt") + "' --box --density ramp:100 --density-bands 5 -o '" +
          path("ramp_metrics") + "'");
  ASSERT_EQ(analysed.status, 0) << analysed.err;
  std::istringstream lines(analysed.out);
  int bands = 0;
  for (std::string line; std::getline(lines, line);) {
    double lo = 0, hi = 0, expected = 0, count = 0, ratio = 0;
    if (std::sscanf(line.c_str(), " %lf–%lf %lf %lf %lf", &lo, &hi, &expected, &count, &ratio) != 5) continue;
    ++bands;
    EXPECT_NEAR(ratio, count / expected, 1e-3) << line;
    if (expected >= 300) {  // measured within 1.5% (seed 1); 5% leaves room for the sampler's changes
      EXPECT_NEAR(ratio, 1.0, 0.05) << line;
    }
  }
  EXPECT_EQ(bands, 5) << analysed.out;
  const std::string json = slurp(path("ramp_metrics/metrics.json"));
  EXPECT_NE(json.find("\"bands\""), std::string::npos);
  EXPECT_NE(json.find("\"rho_lo\""), std::string::npos);
  // radial:R is dense at the centre: its points lie nearer it (mean r about 0.22) than uniform ones (0.38).
  ASSERT_EQ(kdm("sample -n 500 --density radial:100 -o '" + path("radial.txt") + "'").status, 0);
  std::istringstream points(slurp(path("radial.txt")));
  double sum_r = 0, x = 0, y = 0;
  int counted = 0;
  for (std::string line; std::getline(points, line);)
    if (line[0] != '#' && std::sscanf(line.c_str(), "%lf %lf", &x, &y) == 2)
      sum_r += std::hypot(x - 0.5, y - 0.5), ++counted;
  ASSERT_EQ(counted, 500);
  EXPECT_LT(sum_r / counted, 0.3);
  expect_error("sample -n 100 --density ramp:0.5 -o '" + path("z.txt") + "'", "[1, 1e9]");
  expect_error("sample -n 100 --density radial: -o '" + path("z.txt") + "'", "dynamic range");
  expect_error("analyze '" + path("ramp.txt") + "' --density-bands 0 -o '" + path("m") + "'", "1 to 1000");
}

}  // namespace
