// kdm analyze on the command line: JSON to standard output, the domain a set was drawn in (from its
// header or none), and labelled points judged class by class.
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

}  // namespace
