// kdm sample on the command line: NumPy outputs and inputs (densities and volumes), several sets, three
// sides, counts and temperatures at their limits, timing and thread counts.
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
  expect_success_saying("sample --n 1000 --step 1e4" + out, "--step 10000 is too large");
  expect_success_saying("sample --n 1000 --step 0.1" + out, "warning", false);
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

// --width and --dot-size size pictures: with a points file they are refused, not silently ignored (as
// kdm stipple refuses them).
TEST_F(CliTest, SamplePictureOptionsWithAPointsFileAreRefused) {
  for (const char* out : {"x.txt", "x.csv", "x.npy"}) {
    expect_error("sample --n 20 --width 300 -o '" + path(out) + "'", "--width sizes pictures");
    expect_error("sample --n 20 --dot-size 2 -o '" + path(out) + "'", "--dot-size sizes pictures");
  }
  EXPECT_EQ(kdm("sample --n 20 --width 300 --dot-size 2 -o '" + path("x.png") + "'").status, 0);
}

}  // namespace
