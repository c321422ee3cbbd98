// kdm tile sets: the data model and the file format (defined here, once; the baker writes it through
// this header). A tile set is a family of corner tiles (Lagae & Dutré 2006): with C corner colours there
// are C^4 tiles, one per colouring (sw, se, ne, nw) of their corners; tiles whose shared corners have the
// same colours fit together without seams. Each tile holds a nested multi-density pyramid: level k+1 holds
// every point of level k plus about 3× as many new ones, sorted by (level, key).
//
// Emission keys: every point carries a key q in [0, 65536) within its level. Level k spans the nominal
// counts (N_{k-1}, N_k] (level_nominal, N_{-1} = 0), and the point appears once the expected count of
// points in its tile exceeds its threshold N_{k-1} + (q + 1/2) / 65536 · (N_k − N_{k-1})
// (emission_threshold). Points that several tiles share near corners and edges have the same key in all of
// them, so every tile emits the same subset of them at any density: mid-level densities stay seamless.
//
// The glide track (smooth mode): a set may also carry keyframes, expected counts K_0 < … < K_{G-1} = N_top
// per tile (keyframe_nominal). At keyframe g every point emitted there (threshold < K_g) has a position
// of its own, stored as an 8-bit glide offset from its stable position in units of a 32nd of that
// keyframe's spacing 1/√K_g (Tile::glide, TilesetShape::glide_unit); between two keyframes a point moves
// linearly from its position at the one to its position at the next. A point that appears between them has a
// position at the earlier one too (where it enters), so it glides in from there. Each keyframe was relaxed as
// a whole, so densities between levels are good blue noise too, and points still appear in rank order.
//
// The file: a 64-byte header with magic, version, sizes and two CRC-32s (TilesetHeader), the recipe and
// generator version texts, then one zstd frame holding a cereal portable-binary archive of the TilesetData.
// Every byte is described, once, in docs/tileset-format.md.
//
// Thread safety: every function here is reentrant; a TilesetData is a plain value (share it read-only).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "kdm/runtime/allocator.h"
#include "kdm/runtime/export.h"
#include "kdm/runtime/status.h"
#include "kdm/runtime/subdivision.h"
#include "kdm/runtime/version.h"

namespace kdm {

/// Reader caps: files beyond them are refused before anything is allocated.
inline constexpr std::uint64_t kMaxTilesetPayloadBytes = 512ull << 20;  ///< decompressed payload
inline constexpr std::uint32_t kMaxTilesetHeaderBytes = 1u << 20;
inline constexpr std::uint32_t kMaxTileColours = 16;  ///< at most 16^4 = 65536 tiles
inline constexpr std::uint32_t kMaxTileLevels = 16;
inline constexpr std::uint32_t kMaxKeyframes = 256;
inline constexpr std::uint32_t kMaxHandoverSlack = 16;  ///< TilesetShape::handover_slack

/// Glide offsets count in 1/kGlideUnitsPerSpacing of a keyframe's square-grid spacing 1/√K (8 bits: up to
/// ±3.97 spacings, in steps of 0.03 of the point spacing).
inline constexpr double kGlideUnitsPerSpacing = 32;

/// A point's position inside its tile in units of 1/65536 of the tile side: x, y in [0, 65536).
struct TilePoint {
  std::uint16_t x = 0, y = 0;
  /// The point for unit-square coordinates u, v in [0, 1) (floored to the 1/65536 grid, clamped).
  static TilePoint from_unit(double u, double v) { return {quantise(u), quantise(v)}; }
  /// Unit-square position of the grid cell's centre, in [0, 1).
  double unit_x() const { return (x + 0.5) * (1.0 / 65536.0); }
  double unit_y() const { return (y + 0.5) * (1.0 / 65536.0); }
  static std::uint16_t quantise(double u) {
    const double t = u * 65536.0;
    return static_cast<std::uint16_t>(t <= 0 ? 0.0 : (t >= 65535.0 ? 65535.0 : t));
  }
  friend bool operator==(const TilePoint& a, const TilePoint& b) { return a.x == b.x && a.y == b.y; }
};

struct Tile {
  /// Sorted by (level, key): the array index is the point's rank within the whole pyramid.
  TilesetArray<TilePoint> points;
  /// Emission key of each point within its level (see the top of this file); non-decreasing per level.
  TilesetArray<std::uint16_t> keys;
  /// level_end[k] = number of points in levels 0..k; non-decreasing; level_end.back() == points.size().
  TilesetArray<std::uint32_t> level_end;
  /// Glide offsets (x, y pairs from the point's stable position, in TilesetShape::glide_unit(g) tile
  /// sides): keyframe 0's for ranks [0, count_0), then keyframe 1's for [0, count_1), …, where count_g is
  /// TilesetShape::offsets_at_keyframe (the points present at keyframe g or appearing before the next
  /// one). Empty without a glide track.
  TilesetArray<std::int8_t> glide;
  /// The hand-over between depths (sets whose handover_zone is not 0; else empty): per rank, the sub-point
  /// the point glides onto past the top keyframe, as q · 25 + (dy + 2) · 5 + (dx + 2): rank q of the
  /// subtile (dx, dy) away from the one holding the point's stable position (TilesetShape::subtile_of).
  /// So q ≤ kMaxHandoverRank.
  TilesetArray<std::uint16_t> handover;
  static constexpr std::uint32_t kMaxHandoverRank = (65535 - 24) / 25;  ///< 2620
  /// The subtiles' points present at their keyframe 1 that no point glides onto, in the order they appear
  /// during the hand-over: (j << 16) | q, rank q of subtile j = row · m + column (row 0 at the south).
  TilesetArray<std::uint32_t> appearing;
  /// The level of the point at `rank` (< points.size()): the first k with rank < level_end[k].
  std::uint32_t level_of(std::uint32_t rank) const {
    std::uint32_t k = 0;
    while (k + 1 < level_end.size() && rank >= level_end[k]) ++k;
    return k;
  }
  friend bool operator==(const Tile& a, const Tile& b) {
    return a.points == b.points && a.keys == b.keys && a.level_end == b.level_end && a.glide == b.glide &&
           a.handover == b.handover && a.appearing == b.appearing;
  }
};

/// What a tile set's tiles fit into: its corner colours, and how many points per tile each level and each
/// keyframe holds, with the rules that turn a point's level and key into the expected count where it
/// appears. The baker works with it before any tile exists; TilesetData adds the tiles.
struct TilesetShape {
  std::uint32_t colours = 0;  ///< corner colours C; C^4 tiles
  std::uint32_t levels = 0;   ///< pyramid levels per tile
  /// Nominal points per tile in levels 0..k (the count a tile of uniform density has on average);
  /// strictly increasing, positive. Emission thresholds are placed between these.
  TilesetArray<std::uint32_t> level_nominal;
  /// The keyframes of the glide track: nominal points per tile at each, strictly increasing, the last one
  /// the top level's. Empty: the set has no glide track (smooth queries then emit stable positions).
  TilesetArray<std::uint32_t> keyframe_nominal;
  /// The hand-over's corner squares and edge bands, in sub-steps (kdm/runtime/subdivision.h); 0: the set
  /// has no hand-over, and no density beyond its top level.
  std::uint32_t handover_zone = 0;
  /// The level j of the subtiles the hand-over glides onto (format 6; 0 in older files): a depth's
  /// subtiles then never show fewer points than their first keyframe above N_j.
  std::uint32_t handover_level = 0;
  /// Keyframes past the subtiles' first above N_j at which they are handed over (format 7; 0 in older
  /// files): with 2 their points present there outnumber the tile's by a fifth instead of a twentieth,
  /// and every glide but the longest has arrived before the subtiles' own points enter (docs/design.md
  /// §3, "Slack").
  std::uint32_t handover_slack = 0;

  /// Subtiles per tile side in the hand-over: m with m² · N_j = N_top, j = handover_level (0 if there is
  /// no such integer).
  std::uint32_t subtiles_per_side() const {
    if (handover_level + 1 >= level_nominal.size()) return 0;
    const std::uint32_t n_j = level_nominal[handover_level];
    const auto m = static_cast<std::uint32_t>(std::lround(std::sqrt(double(level_nominal.back()) / n_j)));
    return std::uint64_t(m) * m * n_j == level_nominal.back() ? m : 0;
  }
  Subdivision subdivision() const { return {colours, subtiles_per_side(), handover_zone}; }
  /// The hand-over keyframe h: handover_slack keyframes past the subtiles' first keyframe above N_j (at
  /// least 1), where they stand when a point glides onto them; their points present there are the ones
  /// their parent hands over.
  std::size_t handover_keyframe() const {
    if (handover_level >= level_nominal.size()) return 1 + handover_slack;
    const auto* k = keyframe_nominal.data();
    const auto above = std::upper_bound(k, k + keyframe_nominal.size(), level_nominal[handover_level]) - k;
    return std::max<std::size_t>(1, static_cast<std::size_t>(above)) + handover_slack;
  }
  /// The hand-over past the top level, in points per tile (docs/design.md §3, "Unbounded zoom"): the
  /// sub-points no point glides onto have appeared by appearing_end() = m² K_h (h = handover_keyframe()),
  /// and a point whose glide onto its sub-point is `glide` square-grid spacings (1/√N_top) long is taken
  /// over by its subtile at handover_end(glide), m² K_h or later for a long glide.
  double appearing_end() const {
    const double m = subtiles_per_side();
    const std::size_t h = handover_keyframe();
    return h >= keyframe_nominal.size() ? 0.0 : m * m * keyframe_nominal[h];
  }
  /// A glide of `glide` spacings spans at least glide / kHandoverSpacingsPerKeyframe of the top keyframe
  /// intervals (its ratio of counts), so that no glide moves faster with the scale than the keyframes'
  /// points (99th percentile about 0.6 of a spacing per interval).
  static constexpr double kHandoverSpacingsPerKeyframe = 0.5;
  double handover_end(double glide) const {
    const std::size_t n = keyframe_nominal.size();
    if (n < 2) return 0.0;
    const double top = keyframe_nominal[n - 1];
    return std::max(appearing_end(),
                    top * std::pow(top / keyframe_nominal[n - 2], glide / kHandoverSpacingsPerKeyframe));
  }
  /// The subtile (column, row) of m per side holding a stable position.
  static std::uint32_t subtile_of(std::uint16_t coordinate, std::uint32_t m) {
    return static_cast<std::uint32_t>((std::uint64_t(coordinate) * m) >> 16);
  }

  /// The expected point count per tile above which a point of `level` > 0 with key `key` is emitted, in
  /// the float precision the runtime stores it in (4 bytes per point). Level 0's as the baker assigns
  /// them; queries spread them over the set's tiles first (coarsest_level_thresholds).
  float emission_threshold(std::uint32_t level, std::uint16_t key) const {
    const double lo = level == 0 ? 0.0 : level_nominal[level - 1], hi = level_nominal[level];
    return static_cast<float>(lo + (double(key) + 0.5) * (1.0 / 65536.0) * (hi - lo));
  }
  /// The emission rule, stated once for the runtime and the generator test: a point with threshold
  /// `threshold` is emitted where its tile's expected point count is `expected` iff expected > threshold.
  static bool emits(float threshold, double expected) { return expected > static_cast<double>(threshold); }
  /// The unit of keyframe g's glide offsets in tile sides: 1 / (kGlideUnitsPerSpacing · √K_g).
  double glide_unit(std::size_t g) const {
    return 1.0 / (kGlideUnitsPerSpacing * std::sqrt(double(keyframe_nominal[g])));
  }
  /// How many of `tile`'s points are present at keyframe g (threshold < K_g: a prefix of its ranks).
  std::uint32_t points_at_keyframe(const Tile& tile, std::size_t g) const {
    std::uint32_t lo = 0, hi = static_cast<std::uint32_t>(tile.points.size());
    while (lo < hi) {  // thresholds grow with rank
      const std::uint32_t mid = lo + (hi - lo) / 2;
      if (emits(emission_threshold(tile.level_of(mid), tile.keys[mid]), keyframe_nominal[g]))
        lo = mid + 1;
      else
        hi = mid;
    }
    return lo;
  }
  /// How many glide offsets `tile` stores at keyframe g: one per point present there or appearing before
  /// the next keyframe (it glides in from its position here); every point at the last keyframe. A prefix
  /// of its ranks.
  std::uint32_t offsets_at_keyframe(const Tile& tile, std::size_t g) const {
    return g + 1 < keyframe_nominal.size() ? points_at_keyframe(tile, g + 1)
                                           : static_cast<std::uint32_t>(tile.points.size());
  }
  /// The index of the tile with corner colours (sw, se, ne, nw).
  std::size_t tile_index(std::uint32_t sw, std::uint32_t se, std::uint32_t ne, std::uint32_t nw) const {
    return ((std::size_t(sw) * colours + se) * colours + ne) * colours + nw;
  }
  /// The index of the tile that subtile (i, j) (column, row from the south-west, 0 ≤ i, j < m) of tile
  /// `tile` shows in the hand-over: its corners' colours by Subdivision::vertex_colour.
  std::size_t subtile_index(std::size_t tile, std::uint32_t i, std::uint32_t j) const {
    const Subdivision sub = subdivision();
    const std::size_t C = colours;
    const auto sw = std::uint32_t(tile / C / C / C), se = std::uint32_t(tile / C / C % C),
               ne = std::uint32_t(tile / C % C), nw = std::uint32_t(tile % C);
    return tile_index(sub.vertex_colour(sw, se, ne, nw, i, j), sub.vertex_colour(sw, se, ne, nw, i + 1, j),
                      sub.vertex_colour(sw, se, ne, nw, i + 1, j + 1),
                      sub.vertex_colour(sw, se, ne, nw, i, j + 1));
  }
  friend bool operator==(const TilesetShape& a, const TilesetShape& b) {
    return a.colours == b.colours && a.levels == b.levels && a.level_nominal == b.level_nominal &&
           a.keyframe_nominal == b.keyframe_nominal && a.handover_level == b.handover_level &&
           a.handover_zone == b.handover_zone;
  }
};

/// A tile set as the file holds it: its shape, its tiles and where it came from.
struct TilesetData : TilesetShape {
  TilesetArray<Tile> tiles;       ///< index tile_index(sw, se, ne, nw)
  std::string recipe;             ///< the recipe text that rebuilds this set exactly
  std::string generator_version;  ///< the kdm version that baked it

  friend bool operator==(const TilesetData& a, const TilesetData& b) {
    return static_cast<const TilesetShape&>(a) == static_cast<const TilesetShape&>(b) && a.tiles == b.tiles &&
           a.recipe == b.recipe && a.generator_version == b.generator_version;
  }
};

/// What a tile-set file's header says (its fields in docs/tileset-format.md §1), once validated.
struct TilesetHeader {
  std::uint32_t format_version = 0;                  ///< kOldestTilesetFormatVersion to kTilesetFormatVersion
  std::uint32_t header_bytes = 0;                    ///< where the payload starts
  std::uint64_t payload_bytes = 0;                   ///< the zstd frame's size in the file
  std::uint64_t decompressed_bytes = 0;              ///< the payload's size once decompressed
  std::uint32_t payload_crc = 0;                     ///< CRC-32 of the payload bytes as stored
  std::uint32_t tiles = 0, colours = 0, levels = 0;  ///< as the payload holds them (checked against it)
  std::string recipe, generator_version;             ///< the recipe that rebakes it, the kdm that baked it
};

/// Reads and validates the header of a tile-set file of `size` bytes at `data` (the whole file: its size
/// is checked against the header's): magic, version, sizes, the header's CRC, the text sizes and the
/// tile, colour and level counts, before anything else is read. The payload is not decompressed or
/// checked (decode_tileset does both). Returns kOk, or the first problem: kTruncated, kBadMagic,
/// kUnsupportedVersion, kHeaderChecksumMismatch, kTooLarge (a size past the caps), kTrailingBytes or
/// kInvalidContent (counts out of range), with `detail` (optional); on failure `out` is left empty.
KDM_RUNTIME_API Status read_tileset_header(const void* data, std::size_t size, TilesetHeader& out,
                                           std::string* detail = nullptr);

/// Every tile's coarsest-level emission thresholds, rank by rank, as queries compare them
/// (TilesetShape::emits; above that level they are emission_threshold's). The level's keys are ranked
/// patch by patch, each patch's points at the middles of its own shares of (0, N_0], so a small patch's
/// first point comes late: over the built-in set's tiles a tile emitted on average 3.1 points where 4
/// were expected, 7.4 for 8, 14.8 for 16. Here the level's P thresholds of all T tiles are put in order
/// (by threshold; equal ones a tile's first, then its second, …, tile by tile, so that no tile takes a
/// run of them before the others) and the i-th becomes N_0 · (i + ½) / P. Over the tiles, which the
/// world shows equally often, a tile then emits on average the expected count times P / (T · N_0), the
/// level's own share at N_0 (0.994 for the built-in set), at every density below N_0, and no tile more
/// than one point more than another where their thresholds were alike. Within a tile the thresholds
/// stay non-decreasing, and a patch's points, whose thresholds differ, keep their order.
KDM_RUNTIME_API std::vector<std::vector<float>> coarsest_level_thresholds(const TilesetData& set);

/// Checks the structural invariants above (colour and level caps, tile count, level tables, nominal
/// counts, one key per point, keys sorted within each level, keyframes increasing up to the top level,
/// one glide offset pair per point present at each keyframe).
/// Returns kOk or kInvalidContent with `detail` (optional) naming the first problem; kOutOfMemory when the
/// tile-set allocator refuses the hand-over check's scratch.
KDM_RUNTIME_API Status validate_tileset(const TilesetData& set, std::string* detail = nullptr);

/// The format version encode_tileset writes `set` in: the oldest that holds it, so that older readers keep
/// reading them: 4 for a set without a hand-over, 5 for one onto the subtiles' level 0, 6 onto a finer
/// level, 7 with a hand-over slack.
KDM_RUNTIME_API std::uint32_t tileset_format_version_for(const TilesetShape& set);

/// Encodes `set` into `out` (replaced). Returns kOk; kInvalidArgument if validate_tileset fails, the
/// header with its texts would pass kMaxTilesetHeaderBytes, or zstd fails; kTooLarge for a payload past
/// kMaxTilesetPayloadBytes.
KDM_RUNTIME_API Status encode_tileset(const TilesetData& set, std::vector<std::uint8_t>& out,
                                      std::string* detail = nullptr);

/// Decodes a tile set from `size` bytes at `data` (untrusted input: every size, count and checksum is
/// checked before use; nothing is allocated beyond the caps). The body is parsed as zstd decompresses it,
/// a chunk at a time, and never held whole: what a decode holds besides the set's arrays is zstd's window
/// (the frame's, at most the body's size), all of it through the tile-set allocator (allocator.h).
/// Returns kOk, read_tileset_header's statuses, kPayloadChecksumMismatch, kDecompressionFailed,
/// kInvalidContent (validate_tileset's, or a payload that does not parse) or kOutOfMemory (the allocator
/// refused a request), with `detail` (optional). On failure `out` is left empty.
KDM_RUNTIME_API Status decode_tileset(const void* data, std::size_t size, TilesetData& out,
                                      std::string* detail = nullptr);

/// Reads the bytes of the tile-set file at `path` into `bytes`, for read_tileset_header and decode_tileset
/// to judge: its fixed header, then no more than that header says the file holds (a payload size past any
/// payload's: up to that bound), and one byte past it (an endless or huge input stops at its header or at
/// that bound), so a file gives the statuses its bytes give in memory. kIoError, with `detail`, when the path
/// cannot be opened or read or is a directory; else kOk, whatever the bytes are.
KDM_RUNTIME_API Status read_tileset_file(const std::string& path, std::vector<char>& bytes,
                                         std::string* detail = nullptr);

/// Reads (read_tileset_file, into memory from the tile-set allocator) and decodes the file at `path`:
/// read_tileset_file's and decode_tileset's statuses, and kOutOfMemory where the file's bytes are refused.
KDM_RUNTIME_API Status load_tileset(const std::string& path, TilesetData& out, std::string* detail = nullptr);

/// Whether a tile set can be saved at `path`: not a directory, and its temporary file (`path` + ".partial")
/// can be created there (it is created and removed), unless `path` is a device or a pipe. Returns kOk, or
/// kIoError with `detail` (optional) naming the problem. save_tileset checks it first; call it before work
/// whose result is to be saved.
KDM_RUNTIME_API Status check_tileset_path(const std::string& path, std::string* detail = nullptr);

/// Encodes and writes `set` to `path` atomically: a temporary file in the same directory, then rename,
/// so an interrupted save never leaves a damaged file at `path`; a device or a pipe at `path` (/dev/null,
/// a FIFO) is written into, as a shell's > does. Checks `path` (check_tileset_path)
/// before encoding. Returns kOk, check_tileset_path's kIoError, encode_tileset's statuses, or kIoError
/// when writing or renaming fails.
KDM_RUNTIME_API Status save_tileset(const TilesetData& set, const std::string& path,
                                    std::string* detail = nullptr);

}  // namespace kdm
