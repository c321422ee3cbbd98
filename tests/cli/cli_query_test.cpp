// The kdm command line's runtime queries, classes and analysis end to end: partitions of a region give its
// points, --class writes a class column and a group per class, --colours separates inks, kdm sample splits
// a count among classes, and kdm analyze reports per class and per density band.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli_fixture.h"
#include "image_io.h"
#include "kdm/runtime/tileset.h"
#include "kdm/runtime/tileset_format.h"
#include "picture.h"

namespace {

using namespace kdm_cli_test;

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

// -o - writes to standard output in the --format given: the same bytes as the file, so that a pipeline
// (`kdm sample -o - --format txt | kdm analyze -`) needs no scratch files; the summary stays on stderr.
TEST_F(CliTest, OutputToStandardOutputIsTheFilesBytes) {
  const std::string query = "query --rect 0,0,2,1.5 --scale 300 --density ramp:4 ";
  ASSERT_EQ(kdm(query + "-o '" + path("q.csv") + "'").status, 0);
  const Outcome csv = kdm(query + "-o - --format csv");
  ASSERT_EQ(csv.status, 0) << csv.err;
  EXPECT_EQ(csv.out, slurp(path("q.csv")));
  EXPECT_GT(sorted_rows(csv.out).size(), 300u);
  EXPECT_NE(csv.err.find("-> standard output"), std::string::npos) << csv.err;
  // --format names the format of a file without an extension too.
  ASSERT_EQ(kdm(query + "-o '" + path("q.points") + "' --format JSON").status, 0);
  EXPECT_EQ(slurp(path("q.points")), kdm(query + "-o - --format json").out);
  // A file named for another format than --format's is refused: its viewer would misread it.
  expect_error(query + "-o '" + path("q2.png") + "' --format csv", "a png file name");
  EXPECT_FALSE(fs::exists(path("q2.png")));
  ASSERT_EQ(kdm("sample -n 300 --seed 4 -o '" + path("s.txt") + "'").status, 0);
  const Outcome txt = kdm("sample -n 300 --seed 4 -o - --format txt");
  ASSERT_EQ(txt.status, 0) << txt.err;
  EXPECT_EQ(txt.out, slurp(path("s.txt")));
  // Read back from standard input: the same report as from the file.
  const Outcome piped = kdm("analyze - <'" + path("s.txt") + "'");
  ASSERT_EQ(piped.status, 0) << piped.err;
  EXPECT_NE(piped.out.find("300 2D points"), std::string::npos) << piped.out;
  EXPECT_EQ(piped.out.substr(0, piped.out.find("analysis time")),
            kdm("analyze '" + path("s.txt") + "'").out.substr(0, piped.out.find("analysis time")));
  const Outcome png =
      kdm("stipple '" + std::string(KDM_SOURCE_DIR) + "/examples/sphere.png' --points 300 -o - --format png");
  ASSERT_EQ(png.status, 0) << png.err;
  EXPECT_EQ(png.out.substr(1, 3), "PNG");
  // Standard output needs a format; one the command does not write, frames and --timing are refused.
  expect_error("query --rect 0,0,1,1 -o -", "needs --format");
  expect_error("query --rect 0,0,1,1 -o - --format bmp", "unknown --format 'bmp'");
  expect_error("sample -n 10 -o - --format json", "unknown --format 'json'");
  expect_error("sample -n 10 -o - --format txt --timing", "--timing");
  expect_error("stipple '" + std::string(KDM_SOURCE_DIR) +
                   "/examples/sphere.png' -o - --format png --frames 3 --region 0,0,0.5,0.5",
               "--frames");
  expect_error("analyze - </dev/null", "standard input");
  // Points stream from standard input as from a file: an endless bad input fails at its first line
  // (read whole first, it was held in memory to the end: gigabytes, or never).
  const Outcome endless = kdm("analyze -", "yes garbage |");
  EXPECT_EQ(endless.status, 1) << endless.err;
  EXPECT_NE(endless.err.find("standard input:1: header 'garbage'"), std::string::npos) << endless.err;
}

// --glide-together moves smooth points (same ids) and partitions still concatenate to the whole; stable
// mode ignores it.
TEST_F(CliTest, QueryGlideTogetherMovesTheSamePointsAndKeepsPartitions) {
  const std::string image =
      "'" + std::string(KDM_SOURCE_DIR) + "/examples/coffee.png' --density-rect 0,0,3,2";
  const std::string common = " --scale 3000 --tile-size 0.5 --density " + image;
  auto ids = [](const std::vector<std::string>& rows) {
    std::vector<std::string> out;
    for (const std::string& row : rows) out.push_back(row.substr(row.find(',', row.find(',') + 1)));
    std::sort(out.begin(), out.end());
    return out;
  };
  for (const char* mode : {"smooth", "stable"}) {
    const std::string m = std::string(" --mode ") + mode;
    ASSERT_EQ(kdm("query --rect 0,0,3,2" + common + m + " -o '" + path("own.csv") + "'").status, 0);
    const Outcome together =
        kdm("query --rect 0,0,3,2" + common + m + " --glide-together -o '" + path("whole.csv") + "'");
    ASSERT_EQ(together.status, 0) << together.err;
    EXPECT_EQ(together.err.find("--glide-together applies to --mode smooth only") != std::string::npos,
              std::string(mode) == "stable")
        << together.err;
    ASSERT_EQ(
        kdm("query --rect 0,0,1.3,2" + common + m + " --glide-together -o '" + path("left.csv") + "'").status,
        0);
    ASSERT_EQ(kdm("query --rect 1.3,0,3,2" + common + m + " --glide-together -o '" + path("right.csv") + "'")
                  .status,
              0);
    const std::vector<std::string> own = sorted_rows(slurp(path("own.csv"))),
                                   whole = sorted_rows(slurp(path("whole.csv")));
    std::vector<std::string> parts = sorted_rows(slurp(path("left.csv")));
    for (const std::string& row : sorted_rows(slurp(path("right.csv")))) parts.push_back(row);
    std::sort(parts.begin(), parts.end());
    EXPECT_GT(whole.size(), 5000u) << mode;
    EXPECT_EQ(parts, whole) << mode;
    if (std::string(mode) == "stable") {
      EXPECT_EQ(whole, own);
    } else {
      EXPECT_NE(whole, own);
      std::vector<std::string> a = ids(own), b = ids(whole), both;
      std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(both));
      EXPECT_GT(both.size(), 0.98 * a.size());  // only the region's sides differ
    }
  }
}

// A picture of a rect far longer than wide is refused before the query (it was 1 × 10^8 pixels).
TEST_F(CliTest, QueryPicturesOfSliversAreRefused) {
  expect_error("query --rect 0,0,1,1e8 --scale 0.001 --tile-size 1000 -o '" + path("tall.png") + "'",
               "more than 1,024 times taller than wide");
  expect_error("query --rect 0,0,2000,1 --scale 1 -o '" + path("wide.svg") + "'",
               "more than 1,024 times wider than tall");
  ASSERT_EQ(kdm("query --rect 0,0,1000,1 --scale 1 -o '" + path("long.png") + "'").status, 0);
}

// A query's SVG holds its points where they are, those by the rect's sides too (the stippler's pen-plotter
// pictures move dots inward; a query's were moved up to 2 pixels with them).
TEST_F(CliTest, QuerySvgKeepsEveryPointWhereItIs) {
  const std::string args = "query --rect 0,0,2,2 --scale 300 -o '";
  ASSERT_EQ(kdm(args + path("q.csv") + "' --normalised").status, 0);
  ASSERT_EQ(kdm(args + path("q.svg") + "'").status, 0);
  std::vector<std::pair<double, double>> from_csv, from_svg;  // in the pixels of a 1024² picture
  std::istringstream csv(slurp(path("q.csv")));
  std::string row;
  std::getline(csv, row);  // the header
  double x = 0, y = 0, r = 0;
  while (std::getline(csv, row) && std::sscanf(row.c_str(), "%lf,%lf", &x, &y) == 2)
    from_csv.emplace_back(x * 1024, (1 - y) * 1024);
  const std::string svg = slurp(path("q.svg"));
  for (std::size_t c = svg.find("<circle"); c != std::string::npos; c = svg.find("<circle", c + 1)) {
    ASSERT_EQ(std::sscanf(svg.c_str() + c, "<circle cx=\"%lf\" cy=\"%lf\" r=\"%lf\"", &x, &y, &r), 3);
    from_svg.emplace_back(x, y);
  }
  ASSERT_GT(from_csv.size(), 1000u);
  ASSERT_EQ(from_svg.size(), from_csv.size());
  std::size_t moved = 0;  // SVG points with no point of the CSV within the six digits it writes
  for (const auto& p : from_svg) {
    bool found = false;
    for (const auto& q : from_csv) found = found || std::hypot(p.first - q.first, p.second - q.second) < 0.01;
    moved += !found;
  }
  EXPECT_EQ(moved, 0u);
}

// Past the top level ranks repeat in the subtiles: the depth column makes every id unique (without it,
// 261 of 401,662 points shared (tile_x, tile_y, rank) with another point over 2 × 2 units).
TEST_F(CliTest, QueryIdsPastTheTopLevelAreUniqueWithTheirDepth) {
  ASSERT_EQ(kdm("query --rect 0,0,1,1 --scale 100000 --mode smooth -o '" + path("deep.csv") + "'").status, 0);
  std::istringstream in(slurp(path("deep.csv")));
  std::string line;
  std::getline(in, line);
  std::set<std::string> ids;
  std::size_t rows = 0, deep = 0;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::istringstream fields(line);
    for (std::string v; std::getline(fields, v, ',');) f.push_back(v);
    ASSERT_EQ(f.size(), 7u) << line;
    ids.insert(f[2] + "," + f[3] + "," + f[4] + "," + f[6]);
    deep += f[6] != "0", ++rows;
  }
  EXPECT_GT(rows, 90000u);
  EXPECT_GT(deep, 0u);
  EXPECT_EQ(ids.size(), rows);
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
  // World units are refused by kdm analyze, naming the option that writes them normalised.
  expect_error("analyze '" + path("w.csv") + "' --no-energy", "outside the unit domain");
  expect_error("analyze '" + path("w.csv") + "' --no-energy", "give it --normalised");
  EXPECT_EQ(kdm("analyze '" + path("n.csv") + "' --box --aspect 2 --no-energy").status, 0);
  // Options an output would silently drop are refused: --normalised where the output always is, and
  // classes where it has no column for them.
  expect_error("query --rect 1,1,3,2 --normalised -o '" + path("n.png") + "'", "--normalised is for .csv");
  expect_error("query --rect 1,1,3,2 --class const:1 --class const:1 -o '" + path("c.txt") + "'",
               ".txt has no class column");
  EXPECT_FALSE(fs::exists(path("n.png")) || fs::exists(path("c.txt")));
  // More points than a query collects, refused before querying: for an image (its values averaged over
  // the region) as for a constant, and for classes; 4e10 and 1.2e11 points would take minutes to count.
  const std::string sphere = "'" + std::string(KDM_SOURCE_DIR) + "/examples/sphere.png'";
  expect_error("query --rect 0,0,2000,2000 --scale 20000 -o '" + path("big.csv") + "'",
               "would emit at least 8e+10 points, more than 2^25; lower the scale (--scale)");
  expect_error(
      "query --rect 0,0,2000,2000 --scale 20000 --density " + sphere + " -o '" + path("big.csv") + "'",
      "would emit at least");
  expect_error("query --rect 0,0,2000,2000 --scale 20000 --class const:0.5 --class " + sphere + " -o '" +
                   path("big.csv") + "'",
               "would emit at least");
  EXPECT_FALSE(fs::exists(path("big.csv")));
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
  // Bounds that differ as typed but are one double are said to be, not called inverted.
  expect_error("query --rect 1e17,0,100000000000000001,1 -o '" + path("z.csv") + "'", "less than a double");
  const Outcome inverted = kdm("query --rect 2,0,1,1 -o '" + path("z.csv") + "'");
  EXPECT_NE(inverted.err.find("empty or inverted"), std::string::npos) << inverted.err;
  EXPECT_EQ(inverted.err.find("double"), std::string::npos) << inverted.err;
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
  EXPECT_EQ(line, "x,y,tile_x,tile_y,rank,level,class,depth");
  std::vector<std::string> zero;
  std::size_t counts[3] = {};
  while (std::getline(in, line)) {  // ..., level, class, depth
    const std::size_t depth = line.rfind(','), comma = line.rfind(',', depth - 1);
    const int cls = std::atoi(line.c_str() + comma + 1);
    ASSERT_TRUE(cls >= 0 && cls < 3) << line;
    ++counts[cls];
    if (cls == 0) zero.push_back(line.substr(0, comma) + line.substr(depth));
  }
  std::sort(zero.begin(), zero.end());
  EXPECT_EQ(zero, sorted_rows(slurp(path("one.csv"))));
  EXPECT_NEAR(double(counts[1]) / double(counts[0]), 2.0, 0.05);  // rank prefixes: counts within a few points
  ASSERT_EQ(kdm("query --class const:1 --class const:2" + common + path("c.svg") + "'").status, 0);
  const std::string svg = slurp(path("c.svg"));
  EXPECT_NE(svg.find("<g id=\"class-0\""), std::string::npos);
  EXPECT_NE(svg.find("<g id=\"class-1\""), std::string::npos);
  ASSERT_EQ(kdm("query --class const:1 --class const:2" + common + path("c.json") + "'").status, 0);
  EXPECT_NE(slurp(path("c.json")).find("\"level\": 0, \"class\": 0, \"depth\": 0}"), std::string::npos);
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
// A rare class after dense ones gets what the running sums' counts leave: with constant densities their
// errors do not average out, so chests at one per tile after 124 points of trees and bushes come out
// about twice as many (5,186 of 2,500). Warned of, with the way out: as class 0 they get their count.
TEST_F(CliTest, QueryWarnsOfARareClassAfterDenseOnes) {
  const auto chests = [&](const std::string& classes, bool& warned) {
    const Outcome run =
        kdm("query --rect 0,0,1600,1600 --scale 1 --tile-size 32 " + classes + " -o '" + path("c.csv") + "'");
    EXPECT_EQ(run.status, 0) << run.err;
    warned = run.err.find("warning: class 2 expects at most 1.02 points per tile") != std::string::npos;
    std::istringstream in(slurp(path("c.csv")));
    std::string line;
    std::getline(in, line);
    std::size_t counts[3] = {};
    while (std::getline(in, line)) {
      std::istringstream row(line);
      std::string field;
      for (int column = 0; column < 7; ++column) std::getline(row, field, ',');
      ++counts[std::stoi(field)];
    }
    return counts[classes.find("const:0.001") < 20 ? 0 : 2];
  };
  bool warned = false;
  const double expected = 0.001 * 1600 * 1600;
  const double last = double(chests("--class const:0.02 --class const:0.1 --class const:0.001", warned));
  EXPECT_TRUE(warned);
  EXPECT_GT(std::abs(last / expected - 1), 0.3) << last;  // the miscount the warning is about
  const double first = double(chests("--class const:0.001 --class const:0.02 --class const:0.1", warned));
  EXPECT_NEAR(first / expected, 1, 0.03) << first;  // the one-class count: 2,500 of 2,560 measured
  // But at the same few places in every tile, under the coarsest level: said, with the tile size that
  // serves them on their own (32 points at 0.001 a unit area: 179 units).
  const std::string later = " --class const:0.02 --class const:0.1 -o '" + path("c.csv") + "'";
  const std::string small = "query --rect 0,0,64,64 --scale 1 --tile-size 32";
  expect_success_saying(
      small + " --class const:0.001" + later,
      "warning: class 0 expects at most 1.02 points per tile, under the tile set's coarsest "
      "level (32): its points take the same few places in every tile, a pattern that repeats "
      "with the tiles; query it on its own with a --tile-size of at least 179");
  expect_success_saying(small + " --class const:0.04" + later, "warning", false);
}

TEST_F(CliTest, StippleColoursSeparateInksIntoClasses) {
  const std::string coffee = "'" + std::string(KDM_SOURCE_DIR) + "/examples/coffee.png'";
  const std::string sphere = "'" + std::string(KDM_SOURCE_DIR) + "/examples/sphere.png'";
  ASSERT_EQ(kdm("stipple " + coffee + " --colours cmyk --points 8000 -o '" + path("c.svg") + "'").status, 0);
  const std::string svg = slurp(path("c.svg"));
  // Inkscape layers, one per pen in the printing order whatever the classes' order; white paper none.
  EXPECT_EQ(svg.find("<g id=\"paper\""), std::string::npos);
  std::size_t previous = 0;
  for (const std::string ink : {"cyan", "magenta", "yellow", "black"}) {
    const std::size_t at =
        svg.find("<g id=\"" + ink + "\" inkscape:groupmode=\"layer\" inkscape:label=\"" + ink);
    ASSERT_NE(at, std::string::npos) << ink;
    EXPECT_GT(at, previous) << ink;
    previous = at;
  }
  const Outcome grey_run = kdm("stipple " + sphere + " --colours cmyk -o '" + path("s.svg") + "'");
  ASSERT_EQ(grey_run.status, 0) << grey_run.err;
  EXPECT_NE(grey_run.err.find("classes 0 black #000000; no pixel uses cyan, magenta, yellow"),
            std::string::npos)
      << grey_run.err;
  // A grey picture has no colour to separate: black holds every dot, the other pens' layers stay, empty.
  const std::string grey = slurp(path("s.svg"));
  const auto layer = [&](const std::string& ink) {
    const std::size_t start = grey.find("<g id=\"" + ink + "\"");
    return start == std::string::npos ? std::string() : grey.substr(start, grey.find("</g>", start) - start);
  };
  EXPECT_NE(layer("black").find("<circle"), std::string::npos);
  for (const char* ink : {"cyan", "magenta", "yellow"}) {
    ASSERT_FALSE(layer(ink).empty()) << ink;
    EXPECT_EQ(layer(ink).find("<circle"), std::string::npos) << ink;
  }
  // N inks are the image's hues at full strength, drawn at the coverage each pixel's tone asks: a grey
  // image takes one black ink (clustered colours as inks drew a flat 50% grey 25% grey: an ink of the
  // pixel's own colour would have to cover all of it).
  ASSERT_EQ(kdm("stipple " + sphere + " --colours 4 -o '" + path("n.svg") + "'").status, 0);
  const std::string inks = slurp(path("n.svg"));
  const std::size_t first_ink = inks.find("<g id=\"ink-");
  ASSERT_NE(first_ink, std::string::npos);
  EXPECT_EQ(inks.find("<g id=\"ink-", first_ink + 1), std::string::npos);
  EXPECT_NE(inks.find("fill=\"#000000\"", first_ink), std::string::npos);
  // A grey ramp with a photograph's colour noise (±3 levels per channel) is still grey: one black ink (it
  // had six tinted near-black inks, and its darks came out light).
  kdm::tools::RgbImage noisy(128, 64);
  std::uint32_t lcg = 1;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 128; ++x)
      for (int k = 0; k < 3; ++k) {
        lcg = lcg * 1664525u + 1013904223u;
        const int level = 250 - 230 * x / 127 + int(lcg >> 29) - 3;
        noisy.pixels[(y * 128 + x) * 3 + k] = static_cast<std::uint8_t>(std::clamp(level, 0, 255));
      }
  std::string noise_error;
  ASSERT_TRUE(kdm::tools::write_png(path("noisy.png"), noisy, noise_error)) << noise_error;
  const Outcome grey8 = kdm("stipple '" + path("noisy.png") + "' --colours 8 -o '" + path("noisy.svg") + "'");
  ASSERT_EQ(grey8.status, 0) << grey8.err;
  EXPECT_NE(grey8.err.find("classes 0 ink-0-black #000000\n"), std::string::npos) << grey8.err;
  EXPECT_NE(grey8.err.find("inks 1 of 8)"), std::string::npos) << grey8.err;
  // Two flat halves, grey 128 and brown (150, 90, 50): each drawn in its own ink, in its own tone (within
  // 12 of 255 per channel; measured 1-4 off, where the clustered colours drew them 55-60 lighter).
  kdm::tools::RgbImage halves(64, 32);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) {
      const std::uint8_t brown[3] = {150, 90, 50};
      for (int k = 0; k < 3; ++k) halves.pixels[(y * 64 + x) * 3 + k] = x < 32 ? 128 : brown[k];
    }
  std::string error;
  ASSERT_TRUE(kdm::tools::write_png(path("halves.png"), halves, error)) << error;
  const Outcome two = kdm("stipple '" + path("halves.png") + "' --colours 3 --points 20000 --width 512 -o '" +
                          path("halves-out.png") + "'");
  ASSERT_EQ(two.status, 0) << two.err;
  kdm::tools::ColourImage drawn;
  ASSERT_TRUE(kdm::tools::load_colour_image(path("halves-out.png"), drawn, error)) << error;
  for (int half = 0; half < 2; ++half) {
    double mean[3] = {};
    int pixels = 0;
    for (int y = 32; y < 224; ++y)
      for (int x = 32 + 256 * half; x < 224 + 256 * half; ++x, ++pixels)
        for (int k = 0; k < 3; ++k) mean[k] += drawn.pixels[(std::size_t(y) * 512 + x) * 3 + k];
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(mean[k] / pixels * 255, half ? halves.pixels[32 * 3 + k] : 128, 12) << half << k;
  }
  // A hue sweep, bright at the top and dark at the bottom, asked for 8 inks: its yellow and cyan among
  // them, bright colours that no mix side by side draws, though the dark rows dominate the error. The
  // coffee, one hue in many shades, keeps its 3.
  kdm::tools::RgbImage sweep(256, 128);
  for (int y = 0; y < 128; ++y)
    for (int x = 0; x < 256; ++x) {
      const double h = x / 256.0 * 6, v = 1 - 0.8 * y / 127.0, f = h - std::floor(h);
      const double rise = v * f, fall = v * (1 - f);
      const double rgb[6][3] = {{v, rise, 0}, {fall, v, 0}, {0, v, rise},
                                {0, fall, v}, {rise, 0, v}, {v, 0, fall}};
      for (int k = 0; k < 3; ++k)
        sweep.pixels[(y * 256 + x) * 3 + k] = static_cast<std::uint8_t>(std::lround(rgb[int(h)][k] * 255));
    }
  ASSERT_TRUE(kdm::tools::write_png(path("sweep.png"), sweep, error)) << error;
  const Outcome eight =
      kdm("stipple '" + path("sweep.png") + "' --colours 8 --points 20000 -o '" + path("sweep.svg") + "'");
  ASSERT_EQ(eight.status, 0) << eight.err;
  EXPECT_NE(eight.err.find("-yellow #"), std::string::npos) << eight.err;
  EXPECT_NE(eight.err.find("-cyan #"), std::string::npos) << eight.err;
  const Outcome shades = kdm("stipple " + coffee + " --colours 8 --points 8000 -o '" + path("c8.csv") + "'");
  EXPECT_NE(shades.err.find("inks 3 of 8"), std::string::npos) << shades.err;
  ASSERT_EQ(kdm("stipple " + coffee + " --colours 3 --points 8000 -o '" + path("c.csv") + "'").status, 0);
  std::istringstream in(slurp(path("c.csv")));
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "x,y,class,id");  // tiles name their dots
  std::size_t counts[3] = {}, rows = 0;
  while (std::getline(in, line)) {
    const std::size_t third = line.find(',', line.find(',') + 1) + 1;
    const int k = std::atoi(line.c_str() + third);
    ASSERT_TRUE(k >= 0 && k < 3) << line;
    ++counts[k], ++rows;
  }
  EXPECT_NEAR(double(rows), 8000, 80);  // the dots of all inks together
  for (std::size_t c : counts) EXPECT_GT(c, 100u);
  ASSERT_EQ(kdm("stipple " + coffee + " --colours rgb --points 2000 -o '" + path("rgb.svg") + "'").status, 0);
  EXPECT_NE(slurp(path("rgb.svg")).find("fill=\"#000000\" stroke=\"none\"/>"),
            std::string::npos);  // black paper
  // Printed at a size: the SVG's width and height in the unit given, the drawing in its pixels inside.
  ASSERT_EQ(
      kdm("stipple " + coffee + " --points 2000 --width 600 --paper-width 150mm -o '" + path("p.svg") + "'")
          .status,
      0);
  const std::string printed = slurp(path("p.svg"));
  double x0 = 0, y0 = 0, drawn_w = 0, drawn_h = 0, printed_h = 0;  // the picture within a dot's margin
  ASSERT_EQ(std::sscanf(printed.c_str() + printed.find("width=\"150mm\""),
                        "width=\"150mm\" height=\"%lfmm\" viewBox=\"%lf %lf %lf %lf\"", &printed_h, &x0, &y0,
                        &drawn_w, &drawn_h),
            5)
      << printed.substr(0, 300);
  EXPECT_TRUE(x0 == y0 && x0 < 0) << printed.substr(0, 300);
  EXPECT_NEAR(drawn_w + 2 * x0, 600, 1e-9);
  EXPECT_NEAR(drawn_h + 2 * x0, 400, 1e-9);
  EXPECT_NEAR(printed_h, 150 * drawn_h / drawn_w, 1e-6);
  expect_error("stipple " + coffee + " --paper-width 150 -o '" + path("p.svg") + "'", "and a unit");
  expect_error("stipple " + coffee + " --paper-width 0mm -o '" + path("p.svg") + "'",
               "from 0.001 to 1000000");
  expect_error("stipple " + coffee + " --paper-width 0x10mm -o '" + path("p.svg") + "'",
               "from 0.001 to 1000000");
  expect_error("stipple " + coffee + " --paper-width '' -o '" + path("p.svg") + "'",
               "--paper-width: is empty");
  expect_error("stipple " + coffee + " --paper-width 150mm -o '" + path("p.png") + "'", "write .svg");
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

// The artist's test picture, 150 x 100: cyan, magenta and yellow faces over the top half, a gradient
// (R = x, G = y, B = 1 - x) below, pure red and pure black strips at the bottom.
kdm::tools::RgbImage ink_picture() {
  kdm::tools::RgbImage image(150, 100);
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 150; ++x) {
      const double u = x / 150.0, v = y / 100.0;
      double rgb[3] = {u, v, 1 - u};
      const double faces[3][3] = {{0, 1, 1}, {1, 0, 1}, {1, 1, 0}};
      if (v < 0.5) std::copy(faces[std::min(2, int(u * 3))], faces[std::min(2, int(u * 3))] + 3, rgb);
      if (v > 0.8) std::fill(rgb, rgb + 3, 0.0), rgb[0] = u < 0.5 ? 1 : 0;
      for (int k = 0; k < 3; ++k)
        image.pixels[(std::size_t(y) * 150 + x) * 3 + k] =
            static_cast<std::uint8_t>(std::lround(rgb[k] * 255));
    }
  return image;
}

// Each class's dots in a .csv (x, y), by class number.
std::map<int, std::vector<std::pair<double, double>>> csv_classes(const std::string& text) {
  std::map<int, std::vector<std::pair<double, double>>> classes;
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    double x = 0, y = 0;
    int k = 0;
    if (std::sscanf(line.c_str(), "%lf,%lf,%d", &x, &y, &k) == 3) classes[k].push_back({x, y});
  }
  return classes;
}

// --colours N: the inks are the picture's own colours (black where it has black, its saturated colours),
// and each pixel's colour is split over them, so that the picture's colours come back, gradients by dots
// of several inks. It chose a brown and no red or black, drew black #0f2000 and the gradient as flat
// patches of one ink each (blocks off by up to 67 of 255; now 28).
TEST_F(CliTest, StippleNInksDrawThePicturesColours) {
  std::string error;
  const kdm::tools::RgbImage image = ink_picture();
  ASSERT_TRUE(kdm::tools::write_png(path("c.png"), image, error)) << error;
  const Outcome six = kdm("stipple '" + path("c.png") + "' --colours 6 --points 20000 --width 600 -o '" +
                          path("n6.png") + "'");
  ASSERT_EQ(six.status, 0) << six.err;
  for (const char* ink :
       {"black #000000", "red #ff0000", "cyan #00ffff", "magenta #ff00ff", "yellow #ffff00"})
    EXPECT_NE(six.err.find(ink), std::string::npos) << ink << "\n" << six.err;
  // Blocks of 1/12 of the width: each one's mean colour in the picture against the image's.
  kdm::tools::ColourImage drawn;
  ASSERT_TRUE(kdm::tools::load_colour_image(path("n6.png"), drawn, error)) << error;
  ASSERT_EQ(drawn.width, 600);
  double worst = 0, sum = 0;
  int blocks = 0;
  for (int by = 0; by < 8; ++by)
    for (int bx = 0; bx < 12; ++bx, ++blocks) {
      double want[3] = {}, got[3] = {};
      for (int y = by * 100 / 8; y < (by + 1) * 100 / 8; ++y)
        for (int x = bx * 150 / 12; x < (bx + 1) * 150 / 12; ++x)
          for (int k = 0; k < 3; ++k) want[k] += image.pixels[(std::size_t(y) * 150 + x) * 3 + k];
      for (int y = by * 400 / 8; y < (by + 1) * 400 / 8; ++y)
        for (int x = bx * 600 / 12; x < (bx + 1) * 600 / 12; ++x)
          for (int k = 0; k < 3; ++k) got[k] += drawn.pixels[(std::size_t(y) * 600 + x) * 3 + k] * 255;
      double off = 0;
      for (int k = 0; k < 3; ++k)
        off = std::max(off, std::abs(want[k] / (12.5 * 12.5) - got[k] / (50.0 * 50.0)));
      worst = std::max(worst, off), sum += off;
    }
  EXPECT_LT(worst, 45) << "mean " << sum / blocks;
  EXPECT_LT(sum / blocks, 25);
  // The gradient by several inks: in each of 10 windows along it, at least two inks hold a tenth of its dots.
  ASSERT_EQ(
      kdm("stipple '" + path("c.png") + "' --colours 6 --points 20000 -o '" + path("n6.csv") + "'").status,
      0);
  const auto classes = csv_classes(slurp(path("n6.csv")));
  int mixed = 0;
  for (int w = 0; w < 10; ++w) {
    std::map<int, int> counts;
    int all = 0;
    for (const auto& [k, dots] : classes)
      for (const auto& [x, y] : dots)
        if (x >= w / 10.0 && x < (w + 1) / 10.0 && y > 0.22 && y < 0.48) ++counts[k], ++all;
    int inks = 0;
    for (const auto& [k, n] : counts) inks += n >= 0.1 * all;
    mixed += inks >= 2;
  }
  EXPECT_GE(mixed, 9);
  // Four inks: black stays black.
  const Outcome four = kdm("stipple '" + path("c.png") + "' --colours 4 -o '" + path("n4.csv") + "'");
  ASSERT_EQ(four.status, 0) << four.err;
  EXPECT_NE(four.err.find("black #000000"), std::string::npos) << four.err;
}

// The user's own pens as inks, split as N inks are; the printed list, the .svg's layers and the .csv's
// classes one numbering that names each ink and its colour.
TEST_F(CliTest, StipplePensAsInksOneNumbering) {
  std::string error;
  ASSERT_TRUE(kdm::tools::write_png(path("c.png"), ink_picture(), error)) << error;
  const std::string pens = " --colours '#e00000,#0000aa,#000000,#00aa00' --points 6000 ";
  const Outcome run = kdm("stipple '" + path("c.png") + "'" + pens + "-o '" + path("p.svg") + "'");
  ASSERT_EQ(run.status, 0) << run.err;
  ASSERT_EQ(kdm("stipple '" + path("c.png") + "'" + pens + "-o '" + path("p.csv") + "'").status, 0);
  EXPECT_NE(run.err.find("inks 4 of 4 given"), std::string::npos) << run.err;
  const std::string svg = slurp(path("p.svg"));
  const auto classes = csv_classes(slurp(path("p.csv")));
  ASSERT_EQ(classes.size(), 4u);
  std::set<std::string> colours;
  for (const auto& [k, dots] : classes) {
    // "K ink-K-word #rrggbb" printed; the layer of that name holds class K's dots, in that colour.
    const std::string key = std::to_string(k) + " ink-" + std::to_string(k) + "-";
    const std::size_t at = run.err.find(key);
    ASSERT_NE(at, std::string::npos) << key << "\n" << run.err;
    const std::size_t hash = run.err.find(" #", at);
    const std::string name = run.err.substr(at + key.size() - 6, hash - (at + key.size() - 6));
    const std::string hex = run.err.substr(hash + 1, 7);
    colours.insert(hex);
    const std::size_t layer = svg.find("<g id=\"" + name + "\"");
    ASSERT_NE(layer, std::string::npos) << name;
    const std::string group = svg.substr(layer, svg.find("</g>", layer) - layer);
    EXPECT_NE(group.find("fill=\"" + hex + "\""), std::string::npos) << name;
    std::size_t circles = 0;
    for (std::size_t c = group.find("<circle"); c != std::string::npos; c = group.find("<circle", c + 1))
      ++circles;
    EXPECT_EQ(circles, dots.size()) << name;
  }
  EXPECT_EQ(colours, (std::set<std::string>{"#e00000", "#0000aa", "#000000", "#00aa00"}));
  // The layers come in the pens' order as given (a plotter's pens stay put), not in class order.
  const auto layer_at = [](const std::string& text, const char* hex) {
    return text.find("fill=\"" + std::string(hex) + "\"");
  };
  EXPECT_LT(layer_at(svg, "#e00000"), layer_at(svg, "#0000aa"));
  EXPECT_LT(layer_at(svg, "#0000aa"), layer_at(svg, "#000000"));
  EXPECT_LT(layer_at(svg, "#000000"), layer_at(svg, "#00aa00"));
  ASSERT_EQ(
      kdm("stipple '" + path("c.png") + "' --colours '#00aa00,#000000,#0000aa,#e00000' --points 6000 -o '" +
          path("reversed.svg") + "'")
          .status,
      0);
  const std::string reversed = slurp(path("reversed.svg"));
  EXPECT_LT(layer_at(reversed, "#00aa00"), layer_at(reversed, "#000000"));
  EXPECT_LT(layer_at(reversed, "#000000"), layer_at(reversed, "#0000aa"));
  EXPECT_LT(layer_at(reversed, "#0000aa"), layer_at(reversed, "#e00000"));
  EXPECT_NE(run.err.find("ink-0-"), std::string::npos);
  EXPECT_NE(svg.find("-black\""), std::string::npos);
  for (const char* bad : {"'#e00000,#12345'", "'#e00000,,#000000'", "'#ffffff'", "'#000000,#000000'",
                          "'#000000,#111111,#222222,#333333,#444444,#555555,#666666,#777777,#888888'"})
    expect_error("stipple '" + path("c.png") + "' --colours " + bad + " -o '" + path("x.png") + "'", "ink");
  // Spaces around the pens, as a list is typed, change nothing.
  ASSERT_EQ(
      kdm("stipple '" + path("c.png") +
          "' --colours ' #e00000, #0000aa,#000000 ,\t#00aa00' --points 6000 -o '" + path("spaced.csv") + "'")
          .status,
      0);
  EXPECT_EQ(slurp(path("spaced.csv")), slurp(path("p.csv")));
}

// SVG dots in plotting order: each layer's dots as a pen would draw them, each the nearest left (travel was
// about 16 times a greedy order's, the dots coming in the tiles' order), every dot inside the picture,
// and no paper rectangle for a plotter to trace as a frame (other paper in a layer AxiDraw skips).
TEST_F(CliTest, StippleSvgInPlottingOrder) {
  std::string error;
  ASSERT_TRUE(kdm::tools::write_png(path("c.png"), ink_picture(), error)) << error;
  const Outcome run = kdm("stipple '" + path("c.png") + "' --colours cmyk --points 20000 --width 600 -o '" +
                          path("p.svg") + "'");
  ASSERT_EQ(run.status, 0) << run.err;
  const std::string svg = slurp(path("p.svg"));
  EXPECT_EQ(svg.find("<rect"), std::string::npos);
  double r_max = 0;  // the margin around the picture
  ASSERT_EQ(std::sscanf(svg.c_str() + svg.find("viewBox="), "viewBox=\"%lf", &r_max), 1);
  r_max = -r_max;
  std::size_t layers = 0;
  for (std::size_t at = svg.find("<g id="); at != std::string::npos;
       at = svg.find("<g id=", at + 1), ++layers) {
    const std::string group = svg.substr(at, svg.find("</g>", at) - at);
    double travel = 0, px = 0, py = 0;
    std::size_t dots = 0;
    for (std::size_t c = group.find("<circle"); c != std::string::npos; c = group.find("<circle", c + 1)) {
      double x = 0, y = 0, r = 0;
      ASSERT_EQ(std::sscanf(group.c_str() + c, "<circle cx=\"%lf\" cy=\"%lf\" r=\"%lf\"", &x, &y, &r), 3);
      EXPECT_TRUE(x - r >= -r_max && x + r <= 600 + r_max && y - r >= -r_max && y + r <= 400 + r_max)
          << x << "," << y;
      if (dots++) travel += std::hypot(x - px, y - py);
      px = x, py = y;
    }
    // A greedy order's travel is about 1.1 sqrt(n A) for n blue-noise dots over an area A of the picture.
    if (dots > 100) {
      EXPECT_LT(travel, 1.5 * std::sqrt(double(dots) * 600 * 400)) << group.substr(0, 80);
    }
  }
  EXPECT_EQ(layers, 4u);
  // rgb's black paper: a rectangle in a layer whose name starts with % (not plotted), no stroke.
  ASSERT_EQ(
      kdm("stipple '" + path("c.png") + "' --colours rgb --points 2000 -o '" + path("r.svg") + "'").status,
      0);
  EXPECT_NE(slurp(path("r.svg")).find("\" width=\"100%\" height=\"100%\" fill=\"#000000\" stroke=\"none\"/>"),
            std::string::npos);
}

// Every SVG dot lies within the picture as its numbers are printed: rounding a centre next to the edge to
// 6 digits once carried its circle past the edge by thousandths of a pixel (a dark picture, dots all along
// its edges, at widths whose coordinates keep 1 or 2 decimals).
TEST_F(CliTest, StippleSvgDotsStayInsideAsPrinted) {
  write_bytes(path("black.png"), grey_png(8, 8, 8, std::vector<std::uint16_t>(64, 0)));
  for (const int width : {1000, 1500, 2048, 777}) {
    SCOPED_TRACE(width);
    const Outcome run = kdm("stipple '" + path("black.png") + "' --points 20000 --width " +
                            std::to_string(width) + " -o '" + path("b.svg") + "'");
    ASSERT_EQ(run.status, 0) << run.err;
    const std::string svg = slurp(path("b.svg"));
    double x0 = 0, w = 0, h = 0;  // the drawing: the picture within a margin of -x0
    ASSERT_EQ(std::sscanf(svg.c_str() + svg.find("viewBox="), "viewBox=\"%lf %*f %lf %lf\"", &x0, &w, &h), 3);
    ASSERT_LT(x0, 0);
    w += x0, h += x0;  // the far edges (the near ones at x0)
    std::size_t dots = 0, edge = 0;
    const double near = 0.1 * std::sqrt(w * h / 20000);  // a tenth of the dots' spacing
    for (std::size_t c = svg.find("<circle"); c != std::string::npos;
         c = svg.find("<circle", c + 1), ++dots) {
      double x = 0, y = 0, r = 0;
      ASSERT_EQ(std::sscanf(svg.c_str() + c, "<circle cx=\"%lf\" cy=\"%lf\" r=\"%lf\"", &x, &y, &r), 3);
      const double ulps = 1e-9;  // of a reader's sums of the printed numbers
      EXPECT_TRUE(x - r >= x0 - ulps && x + r <= w + ulps && y - r >= x0 - ulps && y + r <= h + ulps)
          << x << "," << y << " r " << r;
      edge += x + r > w - near || y + r > h - near;
    }
    EXPECT_GT(dots, 19000u);
    EXPECT_GT(edge, 10u);  // dots near the right or bottom edge
  }
}

// --method full with inks: a class never lands where its own ink is zero (cyan dots in a black area came
// from the sampler's classes filling one another's gaps at their summed density).
TEST_F(CliTest, StippleFullInksOnlyWhereTheirInkIs) {
  kdm::tools::RgbImage image(90, 60);
  for (int y = 0; y < 60; ++y)
    for (int x = 0; x < 90; ++x) {
      const std::uint8_t black[3] = {0, 0, 0}, cyan[3] = {0, 255, 255}, yellow[3] = {255, 255, 0};
      const std::uint8_t* rgb = y < 20 ? yellow : x < 45 ? black : cyan;
      std::copy(rgb, rgb + 3, &image.pixels[(std::size_t(y) * 90 + x) * 3]);
    }
  std::string error;
  ASSERT_TRUE(kdm::tools::write_png(path("kc.png"), image, error)) << error;
  const Outcome run = kdm("stipple '" + path("kc.png") + "' --method full --colours cmyk --points 6000 -o '" +
                          path("f.csv") + "'");
  ASSERT_EQ(run.status, 0) << run.err;
  ASSERT_NE(run.err.find("classes 0 black #000000, 1 cyan #00aeef, 2 yellow #fff200"), std::string::npos)
      << run.err;
  const auto classes = csv_classes(slurp(path("f.csv")));
  std::size_t counted = 0;
  for (const auto& [k, dots] : classes)
    for (const auto& [u, v] : dots) {
      const double x = u * 90, y = (1 - v) * 60;  // pixels, y down; two pixels in from each area's edge
      const int area = y < 18 ? 2 : y > 22 && x < 43 ? 0 : y > 22 && x > 47 ? 1 : -1;  // its one ink
      if (area < 0) continue;
      EXPECT_EQ(k, area) << u << "," << v;
      ++counted;
    }
  EXPECT_GT(counted, 5000u);
}

// Small frictions of kdm stipple: the help says what --region, --invert and --format allow; a transparent
// image is said to be transparent, not white; a format kdm does not read is named, with those it reads.
TEST_F(CliTest, StippleSaysWhatItTakes) {
  const Outcome help = kdm("stipple --help");
  ASSERT_EQ(help.status, 0);
  std::string words;  // the help's words on one line, whatever its wrapping
  std::istringstream in(help.out);
  for (std::string word; in >> word;) words += word + " ";
  for (const char* said :
       {"needs --method tiles; zoom", "not with --colours", "-o x.png --format svg is refused",
        "#rrggbb,#rrggbb", "drawing order", "AxiDraw skips"})
    EXPECT_NE(words.find(said), std::string::npos) << said;
  std::vector<std::uint16_t> clear(16 * 16 * 2, 0);  // grey and alpha, all 0
  write_bytes(path("clear.png"), grey_png(16, 16, 8, clear, 2));
  for (const char* colours : {"", " --colours 3"}) {
    const Outcome none = kdm("stipple '" + path("clear.png") + "'" + colours + " -o '" + path("n.svg") + "'");
    ASSERT_EQ(none.status, 0) << none.err;
    EXPECT_NE(none.err.find("(it is all transparent)"), std::string::npos) << none.err;
    EXPECT_EQ(none.err.find("white"), std::string::npos) << none.err;
  }
  std::ofstream(path("x.tif"), std::ios::binary) << std::string("II*\0\x08\0\0\0\0\0\0\0", 12);
  std::ofstream(path("x.webp"), std::ios::binary)
      << std::string("RIFF\x1a\0\0\0WEBPVP8 \0\0\0\0\0\0\0\0", 24);
  expect_error("stipple '" + path("x.tif") + "' -o '" + path("x.png") + "'", "a TIFF image");
  expect_error("stipple '" + path("x.webp") + "' --colours 3 -o '" + path("x.png") + "'",
               "a WebP image, a format kdm does not read (it reads PNG, JPEG");
  std::ofstream(path("x.jxl"), std::ios::binary) << std::string("\0\0\0\x0cJXL \x0d\x0a\x87\x0a", 12);
  expect_error("stipple '" + path("x.jxl") + "' -o '" + path("x.png") + "'", "a JPEG XL image");
  // Bytes of no format are not named as one (a magic with NULs had matched every file as JPEG XL).
  std::ofstream(path("junk.png"), std::ios::binary) << "hello, these are no picture's bytes";
  const Outcome junk = kdm("stipple '" + path("junk.png") + "' -o '" + path("x.png") + "'");
  EXPECT_NE(junk.status, 0);
  EXPECT_EQ(junk.err.find("JPEG XL"), std::string::npos) << junk.err;
  EXPECT_NE(junk.err.find("cannot read image"), std::string::npos) << junk.err;
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
  // A picture is never written over the density image it was made from (stipple already refused it).
  fs::copy_file(std::string(KDM_SOURCE_DIR) + "/examples/sphere.png", path("own.png"));
  const std::string own = slurp(path("own.png"));
  expect_error("sample -n 100 --density '" + path("own.png") + "' -o '" + path("own.png") + "'",
               "is the density image");
  expect_error(
      "query --rect 0,0,1,1 --class const:1 --class '" + path("own.png") + "' -o '" + path("own.png") + "'",
      "is the density image");
  EXPECT_EQ(slurp(path("own.png")), own);
  expect_error("bake '" + dir_.string() + "' -o '" + path("x.kdmt") + "'", "it is a directory");
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
  // Tiles too small for a point each are said, not refused; past 2^24 of them the region is refused, also
  // where the count underflows to 0 (a tile size in the wrong units), naming the tile size.
  for (const char* tiny : {"0.001", "1e-300"}) {
    const Outcome sparse =
        kdm(std::string("query --rect 0,0,1,1 --tile-size ") + tiny + " -o '" + path("t.csv") + "'");
    EXPECT_NE(sparse.err.find("warning: at most"), std::string::npos) << tiny << ": " << sparse.err;
    if (std::string(tiny) == "0.001") {
      ASSERT_EQ(sparse.status, 0) << sparse.err;
    } else {
      EXPECT_EQ(sparse.status, 1);
      EXPECT_NE(sparse.err.find("more tiles than one query may"), std::string::npos) << sparse.err;
      EXPECT_NE(sparse.err.find("--tile-size"), std::string::npos) << sparse.err;
    }
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
  // Without a density the bands and the holes' density floor would do nothing: refused, as --gamma is.
  expect_error("analyze '" + path("ramp.txt") + "' --density-bands 5",
               "--density-bands applies with a density (--density or --class-density), and none is given");
  expect_error("analyze '" + path("ramp.txt") + "' --holes-min-density 0.5", "--holes-min-density applies");
  const Outcome floor =
      kdm("analyze '" + path("ramp.txt") + "' --box --density ramp:100 --holes-min-density 0.5 --no-energy");
  EXPECT_EQ(floor.status, 0) << floor.err;
  // --min-expected also sizes the uniformity check's windows (the spectrum's "nonuniform"): taken alone.
  EXPECT_EQ(kdm("analyze '" + path("ramp.txt") + "' --min-expected 50 --no-energy").status, 0);
}

// A chunk of a map queried without --density-rect gets the whole map squeezed into it: where the shapes
// differ that is said. A count per tile that rounds to none says so too (it said only "steps of 1/16").
TEST_F(CliTest, QueryWarnsOfAStretchedMapAndOfACountThatRoundsToNone) {
  std::ofstream(path("m.npy"), std::ios::binary)
      << npy_volume(std::vector<double>(80 * 100, 1.0), 0, 0, 0, "<f8", "80, 100");
  const std::string map = " --density '" + path("m.npy") + "' --scale 100 -o '" + path("q.csv") + "'";
  expect_success_saying("query --rect 0,0,20,20" + map, "the 100x80 map is stretched over --rect");
  expect_success_saying("query --rect 0,0,25,20" + map, "stretched", false);
  expect_success_saying("query --rect 0,0,20,20 --density-rect 0,0,25,20" + map, "stretched", false);
  const std::string constant = " --scale 10 -o '" + path("q.csv") + "'";
  const Outcome none = expect_success_saying("query --rect 0,0,100,100 --density const:0.003" + constant,
                                             "steps of 1/16 of a point, and this one to none");
  EXPECT_NE(none.err.find("kdm query: 0 points"), std::string::npos) << none.err;
  // 0.05 a tile rounds to 1/16 of a point, not to none.
  expect_success_saying("query --rect 0,0,100,100 --density const:0.005" + constant, "to none", false);
}

}  // namespace

// A set sampled in a wider domain is measured in it, and kdm analyze says so (from the aspect or sides kdm
// sample writes in its header); a square or cube draws no such line, nor a warning of stretched measures.
TEST_F(CliTest, AnalyzeWarnsOfASetSampledInAnotherShape) {
  for (const std::string aspect : {"2", "1"}) {
    ASSERT_EQ(kdm("sample --n 200 --aspect " + aspect + " -o '" + path("s.txt") + "'").status, 0);
    const Outcome r = kdm("analyze '" + path("s.txt") + "' --no-energy");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out.find("domain from the file header: aspect 2") != std::string::npos, aspect == "2")
        << r.out;
    EXPECT_EQ(r.err.find("stretched"), std::string::npos) << r.err;
  }
  // A 3D box of three sides of its own, and a cube given as three equal sides.
  for (const std::string sides : {"2:1:0.5", "1:1:1"}) {
    ASSERT_EQ(kdm("sample --dim 3 --n 300 --aspect " + sides + " -o '" + path("v.txt") + "'").status, 0);
    const Outcome r = kdm("analyze '" + path("v.txt") + "' --no-energy");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out.find("domain from the file header: sides 2:1:0.5") != std::string::npos,
              sides == "2:1:0.5")
        << r.out;
  }
}
