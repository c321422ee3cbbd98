// Reading point files (read_point_sets / load_point_sets): good files, several sets per file, and every kind
// of bad input; the JSON writer; the analyze() aggregation on a small input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include "kdm/analysis/json.h"
#include "kdm/analysis/report.h"
#include "point_io.h"
#include "test_sets.h"

namespace kdm::analysis {
namespace {

std::string write_temp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "kdm_analysis_" + name;
  std::ofstream(path) << text;
  return path;
}

std::string read_error(const std::string& text, const std::string& name) {
  std::vector<tools::PointSet> sets;
  std::string error;
  EXPECT_FALSE(tools::read_point_sets(write_temp(name, text), sets, error)) << name;
  return error;
}

TEST(PointFiles, ReadsSeveralSets) {
  const std::string path = write_temp("two.txt", "# header\n0.1 0.2\n0.3 0.4\n#\n0.5 0.6\n\n0.7,0.8\r\n");
  std::vector<tools::PointSet> sets;
  std::string error;
  ASSERT_TRUE(tools::read_point_sets(path, sets, error)) << error;
  ASSERT_EQ(sets.size(), 2u);
  EXPECT_EQ(sets[0].size(), 2u);
  EXPECT_EQ(sets[1].size(), 2u);
  EXPECT_DOUBLE_EQ(sets[1].coords[3], 0.8);
  const std::vector<tools::PointSet> all = load_point_sets({path, path});
  EXPECT_EQ(all.size(), 4u);
  // Labelled and unlabelled files are refused together before any measure, naming the file.
  const std::string labelled = write_temp("labelled.csv", "x,y,class\n0.1,0.2,0\n0.5,0.6,1\n");
  try {
    load_point_sets({labelled, path});
    ADD_FAILURE() << "pooled labelled and unlabelled points";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find(path + " (set 1): points without classes after labelled ones"),
              std::string::npos)
        << e.what();
  }
}

/// `set` written to the temporary file `name` and read back: the one set it must hold.
tools::PointSet round_trip(const tools::PointSet& set, const std::string& name) {
  std::string error;
  EXPECT_TRUE(tools::write_point_set(::testing::TempDir() + name, set, {}, error)) << error;
  std::vector<tools::PointSet> sets;
  EXPECT_TRUE(tools::read_point_sets(::testing::TempDir() + name, sets, error)) << error;
  EXPECT_EQ(sets.size(), 1u);
  return sets.empty() ? tools::PointSet{} : sets.front();
}

TEST(PointFiles, CsvRoundTrip) {
  tools::PointSet s = testing::uniform_set(10, 31);
  EXPECT_EQ(round_trip(s, "kdm_analysis_round.csv").coords, s.coords);  // 17 significant digits: exact
  std::vector<tools::PointSet> sets;
  std::string error;
  EXPECT_FALSE(tools::read_point_sets(write_temp("late_header.csv", "0.1,0.2\nx,y\n"), sets, error));
}

// Labelled points: "x,y,class" CSV round trips, kdm query's CSV reads as x, y (and class), and bad classes
// are refused by line.
TEST(PointFiles, LabelledPointsRoundTripAndQueryCsvReads) {
  tools::PointSet set = testing::uniform_set(50, 3);
  for (std::size_t i = 0; i < set.size(); ++i) set.classes.push_back(static_cast<std::uint8_t>(i % 3));
  const tools::PointSet back = round_trip(set, "kdm_analysis_labelled.csv");
  EXPECT_EQ(back.coords, set.coords);
  EXPECT_EQ(back.classes, set.classes);
  std::string error;
  std::vector<tools::PointSet> sets;
  EXPECT_FALSE(tools::write_point_set(::testing::TempDir() + "kdm_analysis_labelled.txt", set, {}, error));
  EXPECT_NE(error.find(".csv"), std::string::npos);
  ASSERT_TRUE(tools::read_point_sets(
      write_temp("query.csv",
                 "x,y,tile_x,tile_y,rank,level,class\n0.25,0.5,0,0,3,0,2\n0.75,0.125,1,0,0,0,0\n"),
      sets, error))
      << error;
  EXPECT_EQ(sets[0].coords, (std::vector<double>{0.25, 0.5, 0.75, 0.125}));
  EXPECT_EQ(sets[0].classes, (std::vector<std::uint8_t>{2, 0}));
  ASSERT_TRUE(tools::read_point_sets(
      write_temp("query1.csv", "x,y,tile_x,tile_y,rank,level\n0.25,0.5,0,0,3,0\n"), sets, error));
  EXPECT_TRUE(sets[0].classes.empty());
  // Today's, with the depth column last.
  ASSERT_TRUE(tools::read_point_sets(
      write_temp("query2.csv", "x,y,tile_x,tile_y,rank,level,class,depth\n0.25,0.5,0,0,3,0,2,1\n"), sets,
      error))
      << error;
  EXPECT_EQ(sets[0].coords, (std::vector<double>{0.25, 0.5}));
  EXPECT_EQ(sets[0].classes, (std::vector<std::uint8_t>{2}));
  ASSERT_TRUE(tools::read_point_sets(
      write_temp("query3.csv", "x,y,tile_x,tile_y,rank,level,depth\n0.25,0.5,0,0,3,0,1\n"), sets, error))
      << error;
  EXPECT_TRUE(sets[0].classes.empty());
  EXPECT_NE(read_error("x,y,class\n0.1,0.2,1.5\n", "half.csv").find(":2: a class must be an integer"),
            std::string::npos);
  EXPECT_NE(read_error("x,y,class\n0.1,0.2,256\n", "big.csv").find("0 to 255"), std::string::npos);
  EXPECT_NE(read_error("x,y,class\n0.1,0.2,nan\n", "nan.csv").find(":2: a class must be an integer"),
            std::string::npos);
  EXPECT_NE(read_error("x,y,class\nnan,0.2,1\n", "x.csv").find(":2: non-finite coordinate"),
            std::string::npos);
  EXPECT_NE(read_error("x,y,class\n0.1,0.2\n", "short.csv").find("expected 3 columns"), std::string::npos);
}

// Coordinates are written as printf's %.17g, so they read back exactly and the files stay byte for byte
// what earlier versions wrote.
TEST(PointFiles, WritesSeventeenSignificantDigits) {
  tools::PointSet s;
  s.dim = 2;
  s.coords = {0.0, 0.1, 1e-7, 0.99999999999999989, 0.5, 2.5e-300, 1.0 / 3, 0.25};
  const std::string path = ::testing::TempDir() + "kdm_analysis_digits.txt";
  std::string error;
  ASSERT_TRUE(tools::write_point_set(path, s, {"a header"}, error)) << error;
  std::string expected = "# a header\n";
  char line[64];
  for (std::size_t i = 0; i < s.size(); ++i) {
    std::snprintf(line, sizeof line, "%.17g %.17g\n", s.coords[2 * i], s.coords[2 * i + 1]);
    expected += line;
  }
  std::ifstream in(path);
  const std::string written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(written, expected);
}

TEST(PointFiles, RejectsBadInput) {
  EXPECT_NE(read_error("", "empty.txt").find("no points"), std::string::npos);
  EXPECT_NE(read_error("# only a comment\n", "comment.txt").find("no points"), std::string::npos);
  EXPECT_NE(read_error("0.1 0.2\n0.3 abc\n", "malformed.txt").find(":2:"), std::string::npos);
  EXPECT_NE(read_error("0.1 nan\n", "nan.txt").find("non-finite"), std::string::npos);
  EXPECT_NE(read_error("0.1 inf\n", "inf.txt").find("non-finite"), std::string::npos);
  EXPECT_NE(read_error("0.1 1e999\n", "overflow.txt").find("non-finite"), std::string::npos);
  EXPECT_NE(read_error("0.1\n", "one.txt").find("expected 2 or 3"), std::string::npos);
  EXPECT_NE(read_error("0.1 0.2\n0.1 0.2 0.3\n", "mixed.txt").find("dimension changes"), std::string::npos);
  std::vector<tools::PointSet> sets;
  std::string error;
  EXPECT_FALSE(tools::read_point_sets("/nonexistent/kdm/points.txt", sets, error));
  EXPECT_NE(error.find("cannot open"), std::string::npos);
  EXPECT_THROW(load_point_sets({"/nonexistent/kdm/points.txt"}), InvalidInput);
  EXPECT_THROW(load_point_sets({write_temp("range.txt", "0.1 1.5\n0.2 0.3\n")}), InvalidInput);
  EXPECT_THROW(load_point_sets({write_temp("d2.txt", "0.1 0.5\n"), write_temp("d3.txt", "0.1 0.5 0.2\n")}),
               InvalidInput);
  EXPECT_THROW(load_point_sets({}), InvalidInput);
}

/// The one set `text` (a file named `name`) reads as; empty with the failure recorded if it reads not.
tools::PointSet read_one(const std::string& text, const std::string& name) {
  std::vector<tools::PointSet> sets;
  std::string error;
  EXPECT_TRUE(tools::read_point_sets(write_temp(name, text), sets, error)) << name << ": " << error;
  EXPECT_EQ(sets.size(), 1u) << name;
  return sets.empty() ? tools::PointSet{} : sets.front();
}

// Other tools' CSV headers: the columns named x and y (and z, class or label), trimmed and in any case and
// order, are read, and the others skipped whatever they hold; a header that names no x or y says so.
TEST(PointFiles, CsvHeadersAreReadByTheirColumnNames) {
  const std::vector<double> xy = {0.25, 0.5, 0.75, 0.125};
  for (const char* text :
       {"x, y\n0.25, 0.5\n0.75, 0.125\n", "X,Y\n0.25,0.5\n0.75,0.125\n", "y,x\n0.5,0.25\n0.125,0.75\n",
        "id,x,y\np1,0.25,0.5\np2,0.75,0.125\n", "\"x\",\"y\",\"note\"\n0.25,0.5,a b\n0.75,0.125,\n",
        "x y\n0.25 0.5\n0.75 0.125\n",
        // pandas' unnamed index column, a trailing comma, Excel's UTF-8 byte-order mark, a quoted comma
        ",x,y\n0,0.25,0.5\n1,0.75,0.125\n", "x,y,\n0.25,0.5,\n0.75,0.125,\n",
        "\xEF\xBB\xBFx,y\n0.25,0.5\n0.75,0.125\n",
        "\"x\",\"y\",\"note, with comma\"\n0.25,0.5,\"a, b\"\n0.75,0.125,c\n"}) {
    SCOPED_TRACE(text);
    const tools::PointSet set = read_one(text, "named.csv");
    EXPECT_EQ(set.dim, 2);
    EXPECT_EQ(set.coords, xy);
    EXPECT_TRUE(set.classes.empty());
  }
  for (const char* text :
       {"x,y,label\n0.25,0.5,1\n0.75,0.125,0\n", "Class,Y,X\n1,0.5,0.25\n0,0.125,0.75\n"}) {
    const tools::PointSet set = read_one(text, "labelled.csv");
    EXPECT_EQ(set.coords, xy) << text;
    EXPECT_EQ(set.classes, (std::vector<std::uint8_t>{1, 0})) << text;
  }
  const tools::PointSet zyx = read_one("z,y,x\n0.1,0.5,0.25\n", "zyx.csv");
  EXPECT_EQ(zyx.coords, (std::vector<double>{0.25, 0.5, 0.1}));
  EXPECT_NE(read_error("a,b\n0.1,0.2\n", "ab.csv").find(":1: header 'a,b': expected columns named x and y"),
            std::string::npos);
  EXPECT_NE(read_error("x,X,y\n0.1,0.2,0.3\n", "twice.csv").find("names column x twice"), std::string::npos);
  EXPECT_NE(read_error("x,y,class,label\n0.1,0.2,0,1\n", "cl.csv").find("names the class twice"),
            std::string::npos);
  EXPECT_NE(read_error("x;y\n0.1;0.2\n", "semi.csv").find("not semicolons"), std::string::npos);
  EXPECT_NE(read_error("x,y,class\n0.1,0.2,a\n", "letter.csv")
                .find(":2: a class must be an integer 0 to 255, not 'a'"),
            std::string::npos);
  EXPECT_EQ(read_error(",\n0.1,0.2\n", "unnamed.csv").find("header"), std::string::npos);  // no name: a row
  EXPECT_NE(read_error("x,y,z,class\n0.1,0.2,0.3,1\n", "zc.csv").find("classes are for 2D points"),
            std::string::npos);
  EXPECT_NE(read_error("id,x,y\n1,0.2\n", "short.csv").find(":2: expected 3 columns, found 2"),
            std::string::npos);
  EXPECT_NE(read_error("id,x,y\n1,0.2,abc\n", "bad.csv").find(":2: malformed number"), std::string::npos);
  // A first line of numbers, "nan" among them, is a row, not a header.
  EXPECT_NE(read_error("nan,0.5\n", "nan.csv").find(":1: non-finite"), std::string::npos);
}

// A labelled CSV without its header reads as 3D points: said in a warning when every z is 0 or 1, and in
// the error when a class lies outside the unit square.
TEST(PointFiles, AClassColumnWithoutAHeaderIsPointedOut) {
  std::vector<std::string> warnings;
  const std::vector<tools::PointSet> sets =
      load_point_sets({write_temp("unlabelled.csv", "0.1,0.2,0\n0.3,0.4,1\n0.5,0.6,1\n")}, &warnings);
  EXPECT_EQ(sets.front().dim, 3);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("the header line x,y,class"), std::string::npos) << warnings[0];
  warnings.clear();
  load_point_sets({write_temp("plain3d.txt", "0.1 0.2 0.3\n0.3 0.4 1\n")}, &warnings);
  EXPECT_TRUE(warnings.empty());
  try {
    load_point_sets({write_temp("class2.csv", "0.1,0.2,0\n0.3,0.4,2\n")});
    ADD_FAILURE() << "a class of 2 read as z";
  } catch (const InvalidInput& e) {
    EXPECT_NE(
        std::string(e.what()).find("whole numbers only: a class column needs the header line x,y,class"),
        std::string::npos)
        << e.what();
  }
}

/// A NumPy .npy file's bytes as np.save writes them: version 1.0, the header dict `dict` padded, then
/// `data`.
std::string npy(const std::string& dict, const std::string& data, int version = 1) {
  std::string header = dict;
  const std::size_t fixed = version == 1 ? 10 : 12;
  while ((fixed + header.size() + 1) % 64) header += ' ';
  header += '\n';
  std::string out = std::string("\x93NUMPY", 6) + char(version) + char(0);
  out += char(header.size() & 0xff), out += char(header.size() >> 8 & 0xff);
  if (version != 1) out += std::string(2, '\0');
  return out + header + data;
}

template <class T>
std::string bytes_of(std::initializer_list<T> values) {  // little-endian, as this x86-64 machine stores them
  std::string out;
  for (T v : values) out.append(reinterpret_cast<const char*>(&v), sizeof v);
  return out;
}

/// `bytes` with each `size`-byte element's bytes reversed: little-endian values as big-endian.
std::string swapped(std::string bytes, std::size_t size) {
  for (std::size_t at = 0; at + size <= bytes.size(); at += size)
    std::reverse(bytes.begin() + std::ptrdiff_t(at), bytes.begin() + std::ptrdiff_t(at + size));
  return bytes;
}

// NumPy .npy files: float64 or float32 of either byte order, (n, 2) or (n, 3), in C or Fortran order;
// anything else, a header promising more than the file holds and a header that is no dict literal, refused
// by name.
TEST(PointFiles, NpyFilesRead) {
  const std::string c2 = "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 2), }";
  EXPECT_EQ(read_one(npy(c2, bytes_of<double>({0.25, 0.5, 0.75, 0.125})), "c.npy").coords,
            (std::vector<double>{0.25, 0.5, 0.75, 0.125}));
  const tools::PointSet f = read_one(npy("{'descr': '<f4', 'fortran_order': True, 'shape': (2, 3), }",
                                         bytes_of<float>({0.25f, 0.75f, 0.5f, 0.125f, 0, 1})),
                                     "f.npy");
  EXPECT_EQ(f.dim, 3);
  EXPECT_EQ(f.coords, (std::vector<double>{0.25, 0.5, 0, 0.75, 0.125, 1}));
  EXPECT_EQ(read_one(npy(c2, bytes_of<double>({0.25, 0.5, 0.75, 0.125}), 2), "v2.npy").size(), 2u);
  // Big-endian (np.save of a '>f8' array, as the density reader takes it): the same values.
  EXPECT_EQ(read_one(npy("{'descr': '>f8', 'fortran_order': False, 'shape': (2, 2), }",
                         swapped(bytes_of<double>({0.25, 0.5, 0.75, 0.125}), 8)),
                     "big.npy")
                .coords,
            (std::vector<double>{0.25, 0.5, 0.75, 0.125}));
  EXPECT_EQ(read_one(npy("{'descr': '>f4', 'fortran_order': False, 'shape': (1, 2), }",
                         swapped(bytes_of<float>({0.25f, 0.625f}), 4)),
                     "big4.npy")
                .coords,
            (std::vector<double>{0.25, 0.625}));
  // (sets, n, dim), as kdm sample --sets writes it: that many sets.
  std::istringstream several(npy("{'descr': '<f8', 'fortran_order': False, 'shape': (3, 1, 2), }",
                                 bytes_of<double>({0.25, 0.5, 0.75, 0.125, 0, 0.5})));
  std::vector<tools::PointSet> sets;
  std::string read_failure;
  ASSERT_TRUE(tools::read_point_sets(several, "s.npy", sets, read_failure)) << read_failure;
  ASSERT_EQ(sets.size(), 3u);
  EXPECT_EQ(sets[1].coords, (std::vector<double>{0.75, 0.125}));
  EXPECT_EQ(sets[2].coords, (std::vector<double>{0, 0.5}));
  const std::string two = bytes_of<double>({0.25, 0.5, 0.75, 0.125});
  const std::vector<std::pair<std::string, std::string>> refused = {
      {npy("{'descr': '<c16', 'fortran_order': False, 'shape': (1, 2), }", two),
       "expected float64 or float32"},
      {npy("{'descr': '<i8', 'fortran_order': False, 'shape': (2, 2), }", two), "data of type '<i8'"},
      {npy("{'descr': '<f8', 'fortran_order': False, 'shape': (4,), }", two), "shape (4): expected (n, 2)"},
      {npy("{'descr': '<f8', 'fortran_order': False, 'shape': (1, 4), }", two), "shape (1, 4)"},
      {npy("{'descr': '<f8', 'fortran_order': False, 'shape': (99999999999, 2), }", two),
       "cut short: its header promises 199999999998 values"},
      {npy("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 2), }", two.substr(0, 31)), "cut short"},
      {npy("{'descr': '<f8', 'fortran_order': False, 'shape': (0, 2), }", ""), "holds no points"},
      {npy("{'descr': '<f8', 'shape': (2, 2), }", two), "without descr, fortran_order or shape"},
      {npy("__import__('os')", two), "no dictionary"},
      {npy(c2, bytes_of<double>({0.25, std::nan(""), 0.75, 0.125})), "non-finite coordinate at [0, 1]"},
      {npy("{'descr': '<f8', 'fortran_order': True, 'shape': (2, 2), }",
           bytes_of<double>({0.25, std::nan(""), 0.75, 0.125})),
       "non-finite coordinate at [1, 0]"},
      {npy("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 1, 2), }",
           bytes_of<double>({0.25, 0.5, 0.75, std::nan("")})),
       "non-finite coordinate at [1, 0, 1]"},
      {npy("{'descr': '<f8', 'fortran_order': True, 'shape': (2, 1, 2), }", two), "save it in C order"},
      {npy("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 1, 4), }", two), "shape (2, 1, 4)"},
      {std::string("\x93NUMPY\x01\x00\xff\xff", 10), "cut short in its header"},
      {std::string("\x93NUMPY\x02\x00\xff\xff\xff\x7f", 12), "a header of 2147483647 bytes"},
      {std::string("\x93NUMPY\x07\x00", 8), "unknown format version 7"},
      {std::string("\x93NUMPX\x01\x00", 8), "not a NumPy .npy file"}};
  for (const auto& [bytes, message] : refused) {
    const std::string error = read_error(bytes, "bad.npy");
    EXPECT_NE(error.find(message), std::string::npos) << error;
    EXPECT_NE(error.find("bad.npy"), std::string::npos) << error;
  }
}

TEST(Json, WriterEscapesAndNulls) {
  JsonWriter w;
  w.begin_object()
      .key("a\"b")
      .value(std::nan(""))
      .key("v")
      .value(std::vector<double>{1.5, 2})
      .key("s")
      .value("x\ny");
  w.key("t").value(true).end_object();
  EXPECT_EQ(w.str(), "{\n  \"a\\\"b\":null,\n  \"v\":[1.5,2],\n  \"s\":\"x\\ny\",\n  \"t\":true\n}\n");
  EXPECT_EQ(json_quote(std::string("\x01", 1)), "\"\\u0001\"");
  // UTF-8 passes through; a byte of no character (a Latin-1 file name, a cut sequence) is written as \ufffd.
  EXPECT_EQ(json_quote("lat\xC3\xA9 \xE2\x82\xAC"), "\"lat\xC3\xA9 \xE2\x82\xAC\"");
  EXPECT_EQ(json_quote("lat\xE9.csv"), "\"lat\\ufffd.csv\"");
  EXPECT_EQ(json_quote("\xE2\x82"), "\"\\ufffd\\ufffd\"");
  EXPECT_EQ(json_quote("\xC0\xAF\xED\xA0\x80"), "\"\\ufffd\\ufffd\\ufffd\\ufffd\\ufffd\"");
}

TEST(Report, AnalyzeAggregatesSets) {
  // Within 10% of each other in count: the spectrum pools sets of about one size.
  std::vector<tools::PointSet> sets = {testing::uniform_set(1000, 21), testing::uniform_set(1080, 22)};
  AnalysisOptions o;
  o.density = [](double, double) { return 1.0; };
  o.tile_size = 0.25;
  o.fmax = 1.5;
  const AnalysisReport r = analyze(sets, o);
  EXPECT_EQ(r.sets, 2u);
  EXPECT_EQ(r.points_min, 1000u);
  EXPECT_EQ(r.points_max, 1080u);
  EXPECT_EQ(r.nn.count, 2080u);
  ASSERT_EQ(r.dmin_per_set.size(), 2u);
  EXPECT_DOUBLE_EQ(r.nn.dmin, std::min(r.dmin_per_set[0], r.dmin_per_set[1]));
  EXPECT_TRUE(r.has_spectrum && r.has_density && r.has_tiling);
  EXPECT_EQ(r.seams.seam.count + r.seams.interior.count, 2080u);
  EXPECT_GT(r.density.windows, 50u);
  const std::string json = metrics_json(r, {"a.txt"});
  for (const char* key :
       {"\"low_p\"", "\"nu_eff\"", "\"davg\"", "\"rms_z\"", "\"periodicity_ratio\"", "\"g\""})
    EXPECT_NE(json.find(key), std::string::npos) << key;
  EXPECT_NE(format_summary(r).find("δavg"), std::string::npos);
  EXPECT_THROW(analyze({}, o), InvalidInput);
  // Sets 20% apart in count: pooled, but with no spectrum (nor what reads it), and the summary says why.
  const AnalysisReport apart = analyze({testing::uniform_set(1000, 21), testing::uniform_set(1200, 22)}, o);
  EXPECT_FALSE(apart.has_spectrum);
  EXPECT_NE(apart.spectrum_skipped.find("1000 to 1200 points"), std::string::npos) << apart.spectrum_skipped;
  EXPECT_NE(format_summary(apart).find("spectrum           skipped"), std::string::npos);
  EXPECT_NE(metrics_json(apart, {"a", "b"}).find("\"spectrum_skipped\""), std::string::npos);
  EXPECT_TRUE(apart.has_empty_circles);
  o.tile_size = 0.3;
  EXPECT_THROW(analyze(sets, o), InvalidInput);
  // A box set too small to judge any circle two spacings inside says so, where zeros would read as a set
  // without holes.
  AnalysisOptions box;
  box.torus = false;
  const AnalysisReport few = analyze({testing::uniform_set(12, 23)}, box);
  EXPECT_FALSE(few.has_empty_circles);
  EXPECT_NE(few.empty_circles_skipped.find("no circle was judged"), std::string::npos);
  EXPECT_NE(metrics_json(few, {"a"}).find("\"empty_circles_skipped\""), std::string::npos);
  EXPECT_EQ(metrics_json(few, {"a"}).find("\"empty_circles\":"), std::string::npos);
  // Duplicates are counted and said; a periodogram that is constant on its rings (two points on one
  // place) has no anisotropy, where rounding read -153 dB.
  tools::PointSet twins;
  twins.coords = {0.3, 0.3, 0.3, 0.3};
  const AnalysisReport same = analyze({twins}, box);
  EXPECT_EQ(same.coincident, 2u);
  EXPECT_NE(format_summary(same).find("2 points lie on another"), std::string::npos);
  EXPECT_NE(metrics_json(same, {"a"}).find("\"coincident_points\":2"), std::string::npos);
  ASSERT_TRUE(same.has_spectrum);
  EXPECT_TRUE(std::isnan(same.spectrum_stats.anisotropy_db));
  o.tile_size = 0.25;
  EXPECT_EQ(analyze(sets, o).coincident, 0u);
}

// What cannot be measured reads n/a, not a figure: g(r) of two points far apart, the anisotropy below
// f = 0.5; windows that expect more points than a set has are warned of; the distances used are named,
// with the option for the other.
TEST(Report, TheSummarySaysWhatCannotBeMeasured) {
  tools::PointSet two;
  two.coords = {0.1, 0.1, 0.6, 0.6};
  AnalysisOptions o;
  std::string s = format_summary(analyze({two}, o));
  EXPECT_NE(s.find("g peak n/a (no pair within r"), std::string::npos) << s;
  EXPECT_NE(s.find("torus distances (the set wraps around; --box for a bounded set)"), std::string::npos)
      << s;
  o.torus = false;
  EXPECT_NE(format_summary(analyze({two}, o)).find("box distances (a bounded set; --torus"),
            std::string::npos);
  o.torus = true;
  o.fmax = 0.5;
  const tools::PointSet set = testing::uniform_set(4096, 5);
  s = format_summary(analyze({set}, o));
  EXPECT_NE(s.find("anisotropy n/a"), std::string::npos) << s;
  EXPECT_EQ(s.find("nan"), std::string::npos) << s;
  EXPECT_EQ(s.find("warning: no window"), std::string::npos) << s;
  o.density = [](double, double) { return 1.0; };
  o.min_expected = 5000;
  const AnalysisReport r = analyze({set}, o);
  EXPECT_EQ(r.density.windows, 1u);
  s = format_summary(r);
  EXPECT_NE(s.find("warning: no window expects 5000 points (--min-expected; a set has 4096)"),
            std::string::npos)
      << s;
  EXPECT_NE(metrics_json(r, {"a"}).find("\"min_expected\":5000"), std::string::npos);
  o.min_expected = 20;
  EXPECT_EQ(format_summary(analyze({set}, o)).find("warning: no window"), std::string::npos);
}

// The spectrum of a set that is not uniform measures its density, and the summary says so beside it: for
// a target density that varies, or (with none given) windows whose counts vary far beyond Poisson. Its
// numbers stay as they are; uniform sets, white noise too, get no note.
TEST(Report, TheSpectrumOfANonUniformSetSaysWhatItMeasures) {
  AnalysisOptions o;
  o.fmax = 1;
  const std::string note = "note: not a uniform set (";
  for (const tools::PointSet& uniform : {testing::jittered_grid(64, 3), testing::uniform_set(4096, 4)}) {
    const AnalysisReport r = analyze({uniform}, o);
    EXPECT_TRUE(r.spectrum_nonuniform.empty()) << r.spectrum_nonuniform;
    EXPECT_EQ(format_summary(r).find(note), std::string::npos);
    EXPECT_EQ(metrics_json(r, {"a"}).find("\"nonuniform\""), std::string::npos);
  }
  tools::PointSet ramp = testing::uniform_set(4096, 5);  // density ∝ 1/√x
  for (std::size_t p = 0; p < ramp.size(); ++p) ramp.coords[2 * p] *= ramp.coords[2 * p];
  const AnalysisReport plain = analyze({ramp}, o);
  EXPECT_NE(plain.spectrum_nonuniform.find("window counts vary far beyond Poisson"), std::string::npos)
      << plain.spectrum_nonuniform;
  const std::string summary = format_summary(plain);
  const std::size_t next = summary.find('\n', summary.find("spectrum (f")) + 1;
  EXPECT_EQ(summary.find(note), summary.find_first_not_of(' ', next)) << summary;  // the spectrum's next line
  EXPECT_NE(metrics_json(plain, {"a"}).find("\"nonuniform\":\"window counts"), std::string::npos);
  o.density = [](double x, double) { return 1 / std::sqrt(x + 1e-9); };
  const AnalysisReport target = analyze({ramp}, o);
  EXPECT_EQ(target.spectrum_nonuniform, "the target density is not constant");
  EXPECT_EQ(target.spectrum_stats.low_p, plain.spectrum_stats.low_p);
  EXPECT_EQ(target.spectrum_stats.peak, plain.spectrum_stats.peak);
}

}  // namespace
}  // namespace kdm::analysis
