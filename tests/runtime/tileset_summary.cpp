// Prints a canonical summary of a tile set as the C++ runtime decodes it (kdm::load_tileset), in exactly
// the format of `tools/tileset_reader.py FILE --summary`. The ctest runtime.independent_python_reader.*
// diffs the two: the Python reader is written from docs/tileset-format.md alone, so agreement shows the
// document is complete. Usage: tileset_summary FILE; exit status 1 with one line on stderr if the runtime
// refuses the file.
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "kdm/runtime/tileset_format.h"
#include "kdm/runtime/version.h"

namespace {

// The CRC-32 of zlib (reflected 0xEDB88320, initial and final XOR all ones), computed here rather than
// taken from the runtime so that this program uses the runtime's public API only.
std::uint32_t crc32(const std::vector<std::uint8_t>& bytes) {
  std::uint32_t crc = 0xFFFFFFFFu;
  for (const std::uint8_t b : bytes) {
    crc ^= b;
    for (int k = 0; k < 8; ++k) crc = (crc & 1) ? 0xEDB88320u ^ (crc >> 1) : crc >> 1;
  }
  return ~crc;
}

/// The format version in the file's header (bytes 8..11, little-endian); the decoder accepts several.
unsigned file_version(const char* path) {
  std::uint8_t bytes[12] = {};
  if (std::FILE* f = std::fopen(path, "rb")) {
    if (std::fread(bytes, 1, sizeof bytes, f) != sizeof bytes)
      bytes[8] = bytes[9] = bytes[10] = bytes[11] = 0;
    std::fclose(f);
  }
  return bytes[8] | bytes[9] << 8 | bytes[10] << 16 | unsigned(bytes[11]) << 24;
}

void put16(std::vector<std::uint8_t>& out, std::uint16_t v) {
  out.push_back(static_cast<std::uint8_t>(v));
  out.push_back(static_cast<std::uint8_t>(v >> 8));
}

// Text from the file is untrusted: printable ASCII as is, every other byte (and the backslash) as \xNN,
// so the summary is one line per field whatever the bytes.
std::string escaped(const std::string& text) {
  std::string out;
  for (const unsigned char c : text) {
    if (c >= 0x20 && c < 0x7f && c != '\\') {
      out += static_cast<char>(c);
    } else {
      char buf[5];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    }
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: tileset_summary FILE\n");
    return 2;
  }
  kdm::TilesetData set;
  std::string detail;
  const kdm::Status status = kdm::load_tileset(argv[1], set, &detail);
  if (status != kdm::Status::kOk) {
    std::fprintf(stderr, "tileset_summary: error: %s: %s (%s)\n", argv[1], kdm::status_message(status),
                 detail.c_str());
    return 1;
  }
  std::printf("format_version %u\n", file_version(argv[1]));
  std::printf("colours %u\nlevels %u\ntiles %zu\nlevel_nominal", set.colours, set.levels, set.tiles.size());
  for (const std::uint32_t n : set.level_nominal) std::printf(" %u", n);
  std::printf("\nkeyframe_nominal");
  for (const std::uint32_t n : set.keyframe_nominal) std::printf(" %u", n);
  if (set.handover_zone) std::printf("\nhandover_zone %u", set.handover_zone);
  if (set.handover_level) std::printf("\nhandover_level %u", set.handover_level);
  if (set.handover_slack) std::printf("\nhandover_slack %u", set.handover_slack);
  std::printf("\nrecipe_bytes %zu\nrecipe_crc32 %08x\ngenerator_version %s\n", set.recipe.size(),
              crc32({set.recipe.begin(), set.recipe.end()}), escaped(set.generator_version).c_str());
  std::vector<std::uint8_t> triples, thresholds;
  const std::vector<std::vector<float>> coarsest = kdm::coarsest_level_thresholds(set);
  for (std::size_t t = 0; t < set.tiles.size(); ++t) {
    const kdm::Tile& tile = set.tiles[t];
    // (x, y, key) as three little-endian u16 per point, and each point's float32 emission threshold as
    // its little-endian IEEE bits: the checksums cover every decoded value and the emission rule.
    triples.clear();
    thresholds.clear();
    std::uint32_t level = 0;
    for (std::size_t i = 0; i < tile.points.size(); ++i) {
      put16(triples, tile.points[i].x);
      put16(triples, tile.points[i].y);
      put16(triples, tile.keys[i]);
      while (i >= tile.level_end[level]) ++level;
      const float threshold = level == 0 ? coarsest[t][i] : set.emission_threshold(level, tile.keys[i]);
      std::uint32_t bits = 0;
      static_assert(sizeof bits == sizeof threshold);
      std::memcpy(&bits, &threshold, sizeof bits);
      put16(thresholds, static_cast<std::uint16_t>(bits));
      put16(thresholds, static_cast<std::uint16_t>(bits >> 16));
    }
    std::printf("tile %zu points %zu level_end", t, tile.points.size());
    for (const std::uint32_t e : tile.level_end) std::printf(" %u", e);
    std::vector<std::uint8_t> glide;
    for (const std::int8_t v : tile.glide) glide.push_back(static_cast<std::uint8_t>(v));
    std::printf(" points_crc32 %08x thresholds_crc32 %08x glide_crc32 %08x", crc32(triples),
                crc32(thresholds), crc32(glide));
    if (set.handover_zone) {
      std::vector<std::uint8_t> handover, appearing;
      for (const std::uint16_t v : tile.handover) put16(handover, v);
      for (const std::uint32_t v : tile.appearing) {
        put16(appearing, static_cast<std::uint16_t>(v));
        put16(appearing, static_cast<std::uint16_t>(v >> 16));
      }
      std::printf(" handover_crc32 %08x appearing_crc32 %08x", crc32(handover), crc32(appearing));
    }
    std::printf("\n");
  }
  return 0;
}
