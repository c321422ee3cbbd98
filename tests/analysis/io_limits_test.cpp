// Untrusted input files (tools/common): the image pixel limit, read from the header before any pixel is
// allocated; the hostile images the fuzzer found (tests/fuzz/crashes/image) refused or read cleanly; the
// memory and path loaders agreeing on the fuzz seeds; NUL bytes in point files; a JPEG's EXIF orientation,
// applied, and damaged EXIF ignored.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <csignal>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "atomic_file.h"
#include "image_io.h"
#include "point_io.h"

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define KDM_SANITIZED 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define KDM_SANITIZED 1
#endif

namespace {

using kdm::tools::GreyImage;

void put32(std::vector<std::uint8_t>& v, std::uint32_t x) {
  for (int s = 24; s >= 0; s -= 8) v.push_back(static_cast<std::uint8_t>(x >> s));
}

std::uint32_t crc32(const std::uint8_t* p, std::size_t n) {
  std::uint32_t crc = ~0u;
  for (std::size_t i = 0; i < n; ++i) {
    crc ^= p[i];
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

void chunk(std::vector<std::uint8_t>& png, const char* type, const std::vector<std::uint8_t>& data) {
  put32(png, static_cast<std::uint32_t>(data.size()));
  const std::size_t start = png.size();
  png.insert(png.end(), type, type + 4);
  png.insert(png.end(), data.begin(), data.end());
  put32(png, crc32(&png[start], png.size() - start));
}

// An 8-bit greyscale PNG whose header says w×h; its data is one zero row in a zlib stored block, enough
// for the header to be well formed (a decoder would find the pixels short only after allocating them).
std::vector<std::uint8_t> grey_png_header(std::uint32_t w, std::uint32_t h) {
  std::vector<std::uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'}, ihdr, z = {0x78, 0x01};
  put32(ihdr, w);
  put32(ihdr, h);
  ihdr.insert(ihdr.end(), {8, 0, 0, 0, 0});
  const std::size_t row = std::min<std::size_t>(w + 1, 65535);
  z.insert(z.end(), {1, static_cast<std::uint8_t>(row), static_cast<std::uint8_t>(row >> 8),
                     static_cast<std::uint8_t>(~row), static_cast<std::uint8_t>(~row >> 8)});
  z.insert(z.end(), row, 0);
  put32(z, static_cast<std::uint32_t>(row % 65521) << 16 | 1);  // Adler-32 of `row` zeros
  chunk(png, "IHDR", ihdr);
  chunk(png, "IDAT", z);
  chunk(png, "IEND", {});
  return png;
}

std::string write_temp(const std::string& name, const std::vector<std::uint8_t>& bytes) {
  const std::string path = ::testing::TempDir() + "kdm_io_limits_" + name;
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  return path;
}

std::vector<std::uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

TEST(ImageLimit, HugeHeaderIsRefusedWithAClearError) {
  const std::vector<std::uint8_t> png = grey_png_header(20000, 20000);
  GreyImage image;
  image.width = 7;  // untouched on failure
  std::string error;
  EXPECT_FALSE(kdm::tools::load_grey_image_memory(png.data(), png.size(), image, error, "huge.png"));
  EXPECT_TRUE(contains(error, "'huge.png'")) << error;
  EXPECT_TRUE(contains(error, "20000x20000")) << error;
  EXPECT_TRUE(contains(error, "limit of 67108864 pixels (8192x8192)")) << error;
  EXPECT_EQ(image.width, 7);
  EXPECT_TRUE(image.pixels.empty());
  const std::string path = write_temp("huge.png", png);
  error.clear();
  EXPECT_FALSE(kdm::tools::load_grey_image(path, image, error));
  EXPECT_TRUE(contains(error, path) && contains(error, "20000x20000")) << error;
}

// The header alone decides, before anything of the image's size is allocated: in a child process whose
// address space has 256 MiB to spare, the 20000 × 20000 header is refused by the limit; with the limit
// lifted, the same bytes make stb try to allocate its 400 MB of pixels, and fail for want of memory.
TEST(ImageLimit, HugeHeaderAllocatesNothingOfItsSize) {
#ifdef KDM_SANITIZED
  GTEST_SKIP() << "sanitizers reserve terabytes of address space: RLIMIT_AS cannot be used";
#else
  const std::vector<std::uint8_t> png = grey_png_header(20000, 20000);
  auto run_limited = [&png](std::uint64_t max_pixels) {
    const pid_t child = fork();
    if (child == 0) {
      long pages = 0;
      std::ifstream("/proc/self/statm") >> pages;
      const rlim_t spare = rlim_t(256) << 20, now = static_cast<rlim_t>(pages) * sysconf(_SC_PAGESIZE);
      const rlimit limit{now + spare, now + spare};
      if (setrlimit(RLIMIT_AS, &limit) != 0) _exit(3);
      GreyImage image;
      std::string error;
      const bool loaded =
          kdm::tools::load_grey_image_memory(png.data(), png.size(), image, error, "huge.png", max_pixels);
      _exit(loaded ? 2 : contains(error, "limit of") ? 0 : 1);  // 0 refused by the limit, 1 otherwise
    }
    int status = 0;
    waitpid(child, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  EXPECT_EQ(run_limited(kdm::tools::kMaxImagePixels), 0);
  EXPECT_EQ(run_limited(std::numeric_limits<std::uint64_t>::max()), 1);  // the control: stb ran out
#endif
}

TEST(ImageLimit, LimitIsWidthTimesHeight) {
  GreyImage image;
  std::string error;
  const std::vector<std::uint8_t> over = grey_png_header(8193, 8192);
  EXPECT_FALSE(kdm::tools::load_grey_image_memory(over.data(), over.size(), image, error, "over.png"));
  EXPECT_TRUE(contains(error, "8193x8192")) << error;
  // A lower limit, as the fuzzer sets: 5 × 5 needs 25 pixels.
  const std::vector<std::uint8_t> small = grey_png_header(5, 5);
  EXPECT_FALSE(kdm::tools::load_grey_image_memory(small.data(), small.size(), image, error, "s.png", 24));
  EXPECT_TRUE(contains(error, "5x5 pixels, more than the limit of 24 pixels")) << error;
  // At the limit it is read (its data is short: one row of the five, so stb refuses it after the header).
  error.clear();
  EXPECT_FALSE(kdm::tools::load_grey_image_memory(small.data(), small.size(), image, error, "s.png", 25));
  EXPECT_FALSE(contains(error, "limit")) << error;
  const std::vector<std::uint8_t> one = grey_png_header(1, 1);
  EXPECT_TRUE(kdm::tools::load_grey_image_memory(one.data(), one.size(), image, error, "one.png", 1))
      << error;
  EXPECT_EQ(image.width * image.height, 1);
}

// The inputs that made stb_image fault under the image fuzzer (tests/fuzz/crashes/README.md): refused
// before stb reads them, or, for a JPEG without Huffman tables, read from zeroed memory. No crash, no
// sanitizer report, an error naming the file.
TEST(ImageLimit, FuzzerFoundImagesAreRefusedCleanly) {
  const std::string dir = std::string(KDM_SOURCE_DIR) + "/tests/fuzz/crashes/image/";
  const struct {
    const char* file;
    const char* problem;
  } cases[] = {{"jpeg_huffman_overflow.jpg", "Huffman table of more than 256 codes"},
               {"jpeg_no_huffman_tables.jpg", ""},
               {"png_chunk_past_end.png", "ends inside a chunk"},
               {"hdr_run_of_length_zero.hdr", "a run of length 0"},
               {"pnm_header_overflow.pgm", "header number too large"},
               {"pnm_pixels_cut_short.pgm", "pixels cut short"},
               {"bmp_pixels_inside_header.bmp", "its pixels start inside its header"}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.file);
    const std::vector<std::uint8_t> bytes = read_bytes(dir + c.file);
    ASSERT_FALSE(bytes.empty());
    GreyImage image;
    std::string error;
    EXPECT_FALSE(kdm::tools::load_grey_image(dir + c.file, image, error));
    EXPECT_TRUE(contains(error, c.file) && contains(error, c.problem)) << error;
    error.clear();
    EXPECT_FALSE(kdm::tools::load_grey_image_memory(bytes.data(), bytes.size(), image, error, c.file));
    EXPECT_TRUE(contains(error, c.file) && contains(error, c.problem)) << error;
  }
}

// A PNG cut short is said so, wherever the cut falls: inside a chunk's header (stb would name an unknown
// chunk type), inside its CRC, or before IEND (a file missing only IEND's CRC is whole: stb reads no
// further).
TEST(ImageLimit, APngCutShortIsSaidSo) {
  const std::vector<std::uint8_t> whole =
      read_bytes(std::string(KDM_SOURCE_DIR) + "/tests/fuzz/corpus/image/grey8.png");
  ASSERT_GT(whole.size(), 60u);
  GreyImage image;
  std::string error;
  ASSERT_TRUE(kdm::tools::load_grey_image_memory(whole.data(), whole.size(), image, error, "whole")) << error;
  for (const std::size_t cut : {std::size_t(40), std::size_t(31), whole.size() - 12, whole.size() - 6}) {
    SCOPED_TRACE(cut);
    error.clear();
    EXPECT_FALSE(kdm::tools::load_grey_image_memory(whole.data(), cut, image, error, "cut.png"));
    EXPECT_TRUE(contains(error, "cut.png") && contains(error, "cut short")) << error;
  }
}

// A PNG whose compressed pixels do not decode is named a corrupt PNG (stb's reason was another decoder's:
// "Corrupt JPEG").
TEST(ImageLimit, APngWhosePixelsDoNotDecodeIsSaidSo) {
  std::vector<std::uint8_t> png =
      read_bytes(std::string(KDM_SOURCE_DIR) + "/tests/fuzz/corpus/image/grey8.png");
  const std::string text(png.begin(), png.end());
  const std::size_t idat = text.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  png[idat + 4] = 0xff, png[idat + 5] = 0xff;  // no zlib header
  GreyImage image;
  std::string error;
  EXPECT_FALSE(kdm::tools::load_grey_image_memory(png.data(), png.size(), image, error, "bad.png"));
  EXPECT_TRUE(contains(error, "'bad.png': corrupt PNG (its compressed pixels do not decode)")) << error;
}

// Every image seed of the fuzzer (PNG 1/8/16-bit grey, grey+alpha, RGB, RGBA, palette and tRNS, Adam7;
// JPEG, BMP, TGA, PGM, PPM) loads, the same from a path as from memory, with values in [0, 1].
TEST(ImageLimit, PathAndMemoryLoadersAgreeOnTheSeeds) {
  const std::string dir = std::string(KDM_SOURCE_DIR) + "/tests/fuzz/corpus/image/";
  for (const char* file : {"grey1.png", "grey8.png", "grey16.png", "grey_alpha8.png", "rgb8.png",
                           "rgba16.png", "palette_trns.png", "grey8_trns.png", "interlaced.png", "tiny.jpg",
                           "rgb.bmp", "grey.tga", "grey.pgm", "deep.pgm", "rgb.ppm"}) {
    SCOPED_TRACE(file);
    GreyImage from_path, from_memory;
    std::string error;
    ASSERT_TRUE(kdm::tools::load_grey_image(dir + file, from_path, error)) << error;
    const std::vector<std::uint8_t> bytes = read_bytes(dir + file);
    ASSERT_TRUE(kdm::tools::load_grey_image_memory(bytes.data(), bytes.size(), from_memory, error)) << error;
    EXPECT_EQ(from_path.width, from_memory.width);
    EXPECT_EQ(from_path.height, from_memory.height);
    EXPECT_EQ(from_path.pixels, from_memory.pixels);
    ASSERT_EQ(from_path.pixels.size(), std::size_t(from_path.width) * from_path.height);
    for (float v : from_path.pixels) EXPECT_TRUE(v >= 0 && v <= 1) << v;
  }
  GreyImage image;
  std::string error;
  const std::vector<std::uint8_t> deep = read_bytes(dir + "deep.pgm");  // 16-bit: 1000 and 60000 of 65535
  ASSERT_TRUE(kdm::tools::load_grey_image_memory(deep.data(), deep.size(), image, error)) << error;
  EXPECT_FLOAT_EQ(image.at(0, 0), 1000.0f / 65535.0f);
  EXPECT_FALSE(kdm::tools::load_grey_image_memory(deep.data(), 0, image, error, "empty.png"));
  EXPECT_TRUE(contains(error, "'empty.png'")) << error;
}

// A PGM's samples are fractions of its maxval, whatever it is (stb reads them as they are); maxval 0 is
// refused, not read as black.
TEST(ImageLimit, PgmSamplesAreFractionsOfTheirMaxval) {
  GreyImage image;
  std::string error;
  const std::string eight = std::string("P5 2 1 100\n") + char(100) + char(25);
  ASSERT_TRUE(kdm::tools::load_grey_image_memory(eight.data(), eight.size(), image, error)) << error;
  EXPECT_FLOAT_EQ(image.at(0, 0), 1.0f);
  EXPECT_FLOAT_EQ(image.at(1, 0), 0.25f);
  const std::string sixteen = std::string("P5 1 1 1000\n") + char(1) + char(244);  // 500 of 1000
  ASSERT_TRUE(kdm::tools::load_grey_image_memory(sixteen.data(), sixteen.size(), image, error)) << error;
  EXPECT_FLOAT_EQ(image.at(0, 0), 0.5f);
  const std::string zero = std::string("P5 2 1 0\n") + char(0) + char(0);
  EXPECT_FALSE(kdm::tools::load_grey_image_memory(zero.data(), zero.size(), image, error));
  EXPECT_TRUE(contains(error, "maxval of 0")) << error;
  const std::string above = std::string("P5 2 1 100\n") + char(100) + char(101);
  EXPECT_FALSE(kdm::tools::load_grey_image_memory(above.data(), above.size(), image, error));
  EXPECT_TRUE(contains(error, "a sample above its maxval of 100")) << error;
}

// A NUL byte inside a line is malformed, not the line's end (the reader used to stop there silently).
TEST(PointFileInput, NulBytesAreMalformed) {
  std::vector<kdm::tools::PointSet> sets;
  std::string error;
  const char text[] = "0.1 0.2\n0.3 0.4\0 0.5\n";
  std::istringstream nul(std::string(text, sizeof text - 1));
  EXPECT_FALSE(kdm::tools::read_point_sets(nul, "nul.txt", sets, error));
  EXPECT_TRUE(contains(error, "nul.txt:2: malformed")) << error;
  EXPECT_TRUE(contains(error, "'0.3 0.4\\x00 0.5'")) << error;  // quoted printably
  std::istringstream good("x,y\n0.1,0.2\n#\n0.3 0.4\n");
  ASSERT_TRUE(kdm::tools::read_point_sets(good, "good.csv", sets, error)) << error;
  EXPECT_EQ(sets.size(), 2u);
}

// A device has no size to check before reading: /dev/zero, with no image header in its first bytes, is
// refused there (it was read to 2 GiB, 12 s, before its size was), and a pipe holding a PNG still reads.
TEST(ImageInput, ADeviceWithNoImageHeaderIsRefusedAtOnce) {
  kdm::tools::GreyImage image;
  std::string error;
  if (!std::filesystem::exists("/dev/zero")) GTEST_SKIP() << "no /dev/zero";
  EXPECT_FALSE(kdm::tools::load_grey_image("/dev/zero", image, error));
  EXPECT_TRUE(contains(error, "'/dev/zero': not a file, and its first bytes are no image header")) << error;
  const std::string fifo = ::testing::TempDir() + "kdm_image_fifo";
  std::filesystem::remove(fifo);
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::thread writer([&] {
    const std::string png = std::string(KDM_SOURCE_DIR) + "/examples/sphere.png";
    std::ifstream in(png, std::ios::binary);
    std::ofstream(fifo, std::ios::binary) << in.rdbuf();
  });
  const bool read = kdm::tools::load_grey_image(fifo, image, error);
  writer.join();
  EXPECT_TRUE(read) << error;
  EXPECT_GT(image.width, 100);
  std::filesystem::remove(fifo);
}

// A file that never ends a line (a binary file, /dev/zero) is refused at its first long line, not read
// whole; a quoted excerpt of a malformed line is short and printable; a directory is named as one.
TEST(PointFileInput, EndlessLinesBinaryBytesAndDirectoriesAreRefused) {
  std::vector<kdm::tools::PointSet> sets;
  std::string error;
  std::istringstream endless("0.1 0.2\n" + std::string(5000, '\0'));
  EXPECT_FALSE(kdm::tools::read_point_sets(endless, "zero.txt", sets, error));
  EXPECT_TRUE(contains(error, "zero.txt:2: a line longer than 4096 characters")) << error;
  std::istringstream longest("0.1 " + std::string(4092, '1') + "\n");  // 4096 characters: still read
  EXPECT_FALSE(kdm::tools::read_point_sets(longest, "long.txt", sets, error));
  EXPECT_TRUE(contains(error, "non-finite")) << error;  // read as a number too large for a double
  std::istringstream binary(
      "\x7f"
      "ELF\x02\x01\x01" +
      std::string(100, 'a') + "\n");
  EXPECT_FALSE(kdm::tools::read_point_sets(binary, "kdm", sets, error));
  EXPECT_TRUE(contains(error, "'\\x7fELF\\x02\\x01\\x01aaa")) << error;
  EXPECT_TRUE(contains(error, "aaa...'")) << error;
  EXPECT_LT(error.size(), 100u) << error;
  EXPECT_FALSE(kdm::tools::read_point_sets(::testing::TempDir(), sets, error));
  EXPECT_TRUE(contains(error, "is a directory")) << error;
}

// tests/data/halves.jpg (16 × 8 grey, its left half black and right half white; written by stb_image_write's
// stbi_write_jpg at quality 95) with an EXIF segment (big-endian TIFF, one entry: Orientation =
// `orientation`) after its SOI; none for 0. `cut` drops that many bytes off the segment's end, its length
// with them (a segment whose entry is cut short).
std::vector<std::uint8_t> halves_jpeg(int orientation, std::size_t cut = 0) {
  std::ifstream file(KDM_TEST_DATA_DIR "/halves.jpg", std::ios::binary);
  std::vector<std::uint8_t> jpeg((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  EXPECT_GT(jpeg.size(), 100u);
  if (orientation == 0) return jpeg;
  std::vector<std::uint8_t> exif = {0xFF, 0xE1, 0, 34, 'E', 'x', 'i', 'f', 0, 0,
                                    'M',  'M',  0, 42, 0,   0,   0,   8,   0, 1,
                                    0x01, 0x12, 0, 3,  0,   0,   0,   1,   0, std::uint8_t(orientation),
                                    0,    0,    0, 0,  0,   0};
  exif.resize(exif.size() - cut);
  exif[3] = std::uint8_t(exif.size() - 2);
  jpeg.insert(jpeg.begin() + 2, exif.begin(), exif.end());
  return jpeg;
}

// Mean luminance of the top half of rows and of the left half of columns.
std::pair<double, double> top_and_left(const GreyImage& image) {
  double top = 0, left = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      if (y < image.height / 2) top += image.at(x, y);
      if (x < image.width / 2) left += image.at(x, y);
    }
  const double half = image.width * image.height / 2.0;
  return {top / half, left / half};
}

TEST(ImageLimits, AJpegIsTurnedAsItsExifOrientationSays) {
  struct Seen {
    int orientation, width, height;
    double top, left;  // 0 black, 1 white, 0.5 half of each
  };
  // 1: as stored; 3: turned 180°; 6: 90° clockwise (the left half on top); 8: 90° counter-clockwise.
  const Seen cases[] = {{0, 16, 8, 0.5, 0}, {1, 16, 8, 0.5, 0}, {3, 16, 8, 0.5, 1}, {6, 8, 16, 0, 0.5},
                        {8, 8, 16, 1, 0.5}, {2, 16, 8, 0.5, 1}, {5, 8, 16, 0, 0.5}};
  for (const Seen& c : cases) {
    SCOPED_TRACE(c.orientation);
    const std::vector<std::uint8_t> jpeg = halves_jpeg(c.orientation);
    GreyImage image;
    std::string error;
    ASSERT_TRUE(kdm::tools::load_grey_image_memory(jpeg.data(), jpeg.size(), image, error)) << error;
    EXPECT_EQ(image.width, c.width);
    EXPECT_EQ(image.height, c.height);
    const auto [top, left] = top_and_left(image);
    EXPECT_NEAR(top, c.top, 0.05);  // JPEG rounding near the halves' edge: a few per cent
    EXPECT_NEAR(left, c.left, 0.05);
  }
  // A segment cut short at any byte: its last 4 (the next directory's offset) leave the entry whole and
  // turned; an entry cut short, or an orientation that is none (9), reads as stored.
  for (std::size_t cut = 1; cut <= 16; ++cut) {
    for (const int orientation : {6, 9}) {
      const std::vector<std::uint8_t> jpeg = halves_jpeg(orientation, cut);
      GreyImage image;
      std::string error;
      ASSERT_TRUE(kdm::tools::load_grey_image_memory(jpeg.data(), jpeg.size(), image, error)) << error;
      EXPECT_EQ(image.width, orientation == 6 && cut <= 4 ? 8 : 16) << cut;
    }
  }
}

}  // namespace

// A command interrupted while it writes an output leaves no OUT.tmp~ behind: the signal removes the file
// being written, then ends the process as it would have. In a child, since the signal ends it.
TEST(AtomicWrite, ASignalRemovesTheFileBeingWrittenAndStillEndsTheProcess) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "kdm_atomic_write_test";
  std::filesystem::create_directories(dir);
  const std::string temp = (dir / "out.csv.tmp~").string();
  std::ofstream(temp) << "half a file";
  std::fflush(nullptr);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    kdm::tools::remove_temporary_files_on_signals();
    kdm::tools::detail::mark_temporary_file(temp.c_str());
    std::raise(SIGINT);
    _exit(0);  // not reached: the signal ends the child
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGINT) << status;
  EXPECT_FALSE(std::filesystem::exists(temp));
  // A whole write unmarks its file: a later signal removes nothing it should not.
  const std::string kept = (dir / "kept.csv").string();
  const pid_t second = fork();
  ASSERT_GE(second, 0);
  if (second == 0) {
    kdm::tools::remove_temporary_files_on_signals();
    std::string e;
    if (!kdm::tools::write_text_file_atomic(kept, "x,y\n", e)) _exit(1);
    std::raise(SIGTERM);
    _exit(0);
  }
  ASSERT_EQ(waitpid(second, &status, 0), second);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << status;
  EXPECT_TRUE(std::filesystem::exists(kept));
  // A signal the process was started ignoring (nohup) stays ignored.
  const pid_t third = fork();
  ASSERT_GE(third, 0);
  if (third == 0) {
    std::signal(SIGHUP, SIG_IGN);
    kdm::tools::remove_temporary_files_on_signals();
    std::raise(SIGHUP);
    _exit(7);
  }
  ASSERT_EQ(waitpid(third, &status, 0), third);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 7) << status;
  std::filesystem::remove_all(dir);
}
