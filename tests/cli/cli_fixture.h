// The kdm command line driven as a process: the fixture of the CLI tests (a scratch directory per test,
// `kdm ARGS` with its exit status and output, the one-line error contract) and a PNG writer for images
// stb_image_write cannot make (16-bit, cut or damaged files).
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "point_io.h"

namespace kdm_cli_test {

namespace fs = std::filesystem;

struct Outcome {
  int status = -1;  // exit status, or -1 if the process did not exit normally (a crash)
  std::string out, err;
};

inline std::string slurp(const std::string& path) {
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

  // Asserts that `kdm ARGS` succeeds and that its standard error mentions `text` (a warning) or, with
  // `said` false, does not. Returns the outcome for further checks.
  Outcome expect_success_saying(const std::string& args, const std::string& text, bool said = true) const {
    const Outcome r = kdm(args);
    EXPECT_EQ(r.status, 0) << "kdm " << args << "\nstderr: " << r.err;
    EXPECT_EQ(r.err.find(text) != std::string::npos, said)
        << "kdm " << args << (said ? "\nshould say: " : "\nshould not say: ") << text
        << "\nstderr: " << r.err;
    return r;
  }

  fs::path dir_;
};

// Data lines of a query's .csv (its header checked and dropped), sorted.
inline std::vector<std::string> sorted_rows(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "x,y,tile_x,tile_y,rank,level,depth");
  std::vector<std::string> rows;
  while (std::getline(in, line)) rows.push_back(line);
  std::sort(rows.begin(), rows.end());
  return rows;
}

// ---- A minimal PNG encoder (stb_image_write cannot write 16-bit or broken files): zlib stored blocks.
inline std::uint32_t crc32(const std::uint8_t* p, std::size_t n, std::uint32_t crc = 0) {
  crc = ~crc;
  for (std::size_t i = 0; i < n; ++i) {
    crc ^= p[i];
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

inline void put32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<std::uint8_t>(v >> s));
}

inline void chunk(std::vector<std::uint8_t>& png, const char type[5], const std::vector<std::uint8_t>& data) {
  put32(png, static_cast<std::uint32_t>(data.size()));
  const std::size_t start = png.size();
  png.insert(png.end(), type, type + 4);
  png.insert(png.end(), data.begin(), data.end());
  put32(png, crc32(&png[start], png.size() - start));
}

// `raw` as a zlib stream of stored (uncompressed) blocks, as a PNG's IDAT holds it.
inline std::vector<std::uint8_t> zlib_stored(const std::vector<std::uint8_t>& raw) {
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
  return z;
}

// A greyscale PNG of `depth` bits (8 or 16), with alpha when `channels` is 2 (grey, alpha per pixel);
// `samples` row-major, top row first.
inline std::vector<std::uint8_t> grey_png(std::uint32_t w, std::uint32_t h, int depth,
                                          const std::vector<std::uint16_t>& samples, int channels = 1) {
  std::vector<std::uint8_t> raw;  // filter byte 0 per row, then big-endian samples
  for (std::uint32_t y = 0; y < h; ++y) {
    raw.push_back(0);
    for (std::uint32_t x = 0; x < w * channels; ++x) {
      const std::uint16_t v = samples[y * w * channels + x];
      if (depth == 16) raw.push_back(static_cast<std::uint8_t>(v >> 8));
      raw.push_back(static_cast<std::uint8_t>(v));
    }
  }
  const std::vector<std::uint8_t> z = zlib_stored(raw);
  std::vector<std::uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  std::vector<std::uint8_t> ihdr;
  put32(ihdr, w);
  put32(ihdr, h);
  ihdr.insert(ihdr.end(), {static_cast<std::uint8_t>(depth), static_cast<std::uint8_t>(channels == 2 ? 4 : 0),
                           0, 0, 0});  // greyscale (with alpha), no interlace
  chunk(png, "IHDR", ihdr);
  chunk(png, "IDAT", z);
  chunk(png, "IEND", {});
  return png;
}

inline void write_bytes(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream f(path, std::ios::binary);
  f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(f.good()) << path;
}

// A Radiance (.hdr) image of flat RGBE scanlines: each value as an 8-bit mantissa and a shared exponent.
inline std::vector<std::uint8_t> radiance_hdr(int w, int h, const std::vector<float>& grey) {
  std::string out =
      "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " + std::to_string(h) + " +X " + std::to_string(w) + "\n";
  for (const float v : grey) {
    int e = 0;
    const double m = std::frexp(v, &e);
    const auto mantissa = static_cast<char>(static_cast<int>(m * 256));
    out += std::string(3, mantissa) + static_cast<char>(e + 128);
  }
  return {out.begin(), out.end()};
}

// A 64×64 8-bit horizontal ramp: a valid image to cut and damage.
inline std::vector<std::uint8_t> ramp_png() {
  std::vector<std::uint16_t> v(64 * 64);
  for (int i = 0; i < 64 * 64; ++i) v[i] = static_cast<std::uint16_t>(4 * (i % 64));
  return grey_png(64, 64, 8, v);
}

/// `values` (depth × height × width, in numpy's C order) as np.save writes a 3-D array of `descr` ('<f8',
/// '<f4', big-endian '>f8' or '>f4', or '|u1'); `shape` overrides the header's shape.
inline std::string npy_volume(const std::vector<double>& values, int depth, int height, int width,
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

/// The first point set of `file` (empty, with a test failure, if it does not read).
inline kdm::tools::PointSet first_set(const std::string& file) {
  std::vector<kdm::tools::PointSet> sets;
  std::string error;
  EXPECT_TRUE(kdm::tools::read_point_sets(file, sets, error) && !sets.empty()) << file << ": " << error;
  return sets.empty() ? kdm::tools::PointSet{} : sets[0];
}

}  // namespace kdm_cli_test
