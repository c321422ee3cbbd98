// The tile-set file format on untrusted input (meshoptimizer style: cut at every length, flip bits,
// craft hostile counts behind valid checksums) and its round trip.
#include <gtest/gtest.h>
#define ZSTD_STATIC_LINKING_ONLY  // ZSTD_getFrameHeader: the window a bomb's frame asks for
#include <zstd.h>

#include <algorithm>
#include <cereal/archives/portable_binary.hpp>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <memory>
#include <random>
#include <sstream>
#include <tuple>

#include "allocation_counter.h"
#include "crc32.h"
#include "kdm/runtime/kdm_runtime.h"
#include "kdm/runtime/query.h"
#include "kdm/runtime/tileset.h"
#include "query_tables.h"

namespace kdm {
namespace {

// A valid random set; with `glide`, a glide track too (the optional arrays since format 3, filled).
TilesetData make_tileset(std::uint32_t colours = 2, std::uint32_t levels = 3, std::uint32_t seed = 1,
                         bool glide = true) {
  std::mt19937 rng(seed);
  TilesetData set;
  set.colours = colours;
  set.levels = levels;
  set.recipe = "seed 1\ncolours 2\nlevels 3\n";
  set.generator_version = "test";
  set.tiles.resize(std::size_t(colours) * colours * colours * colours);
  for (std::uint32_t k = 0; k < levels; ++k) set.level_nominal.push_back(12u << (2 * k));
  for (Tile& tile : set.tiles) {
    std::uint32_t count = 0;
    for (std::uint32_t k = 0; k < levels; ++k) {
      const std::uint32_t added = 4 + rng() % 20;
      std::vector<std::uint16_t> keys(added);
      for (auto& key : keys) key = static_cast<std::uint16_t>(rng());
      std::sort(keys.begin(), keys.end());
      tile.keys.insert(tile.keys.end(), keys.begin(), keys.end());
      count += added;
      tile.level_end.push_back(count);
    }
    for (std::uint32_t i = 0; i < count; ++i)
      tile.points.push_back({static_cast<std::uint16_t>(rng()), static_cast<std::uint16_t>(rng())});
  }
  if (glide && levels > 1) {
    for (std::uint32_t k = 0; k < levels; ++k) {  // N_k and a step half-way to the next level
      set.keyframe_nominal.push_back(set.level_nominal[k]);
      if (k + 1 < levels)
        set.keyframe_nominal.push_back((set.level_nominal[k] + set.level_nominal[k + 1]) / 2);
    }
    for (Tile& tile : set.tiles)
      for (std::size_t g = 0; g < set.keyframe_nominal.size(); ++g)
        for (std::uint32_t i = 0; i < 2 * set.offsets_at_keyframe(tile, g); ++i)
          tile.glide.push_back(static_cast<std::int8_t>(rng()));
  }
  return set;
}

std::vector<std::uint8_t> encode(const TilesetData& set) {
  std::vector<std::uint8_t> bytes;
  EXPECT_EQ(encode_tileset(set, bytes), Status::kOk);
  return bytes;
}

Status decode(const std::vector<std::uint8_t>& bytes, std::size_t size) {
  TilesetData out;
  return decode_tileset(bytes.data(), size, out);
}

std::uint32_t get32(const std::uint8_t* p) {
  return p[0] | p[1] << 8 | p[2] << 16 | std::uint32_t(p[3]) << 24;
}
void put32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void put64(std::uint8_t* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

// Rewrites `file`'s payload with `payload` (a zstd frame of `body_size` bytes) and fixes every size and
// checksum, as a hostile writer who knows the format would.
std::vector<std::uint8_t> with_payload(std::vector<std::uint8_t> file,
                                       const std::vector<std::uint8_t>& payload, std::uint64_t body_size) {
  const std::uint32_t header_size = get32(&file[12]);
  file.resize(header_size);
  put64(&file[16], payload.size());
  put64(&file[24], body_size);
  put32(&file[32], detail::crc32(payload.data(), payload.size()));
  put32(&file[60], 0);
  put32(&file[60], detail::crc32(file.data(), file.size()));
  file.insert(file.end(), payload.begin(), payload.end());
  return file;
}
// The same with `body` compressed (its size claimed to be `claimed_body_size` if not 0).
std::vector<std::uint8_t> with_body(std::vector<std::uint8_t> file, const std::string& body,
                                    std::uint64_t claimed_body_size = 0) {
  std::vector<std::uint8_t> payload(ZSTD_compressBound(body.size()));
  payload.resize(ZSTD_compress(payload.data(), payload.size(), body.data(), body.size(), 3));
  return with_payload(std::move(file), payload, claimed_body_size ? claimed_body_size : body.size());
}

TEST(TilesetFormatTest, RoundTripIsExact) {
  const TilesetData without = make_tileset(2, 3, 1, /*glide=*/false);
  const std::vector<std::uint8_t> plain = encode(without);
  TilesetData back;
  ASSERT_EQ(decode_tileset(plain.data(), plain.size(), back), Status::kOk);
  EXPECT_TRUE(back == without);
  const TilesetData set = make_tileset();
  ASSERT_FALSE(set.tiles[0].glide.empty());
  const std::vector<std::uint8_t> bytes = encode(set);
  ASSERT_EQ(decode_tileset(bytes.data(), bytes.size(), back), Status::kOk);
  EXPECT_EQ(back, set);
  const std::string path = ::testing::TempDir() + "/roundtrip.kdmt";
  ASSERT_EQ(save_tileset(set, path), Status::kOk);
  TilesetData loaded;
  ASSERT_EQ(load_tileset(path, loaded), Status::kOk);
  EXPECT_EQ(loaded, set);
  std::remove(path.c_str());
}

TEST(TilesetFormatTest, EveryTruncationIsRejectedAsTruncated) {
  const std::vector<std::uint8_t> bytes = encode(make_tileset());
  for (std::size_t len = 0; len < bytes.size(); ++len)
    ASSERT_EQ(decode(bytes, len), Status::kTruncated) << "cut at " << len << " of " << bytes.size();
  EXPECT_EQ(decode(bytes, bytes.size()), Status::kOk);
}

TEST(TilesetFormatTest, TrailingBytesAreRejected) {
  std::vector<std::uint8_t> bytes = encode(make_tileset());
  const std::size_t end = bytes.size();
  bytes.push_back(0);
  EXPECT_EQ(decode(bytes, bytes.size()), Status::kTrailingBytes);
  TilesetData out;
  std::string why;
  EXPECT_EQ(decode_tileset(bytes.data(), bytes.size(), out, &why), Status::kTrailingBytes);
  EXPECT_NE(why.find("ends at byte " + std::to_string(end)), std::string::npos) << why;
}

TEST(TilesetFormatTest, EveryHeaderBitFlipIsRejected) {
  const std::vector<std::uint8_t> bytes = encode(make_tileset());
  const std::uint32_t header_size = get32(&bytes[12]);
  for (std::size_t bit = 0; bit < header_size * 8; ++bit) {
    std::vector<std::uint8_t> damaged = bytes;
    damaged[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
    const Status s = decode(damaged, damaged.size());
    ASSERT_NE(s, Status::kOk) << "bit " << bit;
    if (bit >= 12 * 8) {  // past magic and version: a damaged header, never a cut file
      ASSERT_TRUE(s == Status::kHeaderChecksumMismatch) << "bit " << bit << ": " << status_message(s);
    }
  }
}

TEST(TilesetFormatTest, PayloadBitFlipsAreCaughtByTheChecksum) {
  const std::vector<std::uint8_t> bytes = encode(make_tileset());
  const std::uint32_t header_size = get32(&bytes[12]);
  std::mt19937 rng(5);
  for (int trial = 0; trial < 2000; ++trial) {
    std::vector<std::uint8_t> damaged = bytes;
    const std::size_t bit = header_size * 8 + rng() % ((bytes.size() - header_size) * 8);
    damaged[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
    ASSERT_EQ(decode(damaged, damaged.size()), Status::kPayloadChecksumMismatch) << "bit " << bit;
  }
}

TEST(TilesetFormatTest, WrongMagicAndVersionAreNamed) {
  std::vector<std::uint8_t> bytes = encode(make_tileset());
  std::vector<std::uint8_t> other = bytes;
  other[0] = 'X';
  EXPECT_EQ(decode(other, other.size()), Status::kBadMagic);
  other = bytes;
  put32(&other[8], kTilesetFormatVersion + 1);
  EXPECT_EQ(decode(other, other.size()), Status::kUnsupportedVersion);
  const char png[] = "\x89PNG\r\n\x1a\n....";
  TilesetData out;
  EXPECT_EQ(decode_tileset(png, sizeof png, out), Status::kBadMagic);
}

std::string body_bytes(const std::function<void(cereal::PortableBinaryOutputArchive&)>& write) {
  std::ostringstream s(std::ios::binary);
  {
    cereal::PortableBinaryOutputArchive ar(s);
    write(ar);
  }
  return s.str();
}

// A set of 16 colours has 65,536 tiles: a few points each make a file of a few hundred kilobytes, and
// loaded it must cost about what it holds, not a 4 KB cell index a tile (270 MB, most of it for nothing:
// a tile of fewer points than cells is scanned whole).
TEST(TilesetFormatTest, LoadedSetsCostWhatTheyHold) {
  const TilesetData sparse = make_tileset(16, 1, 1, false);
  std::vector<std::uint8_t> bytes;
  ASSERT_EQ(encode_tileset(sparse, bytes), Status::kOk);
  Tileset t;
  ASSERT_EQ(Tileset::load_memory(bytes.data(), bytes.size(), t), Status::kOk);
  const std::size_t tiles = sparse.tiles.size();
  EXPECT_LT(t.resident_bytes(), 1024 * tiles) << bytes.size() << "-byte file";
  EXPECT_TRUE(detail::TilesetInternals::tables(t).cell_start.empty());
  // The points are the same, whether a tile is visited through its cells or scanned.
  QueryParams q;
  q.x0 = 0.1, q.y0 = 0.1, q.x1 = 0.15, q.y1 = 3.2, q.scale = 12;
  std::vector<QueryPoint> part(4096);
  std::size_t written = 0;
  QueryCursor cursor;
  ASSERT_EQ(query_points(t, q, part.data(), part.size(), &written, &cursor), Status::kOk);
  part.resize(written);
  q.x0 = 0, q.y0 = 0, q.x1 = 4, q.y1 = 4;
  std::vector<QueryPoint> whole(4096);
  cursor = QueryCursor{};
  ASSERT_EQ(query_points(t, q, whole.data(), whole.size(), &written, &cursor), Status::kOk);
  whole.resize(written);
  std::size_t inside = 0;
  for (const QueryPoint& p : whole) inside += p.x >= 0.1 && p.x < 0.15 && p.y >= 0.1 && p.y < 3.2;
  EXPECT_EQ(part.size(), inside);
  EXPECT_GT(inside, 0u);
}

TEST(TilesetFormatTest, HostileCountsBehindValidChecksumsAreRejected) {
  const TilesetData set = make_tileset(1, 2);  // one colour: a single tile
  const std::vector<std::uint8_t> file = encode(set);
  // An array that claims 2^40 elements: refused before any allocation.
  // The level table, then an empty keyframe table (no glide track).
  const auto nominal = [](auto& ar) {
    ar(cereal::make_size_tag(cereal::size_type(2)), std::uint32_t(4), std::uint32_t(16));
    ar(cereal::make_size_tag(cereal::size_type(0)));
  };
  const auto no_glide = [](auto& ar) { ar(cereal::make_size_tag(cereal::size_type(0))); };
  const std::string huge = body_bytes([&](auto& ar) {
    ar(std::uint32_t(1), std::uint32_t(2), std::uint32_t(1));
    nominal(ar);
    ar(cereal::make_size_tag(cereal::size_type(1) << 40));
    for (int i = 0; i < 8; ++i) ar(std::uint64_t(0));  // some bytes, far fewer than claimed
  });
  TilesetData out;
  std::string why;
  std::vector<std::uint8_t> bad = with_body(file, huge);
  EXPECT_EQ(decode_tileset(bad.data(), bad.size(), out, &why), Status::kInvalidContent);
  EXPECT_NE(why.find("more than the payload"), std::string::npos) << "detail: " << why;
  // A body that ends inside a record (its header's sizes fixed to match): said in kdm's words.
  const std::string whole = body_bytes([&](auto& ar) {
    ar(std::uint32_t(1), std::uint32_t(2), std::uint32_t(1));
    nominal(ar);
  });
  bad = with_body(file, whole.substr(0, whole.size() - 3));
  EXPECT_EQ(decode_tileset(bad.data(), bad.size(), out, &why), Status::kInvalidContent);
  EXPECT_EQ(why, "payload: its records end before their stated sizes");
  // A level table that does not end at the point count.
  const std::string inconsistent = body_bytes([&](auto& ar) {
    ar(std::uint32_t(1), std::uint32_t(2), std::uint32_t(1));
    nominal(ar);
    ar(cereal::make_size_tag(cereal::size_type(2)), std::uint32_t(1), std::uint32_t(5));
    ar(cereal::make_size_tag(cereal::size_type(2)), std::uint16_t(7), std::uint16_t(9));
    ar(cereal::make_size_tag(cereal::size_type(1)), std::uint16_t(0));
    no_glide(ar);
  });
  bad = with_body(file, inconsistent);
  EXPECT_EQ(decode_tileset(bad.data(), bad.size(), out, &why), Status::kInvalidContent);
  // Keys out of order within a level, and a nominal table that does not increase.
  const std::string unsorted = body_bytes([&](auto& ar) {
    ar(std::uint32_t(1), std::uint32_t(2), std::uint32_t(1));
    nominal(ar);
    ar(cereal::make_size_tag(cereal::size_type(2)), std::uint32_t(1), std::uint32_t(3));
    ar(cereal::make_size_tag(cereal::size_type(6)));
    for (int i = 0; i < 6; ++i) ar(std::uint16_t(i));
    ar(cereal::make_size_tag(cereal::size_type(3)), std::uint16_t(0), std::uint16_t(9), std::uint16_t(8));
    no_glide(ar);
  });
  bad = with_body(file, unsorted);
  EXPECT_EQ(decode_tileset(bad.data(), bad.size(), out, &why), Status::kInvalidContent);
  EXPECT_NE(why.find("unsorted keys"), std::string::npos) << "detail: " << why;
  const std::string flat = body_bytes([&](auto& ar) {
    ar(std::uint32_t(1), std::uint32_t(2), std::uint32_t(1));
    ar(cereal::make_size_tag(cereal::size_type(2)), std::uint32_t(4), std::uint32_t(4));
    ar(cereal::make_size_tag(cereal::size_type(0)));
    ar(cereal::make_size_tag(cereal::size_type(2)), std::uint32_t(1), std::uint32_t(1));
    ar(cereal::make_size_tag(cereal::size_type(2)), std::uint16_t(7), std::uint16_t(9));
    ar(cereal::make_size_tag(cereal::size_type(1)), std::uint16_t(0));
    no_glide(ar);
  });
  bad = with_body(file, flat);
  EXPECT_EQ(decode_tileset(bad.data(), bad.size(), out, &why), Status::kInvalidContent);
  EXPECT_NE(why.find("nominal"), std::string::npos) << "detail: " << why;
  // Glide tracks: keyframes that do not increase, that stop short of the top level, and a glide array
  // of the wrong size for its keyframes (one point, present at both keyframes: 2 pairs needed).
  const auto one_point = [&](auto& ar, std::uint32_t k0, std::uint32_t k1, std::size_t offsets) {
    ar(std::uint32_t(1), std::uint32_t(2), std::uint32_t(1));
    ar(cereal::make_size_tag(cereal::size_type(2)), std::uint32_t(4), std::uint32_t(16));
    ar(cereal::make_size_tag(cereal::size_type(2)), k0, k1);
    ar(cereal::make_size_tag(cereal::size_type(2)), std::uint32_t(1), std::uint32_t(1));
    ar(cereal::make_size_tag(cereal::size_type(2)), std::uint16_t(7), std::uint16_t(9));
    ar(cereal::make_size_tag(cereal::size_type(1)), std::uint16_t(0));
    ar(cereal::make_size_tag(cereal::size_type(offsets)));
    for (std::size_t i = 0; i < offsets; ++i) ar(std::int8_t(-3));
  };
  const struct {
    std::uint32_t k0, k1;
    std::size_t offsets;
    const char* says;
  } gliding[] = {{8, 8, 4, "keyframe counts"}, {4, 8, 4, "last keyframe"}, {4, 16, 2, "glide offsets"}};
  for (const auto& g : gliding) {
    bad = with_body(file, body_bytes([&](auto& ar) { one_point(ar, g.k0, g.k1, g.offsets); }));
    EXPECT_EQ(decode_tileset(bad.data(), bad.size(), out, &why), Status::kInvalidContent) << g.says;
    EXPECT_NE(why.find(g.says), std::string::npos) << "detail: " << why;
  }
  bad = with_body(file, body_bytes([&](auto& ar) { one_point(ar, 4, 16, 4); }));
  EXPECT_EQ(decode_tileset(bad.data(), bad.size(), out, &why), Status::kOk) << why;
  EXPECT_EQ(out.tiles[0].glide.size(), 4u);
  // A tile count that disagrees with the header.
  const std::string miscounted =
      body_bytes([](auto& ar) { ar(std::uint32_t(1), std::uint32_t(2), std::uint32_t(900)); });
  bad = with_body(file, miscounted);
  EXPECT_EQ(decode_tileset(bad.data(), bad.size(), out, &why), Status::kInvalidContent);
  // A payload that claims to decompress to more than the cap (a zip bomb) is refused unopened.
  bad = with_body(file, inconsistent, kMaxTilesetPayloadBytes + 1);
  EXPECT_EQ(decode_tileset(bad.data(), bad.size(), out, &why), Status::kTooLarge);
  // And one whose zstd frame disagrees with the stated size.
  bad = with_body(file, inconsistent, inconsistent.size() + 1);
  EXPECT_EQ(decode_tileset(bad.data(), bad.size(), out, &why), Status::kDecompressionFailed);
  EXPECT_TRUE(out.tiles.empty());
}

// A file of format `version` (one colour, two levels) whose body `write` writes by hand; the header is a
// valid one's, with every size and checksum fixed.
std::vector<std::uint8_t> older_file(std::uint32_t version,
                                     const std::function<void(cereal::PortableBinaryOutputArchive&)>& write) {
  std::vector<std::uint8_t> file = encode(make_tileset(1, 2, 1, /*glide=*/false));
  put32(&file[8], version);
  return with_body(file, body_bytes(write));
}

TEST(TilesetFormatTest, Version2FilesStillLoad) {
  // A format-2 file: the same header, a body without keyframe_nominal and glide arrays.
  std::vector<std::uint8_t> file = older_file(2, [](auto& ar) {
    ar(std::uint32_t(1), std::uint32_t(2), std::uint32_t(1));
    ar(cereal::make_size_tag(cereal::size_type(2)), std::uint32_t(4), std::uint32_t(16));
    ar(cereal::make_size_tag(cereal::size_type(2)), std::uint32_t(1), std::uint32_t(2));
    ar(cereal::make_size_tag(cereal::size_type(4)), std::uint16_t(7), std::uint16_t(9), std::uint16_t(70),
       std::uint16_t(90));
    ar(cereal::make_size_tag(cereal::size_type(2)), std::uint16_t(5), std::uint16_t(3));
  });
  TilesetData out;
  std::string why;
  ASSERT_EQ(decode_tileset(file.data(), file.size(), out, &why), Status::kOk) << why;
  EXPECT_EQ(out.tiles[0].points.size(), 2u);
  EXPECT_TRUE(out.keyframe_nominal.empty());
  EXPECT_TRUE(out.tiles[0].glide.empty());
  // The same body under version 3 lacks its arrays: refused, never misread.
  put32(&file[8], 3);
  put32(&file[60], 0);
  put32(&file[60], detail::crc32(file.data(), get32(&file[12])));
  EXPECT_EQ(decode_tileset(file.data(), file.size(), out, &why), Status::kInvalidContent);
}

TEST(TilesetFormatTest, Version3GlideOffsetsAreConvertedToEightBits) {
  // A format-3 file: one point present at keyframes K = 4 and 65536, its offsets 16-bit in 1/65536 tile
  // sides, the second stored as the difference from the first. Format 4's units are 1/(32 √K) tile sides:
  // 1024 and 8 sixty-five-thousandths, so (2048, -3000) becomes (2, -3) (-2.93 rounded) and (-400, 5000)
  // becomes (-50, 127) (625 clamped).
  const std::vector<std::uint8_t> file = older_file(3, [](auto& ar) {
    ar(std::uint32_t(1), std::uint32_t(2), std::uint32_t(1));
    ar(cereal::make_size_tag(cereal::size_type(2)), std::uint32_t(4), std::uint32_t(65536));
    ar(cereal::make_size_tag(cereal::size_type(2)), std::uint32_t(4), std::uint32_t(65536));
    ar(cereal::make_size_tag(cereal::size_type(2)), std::uint32_t(1), std::uint32_t(1));
    ar(cereal::make_size_tag(cereal::size_type(2)), std::uint16_t(7), std::uint16_t(9));
    ar(cereal::make_size_tag(cereal::size_type(1)), std::uint16_t(0));
    ar(cereal::make_size_tag(cereal::size_type(4)), std::int16_t(2048), std::int16_t(-3000),
       std::int16_t(-400 - 2048), std::int16_t(5000 + 3000));
  });
  TilesetData out;
  std::string why;
  ASSERT_EQ(decode_tileset(file.data(), file.size(), out, &why), Status::kOk) << why;
  ASSERT_EQ(out.tiles[0].glide.size(), 4u);
  EXPECT_EQ(out.tiles[0].glide[0], 2);
  EXPECT_EQ(out.tiles[0].glide[1], -3);
  EXPECT_EQ(out.tiles[0].glide[2], -50);
  EXPECT_EQ(out.tiles[0].glide[3], 127);
  EXPECT_DOUBLE_EQ(out.glide_unit(0), 1.0 / 64);
  EXPECT_DOUBLE_EQ(out.glide_unit(1), 1.0 / 8192);
}

TEST(TilesetFormatTest, InvalidTileSetsAreNotWritten) {
  TilesetData set = make_tileset();
  set.tiles.pop_back();
  std::vector<std::uint8_t> bytes;
  std::string why;
  EXPECT_EQ(encode_tileset(set, bytes, &why), Status::kInvalidArgument);
  EXPECT_NE(why.find("tiles"), std::string::npos) << why;
  set = make_tileset();
  set.tiles[3].level_end[1] = 0;
  EXPECT_EQ(validate_tileset(set), Status::kInvalidContent);
  set = make_tileset();
  set.colours = 17;
  EXPECT_EQ(validate_tileset(set), Status::kInvalidContent);
  set = make_tileset();
  set.tiles[2].keys.pop_back();
  EXPECT_EQ(validate_tileset(set), Status::kInvalidContent);
  // Tiles that hold no points: a set that emits nothing at any density, a damaged or forged file. One
  // point anywhere is a set (LoadedSetsCostWhatTheyHold bounds what a sparse one costs).
  set = make_tileset();
  for (Tile& tile : set.tiles) tile = Tile{}, tile.level_end.assign(set.levels, 0);
  EXPECT_EQ(validate_tileset(set, &why), Status::kInvalidContent);
  EXPECT_NE(why.find("hold no points"), std::string::npos) << why;
  set.tiles[1] = make_tileset().tiles[1];
  EXPECT_EQ(validate_tileset(set, &why), Status::kOk) << why;
  // A tile of millions of points where its level promises 32 (a forged file of 16 KB): a query of one
  // point per tile emitted them all at one place.
  set = make_tileset();
  set.tiles[0].level_end = {4 * 12 + 65, 4 * 12 + 65, 4 * 12 + 65};
  set.tiles[0].points.assign(4 * 12 + 65, TilePoint{1, 1});
  set.tiles[0].keys.assign(4 * 12 + 65, 7);
  set.keyframe_nominal.clear();
  for (Tile& tile : set.tiles) tile.glide.clear();
  EXPECT_EQ(validate_tileset(set, &why), Status::kInvalidContent);
  EXPECT_NE(why.find("tile 0 holds 113 points in levels 0..0, more than 4 times their nominal 12"),
            std::string::npos)
      << why;
  set.tiles[0].level_end = {4 * 12 + 64, 4 * 12 + 65, 4 * 12 + 65};  // at the bound
  EXPECT_EQ(validate_tileset(set, &why), Status::kOk) << why;
}

TEST(TilesetFormatTest, SavingIsAtomicAndReportsIoErrors) {
  const TilesetData set = make_tileset();
  EXPECT_EQ(save_tileset(set, "/nonexistent-dir/x.kdmt"), Status::kIoError);
  // A path that cannot take the set is found before any work (check_tileset_path), named in the detail.
  std::string detail;
  EXPECT_EQ(check_tileset_path(::testing::TempDir(), &detail), Status::kIoError);
  EXPECT_NE(detail.find("is a directory"), std::string::npos) << detail;
  EXPECT_EQ(save_tileset(set, ::testing::TempDir(), &detail), Status::kIoError);
  EXPECT_NE(detail.find("is a directory"), std::string::npos) << detail;
  EXPECT_EQ(check_tileset_path("", &detail), Status::kIoError);
  EXPECT_EQ(check_tileset_path("/nonexistent-dir/x.kdmt", &detail), Status::kIoError);
  EXPECT_NE(
      detail.find("cannot write '/nonexistent-dir/x.kdmt': directory '/nonexistent-dir' does not exist"),
      std::string::npos)
      << detail;
  EXPECT_EQ(check_tileset_path(::testing::TempDir() + "/fresh.kdmt"), Status::kOk);
  EXPECT_FALSE(std::ifstream(::testing::TempDir() + "/fresh.kdmt.partial").good());  // removed again
  const std::string path = ::testing::TempDir() + "/atomic.kdmt";
  { std::ofstream(path) << "old contents"; }
  ASSERT_EQ(save_tileset(set, path), Status::kOk);
  TilesetData loaded;
  EXPECT_EQ(load_tileset(path, loaded), Status::kOk);
  std::ifstream partial(path + ".partial");
  EXPECT_FALSE(partial.good());  // no temporary left behind
  std::remove(path.c_str());
  EXPECT_EQ(load_tileset(path, loaded), Status::kIoError);
  // Through a symbolic link the set replaces the link's target; the link stays a link.
  namespace fs = std::filesystem;
  const fs::path target = fs::path(::testing::TempDir()) / "target.kdmt",
                 link = fs::path(::testing::TempDir()) / "link.kdmt";
  fs::remove(target), fs::remove(link);
  { std::ofstream(target) << "old contents"; }
  fs::create_symlink(target, link);
  ASSERT_EQ(save_tileset(set, link.string()), Status::kOk);
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(link)));
  EXPECT_EQ(load_tileset(target.string(), loaded), Status::kOk);
  fs::remove(target), fs::remove(link);
}

}  // namespace
}  // namespace kdm

namespace kdm {
namespace {

// The shipped set itself: every cut within the header and the first 4 KiB of payload, then 2,000 cuts
// spread over the rest, is refused as truncated; 300 random payload bit flips are caught by the checksum.
TEST(TilesetFormatTest, TheShippedSetCutOrDamagedIsRejected) {
  std::ifstream in(std::string(KDM_SOURCE_DIR) + "/tilesets/default.kdmt", std::ios::binary);
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                                        std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 100000u);
  ASSERT_EQ(decode(bytes, bytes.size()), Status::kOk);
  const std::size_t header_size = get32(&bytes[12]);
  for (std::size_t len = 0; len < header_size + 4096; ++len)
    ASSERT_EQ(decode(bytes, len), Status::kTruncated) << "cut at " << len;
  for (int i = 0; i < 2000; ++i) {
    const std::size_t len = header_size + 4096 + (bytes.size() - header_size - 4096) * std::size_t(i) / 2000;
    ASSERT_EQ(decode(bytes, len), Status::kTruncated) << "cut at " << len;
  }
  std::mt19937 rng(11);
  std::vector<std::uint8_t> damaged = bytes;
  for (int trial = 0; trial < 300; ++trial) {
    const std::size_t bit = header_size * 8 + rng() % ((bytes.size() - header_size) * 8);
    damaged[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
    ASSERT_EQ(decode(damaged, damaged.size()), Status::kPayloadChecksumMismatch) << "bit " << bit;
    damaged[bit / 8] = bytes[bit / 8];
  }
}

// The header alone says what a file is (kdm info asks this), agrees with the decoded set, and is refused
// at every length short of the whole file (its size is checked against the header's sizes).
TEST(TilesetFormatTest, TheHeaderDescribesTheFileAndIsValidatedAlone) {
  const TilesetData set = make_tileset();
  const std::vector<std::uint8_t> bytes = encode(set);
  TilesetHeader h;
  ASSERT_EQ(read_tileset_header(bytes.data(), bytes.size(), h), Status::kOk);
  EXPECT_EQ(h.format_version, 4u);  // the oldest that holds a set without a hand-over
  EXPECT_EQ(h.colours, set.colours);
  EXPECT_EQ(h.levels, set.levels);
  EXPECT_EQ(h.tiles, set.tiles.size());
  EXPECT_EQ(h.recipe, set.recipe);
  EXPECT_EQ(h.generator_version, set.generator_version);
  EXPECT_EQ(h.header_bytes + h.payload_bytes, bytes.size());
  EXPECT_GT(h.decompressed_bytes, h.payload_bytes / 2);
  const std::size_t header_bytes = h.header_bytes;
  for (std::size_t len = 0; len < bytes.size(); ++len) {
    std::string why;
    ASSERT_EQ(read_tileset_header(bytes.data(), len, h, &why), Status::kTruncated) << "cut at " << len;
    EXPECT_EQ(h.format_version, 0u);  // left empty
    // Past the magic number the detail says how many bytes the file has and how many it needs.
    if (len >= 8) {
      const std::string has = "it has " + std::to_string(len) + " bytes";
      const std::string needs = len < 64             ? "fixed header's 64"
                                : len < header_bytes ? "header's " + std::to_string(header_bytes)
                                                     : "need " + std::to_string(bytes.size());
      EXPECT_NE(why.find(has), std::string::npos) << "cut at " << len << ": " << why;
      EXPECT_NE(why.find(needs), std::string::npos) << "cut at " << len << ": " << why;
    }
  }
  std::vector<std::uint8_t> damaged = bytes;
  damaged[header_bytes + 3] ^= 1;  // the payload: the header does not look at it
  EXPECT_EQ(read_tileset_header(damaged.data(), damaged.size(), h), Status::kOk);
  damaged[41] ^= 1;  // the colours field
  EXPECT_EQ(read_tileset_header(damaged.data(), damaged.size(), h), Status::kHeaderChecksumMismatch);
  // With a checksum that matches, each count the header holds is checked and named.
  const auto refusal = [&](std::uint32_t colours, std::uint32_t tiles) {
    std::vector<std::uint8_t> file = bytes;
    put32(&file[36], tiles), put32(&file[40], colours);
    put32(&file[60], 0);
    put32(&file[60], detail::crc32(file.data(), get32(&file[12])));
    std::string why;
    EXPECT_EQ(read_tileset_header(file.data(), file.size(), h, &why), Status::kInvalidContent);
    return why;
  };
  EXPECT_NE(refusal(17, 17 * 17 * 17 * 17).find("colour count 17 is outside 1..16"), std::string::npos);
  EXPECT_NE(refusal(0, 0).find("colour count 0"), std::string::npos);
  EXPECT_NE(refusal(2, 15).find("15 tiles for 2 colours"), std::string::npos);
  EXPECT_EQ(read_tileset_header(nullptr, 0, h), Status::kTruncated);
}

// A header past the reader's cap whose size agrees with its texts' (a 2 MiB recipe) is too large, not
// damaged; a size field that alone is past the cap is damage. The file reader stops at the fixed header.
TEST(TilesetFormatTest, AHeaderPastTheCapIsTooLargeNotDamaged) {
  const std::vector<std::uint8_t> file = encode(make_tileset(1, 2, 1, /*glide=*/false));
  const std::uint32_t fixed = 64, long_recipe = 2u << 20, version_size = get32(&file[52]);
  std::vector<std::uint8_t> big(file.begin(), file.begin() + fixed);  // the fixed header (format doc §2)
  put32(&big[12], fixed + long_recipe + version_size), put32(&big[48], long_recipe);
  const std::string path = ::testing::TempDir() + "/long_recipe.kdmt";
  {
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(big.data()), static_cast<std::streamsize>(big.size()));
    f << std::string(long_recipe + version_size + 100, 'r');
  }
  TilesetData loaded;
  std::string why;
  EXPECT_EQ(load_tileset(path, loaded, &why), Status::kTooLarge);
  const std::string size = std::to_string(fixed + long_recipe + version_size);
  EXPECT_NE(why.find("header of " + size + " bytes passes this reader's limit of 1048576"), std::string::npos)
      << why;
  TilesetHeader h;
  put32(&big[48], get32(&file[48]));  // the texts' sizes disagree with the header's
  EXPECT_EQ(read_tileset_header(big.data(), big.size(), h, &why), Status::kHeaderChecksumMismatch);
  EXPECT_NE(why.find("implausible"), std::string::npos) << why;
  std::remove(path.c_str());
}

// An engine's allocator serves every array of a loaded tile set, and gets all of it back, even when
// other hooks are installed in between.
struct CountingHeap {
  std::size_t live_bytes = 0, allocations = 0, frees = 0;
};
void* counting_allocate(std::size_t bytes, std::size_t, void* user) {
  auto* heap = static_cast<CountingHeap*>(user);
  heap->live_bytes += bytes, ++heap->allocations;
  return std::malloc(bytes ? bytes : 1);
}
void counting_deallocate(void* p, std::size_t bytes, std::size_t, void* user) {
  auto* heap = static_cast<CountingHeap*>(user);
  heap->live_bytes -= bytes, ++heap->frees;
  std::free(p);
}

TEST(TilesetFormatTest, KeyframesCloserThanTheLookupTableStillFindTheirBracket) {
  // A keyframe at every count from the first level to the top (1 apart, under the lookup table's 3.1%
  // buckets): the one-step lookup no longer holds, and the search must still match std::lower_bound, and a
  // smooth query with a varying density must emit the same ids as a stable one.
  TilesetData set = make_tileset(2, 3, 4, /*glide=*/false);
  for (std::uint32_t k = set.level_nominal.front(); k <= set.level_nominal.back(); ++k)
    set.keyframe_nominal.push_back(k);
  std::mt19937 rng(5);
  for (Tile& tile : set.tiles)
    for (std::size_t g = 0; g < set.keyframe_nominal.size(); ++g)
      for (std::uint32_t i = 0; i < 2 * set.offsets_at_keyframe(tile, g); ++i)
        tile.glide.push_back(static_cast<std::int8_t>(rng() % 9) - 4);
  const std::vector<std::uint8_t> bytes = encode(set);
  Tileset t;
  ASSERT_EQ(Tileset::load_memory(bytes.data(), bytes.size(), t), Status::kOk);
  EXPECT_FALSE(detail::TilesetInternals::tables(t).keyframe_one_step);
  EXPECT_TRUE(detail::TilesetInternals::tables(Tileset::builtin()).keyframe_one_step);
  const auto& k = set.keyframe_nominal;
  for (double c = 0.25; c < 400; c += 0.125)
    ASSERT_EQ(detail::first_keyframe_at_least(t, c), std::lower_bound(k.begin(), k.end(), c) - k.begin())
        << c;

  QueryParams q;
  q.x1 = q.y1 = 3;
  q.scale = 90;  // up to 180 expected per tile, of 192 at the top
  q.density.kind = QueryDensity::Kind::kCallback;
  q.density.callback = [](void*, double x, double y) { return 0.1 + 0.3 * (x + y); };
  q.density.callback_max = 2;
  std::vector<QueryPoint> stable(4096), smooth(4096);
  std::size_t stable_n = 0, smooth_n = 0;
  QueryCursor a, b;
  ASSERT_EQ(query_points(t, q, stable.data(), stable.size(), &stable_n, &a), Status::kOk);
  q.mode = QueryMode::kSmooth;
  ASSERT_EQ(query_points(t, q, smooth.data(), smooth.size(), &smooth_n, &b), Status::kOk);
  std::vector<std::tuple<std::int64_t, std::int64_t, std::uint32_t>> ids_stable, ids_smooth;
  for (std::size_t i = 0; i < stable_n; ++i)
    if (stable[i].x > 0.5 && stable[i].x < 2.5 && stable[i].y > 0.5 && stable[i].y < 2.5)
      ids_stable.emplace_back(stable[i].id.tile_x, stable[i].id.tile_y, stable[i].id.rank);
  for (std::size_t i = 0; i < smooth_n; ++i)
    ids_smooth.emplace_back(smooth[i].id.tile_x, smooth[i].id.tile_y, smooth[i].id.rank);
  std::sort(ids_smooth.begin(), ids_smooth.end());
  ASSERT_GT(ids_stable.size(), 50u);
  for (const auto& id : ids_stable)  // away from the border, where points glide in and out
    EXPECT_TRUE(std::binary_search(ids_smooth.begin(), ids_smooth.end(), id));
}

TEST(TilesetAllocatorTest, TheTileSetsArraysGoThroughTheHook) {
  CountingHeap heap;
  set_tileset_allocator({counting_allocate, counting_deallocate, &heap});
  EXPECT_EQ(tileset_allocator().user, &heap);
  {
    Tileset loaded;
    ASSERT_EQ(Tileset::load_file(std::string(KDM_SOURCE_DIR) + "/tilesets/default.kdmt", loaded),
              Status::kOk);
    set_tileset_allocator({});  // later allocations use operator new; the set's memory still returns here
    EXPECT_EQ(tileset_allocator().allocate, nullptr);
    const TilesetData& d = loaded.data();
    // Everything resident but the object itself and its two texts: positions, keys, tables, thresholds.
    EXPECT_EQ(heap.live_bytes, loaded.resident_bytes() - sizeof(Tileset) - d.recipe.capacity() -
                                   d.generator_version.capacity());
    EXPECT_GT(heap.live_bytes, std::size_t(4) << 20);
    TilesetData copy = d;  // copies keep the source's allocator (propagation), so they count here too
    EXPECT_GT(heap.allocations, 3 * d.tiles.size());
  }
  EXPECT_EQ(heap.live_bytes, 0u);
  EXPECT_EQ(heap.allocations, heap.frees);
}

struct RefusingHeap {
  std::size_t refuse = 0;  ///< the allocation to refuse, counting from 1 (0: none)
  std::size_t calls = 0, live = 0;
};
void* refusing_allocate(std::size_t bytes, std::size_t, void* user) {
  auto* heap = static_cast<RefusingHeap*>(user);
  if (++heap->calls == heap->refuse) return nullptr;
  heap->live += bytes;
  return std::malloc(bytes ? bytes : 1);
}
void refusing_deallocate(void* p, std::size_t bytes, std::size_t, void* user) {
  static_cast<RefusingHeap*>(user)->live -= bytes;
  std::free(p);
}

// Whichever allocation of a load the hook refuses, the load fails as out of memory and leaves nothing
// allocated: none is optional (a shrink of an array that swallowed its refusal let the load succeed).
TEST(TilesetAllocatorTest, EveryRefusedAllocationOfALoadFailsIt) {
  const std::vector<std::uint8_t> bytes = encode(make_tileset());
  RefusingHeap heap;
  set_tileset_allocator({refusing_allocate, refusing_deallocate, &heap});
  {
    Tileset loaded;
    ASSERT_EQ(Tileset::load_memory(bytes.data(), bytes.size(), loaded), Status::kOk);
  }
  const std::size_t allocations = heap.calls;
  ASSERT_GT(allocations, 20u);
  for (std::size_t n = 1; n <= allocations; ++n) {
    heap.refuse = n, heap.calls = 0;
    Tileset loaded;
    EXPECT_EQ(Tileset::load_memory(bytes.data(), bytes.size(), loaded), Status::kOutOfMemory) << n;
    EXPECT_TRUE(loaded.empty()) << n;
    EXPECT_EQ(heap.live, 0u) << n;
  }
  set_tileset_allocator({});
}

// A path that holds no tile set fails at once with a reason: a directory, an endless device, a file cut
// short or with bytes after its payload. The loader reads no more than the header says the file holds.
TEST(TilesetFormatTest, LoadingAFileThatIsNoTilesetFailsAtItsHeader) {
  TilesetData loaded;
  std::string detail;
  EXPECT_EQ(load_tileset(::testing::TempDir(), loaded, &detail), Status::kIoError);
  EXPECT_NE(detail.find("is a directory"), std::string::npos) << detail;
  Tileset handle;
  EXPECT_EQ(Tileset::load_file(::testing::TempDir(), handle), Status::kIoError);
  if (std::ifstream("/dev/zero").good()) {
    EXPECT_EQ(load_tileset("/dev/zero", loaded), Status::kBadMagic);
  }

  std::vector<std::uint8_t> bytes;
  ASSERT_EQ(encode_tileset(make_tileset(), bytes), Status::kOk);
  const std::string path = ::testing::TempDir() + "/cut.kdmt";
  auto load_bytes = [&](std::size_t size, const std::string& tail) {
    {
      std::ofstream f(path, std::ios::binary | std::ios::trunc);
      f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(size));
      f << tail;
    }
    return load_tileset(path, loaded);
  };
  EXPECT_EQ(load_bytes(bytes.size(), ""), Status::kOk);
  EXPECT_EQ(load_bytes(bytes.size(), "x"), Status::kTrailingBytes);
  EXPECT_EQ(load_bytes(bytes.size(), std::string(1 << 16, 'x')), Status::kTrailingBytes);
  for (const std::size_t size :
       {std::size_t(0), std::size_t(5), std::size_t(63), std::size_t(64), bytes.size() / 2, bytes.size() - 1})
    EXPECT_EQ(load_bytes(size, ""), Status::kTruncated) << size;
  // A 64-byte file that claims a megabyte of header and half a gigabyte of payload is read as the 64
  // bytes it is: what it claims is not allocated before it is checked.
  std::vector<std::uint8_t> claims(bytes.begin(), bytes.begin() + 64);
  put32(&claims[12], 1u << 20), put64(&claims[16], 530000000);
  std::vector<char> read;
  {
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(claims.data()), 64);
  }
  ASSERT_EQ(read_tileset_file(path, read), Status::kOk);
  EXPECT_EQ(read.size(), 64u);
  EXPECT_LT(read.capacity(), 4096u);
  EXPECT_EQ(load_tileset(path, loaded), Status::kHeaderChecksumMismatch);
  std::remove(path.c_str());
}

// A file is judged as its bytes are in memory: a damaged size field (a payload size flipped far past any
// payload's included) is a damaged header, not a file cut inside it.
TEST(TilesetFormatTest, EveryHeaderBitFlipInAFileIsJudgedAsInMemory) {
  const std::vector<std::uint8_t> bytes = encode(make_tileset());
  const std::uint32_t header_size = get32(&bytes[12]);
  const std::string path = ::testing::TempDir() + "/flipped.kdmt";
  for (std::size_t bit = 0; bit < header_size * 8; ++bit) {
    std::vector<std::uint8_t> damaged = bytes;
    damaged[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
    {
      std::ofstream f(path, std::ios::binary | std::ios::trunc);
      f.write(reinterpret_cast<const char*>(damaged.data()), static_cast<std::streamsize>(damaged.size()));
    }
    TilesetData loaded;
    std::string in_file, in_memory;
    const Status from_file = load_tileset(path, loaded, &in_file);
    const Status from_memory = decode_tileset(damaged.data(), damaged.size(), loaded, &in_memory);
    ASSERT_EQ(from_file, from_memory) << "bit " << bit << ": " << in_file << " / " << in_memory;
    ASSERT_EQ(in_file, in_memory) << "bit " << bit;
  }
  std::vector<std::uint8_t> damaged = bytes;
  damaged[20] ^= 1u << 4;  // payload size + 2^36
  {
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(damaged.data()), static_cast<std::streamsize>(damaged.size()));
  }
  Tileset handle;
  std::string why;
  EXPECT_EQ(Tileset::load_file(path, handle, &why), Status::kHeaderChecksumMismatch) << why;
  std::remove(path.c_str());
}

// An engine's heap with a budget, as one that bounds what a set it did not bake may cost: it refuses a
// request that would take its live bytes past the budget, and records what it was asked.
struct BudgetHeap {
  std::size_t budget = 0, live = 0, peak = 0, allocations = 0, frees = 0, largest_refused = 0;
};
void* budget_allocate(std::size_t bytes, std::size_t, void* user) {
  auto* heap = static_cast<BudgetHeap*>(user);
  if (bytes > heap->budget - heap->live) {
    heap->largest_refused = std::max(heap->largest_refused, bytes);
    return nullptr;
  }
  heap->live += bytes, heap->peak = std::max(heap->peak, heap->live), ++heap->allocations;
  return std::malloc(bytes ? bytes : 1);
}
void budget_deallocate(void* p, std::size_t bytes, std::size_t, void* user) {
  auto* heap = static_cast<BudgetHeap*>(user);
  heap->live -= bytes, ++heap->frees;
  std::free(p);
}

std::vector<std::uint8_t> shipped_set() {
  std::ifstream in(std::string(KDM_SOURCE_DIR) + "/tilesets/default.kdmt", std::ios::binary);
  return std::vector<std::uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// A decompression bomb: a valid header, both checksums right, and a zstd frame of `zeros` zero bytes
// (streamed in, level 3 with level 19's 8 MiB window, as `zstd -19` writes a large input) where a set of one
// tile needs a few hundred bytes.
std::vector<std::uint8_t> decompression_bomb(std::uint64_t zeros) {
  const std::unique_ptr<ZSTD_CCtx, std::size_t (*)(ZSTD_CCtx*)> z(ZSTD_createCCtx(), ZSTD_freeCCtx);
  ZSTD_CCtx_setParameter(z.get(), ZSTD_c_compressionLevel, 3);
  ZSTD_CCtx_setParameter(z.get(), ZSTD_c_windowLog, 23);
  ZSTD_CCtx_setPledgedSrcSize(z.get(), zeros);  // the frame states its size, as the format requires
  const std::vector<char> chunk(1 << 20, 0);
  std::vector<std::uint8_t> payload, out(ZSTD_CStreamOutSize());
  for (std::uint64_t left = zeros; left > 0;) {
    const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(left, chunk.size()));
    left -= n;
    ZSTD_inBuffer in{chunk.data(), n, 0};
    const ZSTD_EndDirective mode = left ? ZSTD_e_continue : ZSTD_e_end;
    for (std::size_t pending = 1; in.pos < in.size || (mode == ZSTD_e_end && pending);) {
      ZSTD_outBuffer o{out.data(), out.size(), 0};
      pending = ZSTD_compressStream2(z.get(), &o, &in, mode);
      EXPECT_FALSE(ZSTD_isError(pending));
      if (ZSTD_isError(pending)) return {};
      payload.insert(payload.end(), out.begin(), out.begin() + std::ptrdiff_t(o.pos));
    }
  }
  return with_payload(encode(make_tileset(1, 2)), payload, zeros);
}

// The bomb is a 13 KB file that would decompress to 400 MiB. The loader reads the body as zstd
// decompresses it, so the bomb costs zstd's window (its 8 MiB, through the tile-set allocator) and is
// refused once the parser finds the tile set ends where 400 MiB of body go on; and a heap whose budget is
// below the window is asked for it and refuses it: out of memory, nothing touched, nothing leaked.
TEST(TilesetAllocatorTest, ADecompressionBombCostsItsWindowAndABudgetRefusesIt) {
  const std::uint64_t body = 400ull << 20;
  const std::vector<std::uint8_t> bomb = decompression_bomb(body);
  ASSERT_GT(bomb.size(), 64u);
  ASSERT_LT(bomb.size(), 64u << 10);
  TilesetHeader header;
  ASSERT_EQ(read_tileset_header(bomb.data(), bomb.size(), header), Status::kOk);
  ASSERT_EQ(header.decompressed_bytes, body);
  ZSTD_frameHeader frame;
  ASSERT_EQ(ZSTD_getFrameHeader(&frame, bomb.data() + header.header_bytes, header.payload_bytes), 0u);
  ASSERT_EQ(frame.frameContentSize, body);
  const std::size_t window = static_cast<std::size_t>(frame.windowSize);
  ASSERT_EQ(window, std::size_t(8) << 20);

  BudgetHeap heap;
  heap.budget = std::size_t(4) << 20;  // below the window
  set_tileset_allocator({budget_allocate, budget_deallocate, &heap});
  Tileset loaded;
  std::string why;
  EXPECT_EQ(Tileset::load_memory(bomb.data(), bomb.size(), loaded, &why), Status::kOutOfMemory) << why;
  EXPECT_EQ(why, "payload: no memory to decompress it");
  EXPECT_GE(heap.largest_refused, window);  // the decompression buffer was asked of the hook
  EXPECT_LT(heap.largest_refused, window + (std::size_t(1) << 20));
  EXPECT_EQ(heap.live, 0u);
  EXPECT_EQ(heap.allocations, heap.frees);
  EXPECT_TRUE(loaded.empty());
  // The C API's hooks are the same ones, and so is its status.
  kdm_tileset* handle = nullptr;
  char detail[256] = "";
  EXPECT_EQ(kdm_tileset_load_memory_detail(bomb.data(), bomb.size(), &handle, detail, sizeof detail),
            KDM_OUT_OF_MEMORY);
  EXPECT_EQ(handle, nullptr);
  EXPECT_NE(std::strstr(detail, "no memory to decompress"), nullptr) << detail;
  EXPECT_EQ(heap.live, 0u);

  // A budget the shipped set loads in (with its file: kdm_runtime.h's figures) takes the bomb's window,
  // and the bomb is refused for its content after a few chunks, not after 400 MiB.
  heap = BudgetHeap{};
  heap.budget = std::size_t(64) << 20;
  const std::vector<std::uint8_t> shipped = shipped_set();
  EXPECT_EQ(Tileset::load_memory(shipped.data(), shipped.size(), loaded), Status::kOk);
  loaded = Tileset{};
  heap.peak = 0;
  EXPECT_EQ(Tileset::load_memory(bomb.data(), bomb.size(), loaded, &why), Status::kInvalidContent);
  EXPECT_EQ(why, "payload: payload has bytes after the last tile");
  EXPECT_GE(heap.peak, window);
  EXPECT_LT(heap.peak, window + (std::size_t(1) << 20));
  EXPECT_EQ(heap.live, 0u);
  set_tileset_allocator({});

  // Without hooks the same: operator new serves zstd, and is never asked for more than the window.
  testing::reset_largest_allocation();
  EXPECT_EQ(Tileset::load_memory(bomb.data(), bomb.size(), loaded), Status::kInvalidContent);
  EXPECT_LT(testing::largest_allocation(), window + (std::size_t(1) << 20));
}

// What a load of the shipped set takes at its peak, all of it through the hooks but small things (texts,
// a stream object): from memory the set's arrays and zstd's window while they fill, from its file the
// file's bytes too (kdm_runtime.h and allocator.h give these figures).
TEST(TilesetAllocatorTest, ALoadsSizeableAllocationsAllGoThroughTheHooks) {
  const std::vector<std::uint8_t> shipped = shipped_set();
  BudgetHeap heap;
  heap.budget = ~std::size_t(0);
  set_tileset_allocator({budget_allocate, budget_deallocate, &heap});
  testing::reset_largest_allocation();
  {
    Tileset loaded;
    ASSERT_EQ(Tileset::load_memory(shipped.data(), shipped.size(), loaded), Status::kOk);
    const std::size_t set = heap.live;  // the loaded set's arrays
    EXPECT_LT(testing::largest_allocation(), std::size_t(64) << 10);
    const std::size_t window = std::size_t(8) << 20;  // the shipped set's frame's, zstd's buffer
    EXPECT_GT(heap.peak, set);
    EXPECT_LT(heap.peak, set + window);
    std::printf("from memory: the set's arrays %zu bytes, peak through the hooks %zu\n", set, heap.peak);
  }
  EXPECT_EQ(heap.live, 0u);
  heap.peak = 0;
  {
    Tileset loaded;
    ASSERT_EQ(Tileset::load_file(std::string(KDM_SOURCE_DIR) + "/tilesets/default.kdmt", loaded),
              Status::kOk);
    EXPECT_LT(testing::largest_allocation(), std::size_t(64) << 10);
    EXPECT_GT(heap.peak, heap.live + shipped.size());
    std::printf("from its file: peak through the hooks %zu\n", heap.peak);
  }
  EXPECT_EQ(heap.live, 0u);
  EXPECT_EQ(heap.allocations, heap.frees);
  set_tileset_allocator({});
}

// A hand-over onto 256 × 256 subtiles of a tile of 70,001 points names 4.6 × 10^9 sub-points, past 32
// bits: the check counts them in 64 bits and compares the count with the tile's tables before it sizes
// anything by it (a 32-bit count wrapped to 2.9 × 10^8 and the check wrote far past that many bytes).
TEST(TilesetFormatTest, AHandOverOfMoreSubPointsThan32BitsCountIsRefusedBeforeItsScratch) {
  const std::uint32_t points = 70001;
  const std::string body = body_bytes([&](auto& ar) {
    ar(std::uint32_t(1), std::uint32_t(2), std::uint32_t(1));  // one colour, two levels, one tile
    ar(cereal::make_size_tag(cereal::size_type(2)), std::uint32_t(1), std::uint32_t(65536));  // m = 256
    ar(cereal::make_size_tag(cereal::size_type(3)), std::uint32_t(2), std::uint32_t(4), std::uint32_t(65536));
    ar(std::uint32_t(1));  // the hand-over zone (format 5)
    ar(cereal::make_size_tag(cereal::size_type(2)), std::uint32_t(1), points);
    ar(cereal::make_size_tag(cereal::size_type(2 * points)));
    for (std::uint32_t i = 0; i < 2 * points; ++i) ar(std::uint16_t(i % 2 ? 238 << 8 : 72 << 8));
    ar(cereal::make_size_tag(cereal::size_type(points)));
    for (std::uint32_t i = 0; i < points; ++i) ar(std::uint16_t(0));  // every point present at keyframe 1
    ar(cereal::make_size_tag(cereal::size_type(6 * points)));         // three keyframes' offsets, none moves
    for (std::uint32_t i = 0; i < 6 * points; ++i) ar(std::uint8_t(0));
    ar(cereal::make_size_tag(cereal::size_type(points)));
    for (std::uint32_t i = 0; i < points; ++i) ar(std::uint16_t(12));  // rank 0 of its own subtile
    ar(cereal::make_size_tag(cereal::size_type(0)));
  });
  std::vector<std::uint8_t> file = encode(make_tileset(1, 2, 1, /*glide=*/false));
  put32(&file[8], 5);
  file = with_body(file, body);
  TilesetData out;
  std::string why;
  EXPECT_EQ(decode_tileset(file.data(), file.size(), out, &why), Status::kInvalidContent);
  EXPECT_EQ(why, "tile 0 leaves some of its subtiles' points out of the hand-over");
}

}  // namespace
}  // namespace kdm
