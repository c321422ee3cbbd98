// Real-time blue noise from a baked tile set: the points of a region for a spatially varying density.
//
// World space is tiled by squares of side `tile_size`; tile (tx, ty) covers [tx·S, (tx+1)·S) × [ty·S,
// (ty+1)·S) and shows the set's tile chosen by the colours of its four corners (a hash of the corner's
// integer coordinates, so any region is assembled locally). A tile's points are sorted by rank; point c of a
// tile of area A is emitted iff ρ(x_c) · A · scale > t_c, its emission threshold (tileset.h: about c + ½,
// but equal for the points that neighbouring tiles share, so mid-level densities have no seams). Density
// responds continuously, raising the scale only adds points (zoom coherence), and every decision depends
// only on the point's canonical tile coordinates, so query(A ∪ B) = query(A) ⊎ query(B) bit for bit.
//
// Two emission modes (QueryMode): stable, where a point sits at one position from the density it appears
// at on, and smooth, where points glide with the density between the set's keyframes (tileset.h), so every
// density is a good blue-noise set. Both emit the same points (the same ids at the same densities); in
// smooth mode the expected count that decides emission, taken at the point's stable position, also sets
// where it glides to, so chunk consistency and determinism hold the same way. One exception to "the same
// points": a smooth point whose glided position has zero density is not emitted, so no point shows where
// the density is zero (it could glide up to a spacing past a sharp edge of the density).
//
// Thread safety: a Tileset is immutable after loading; any number of threads may query it at once.
// Queries allocate nothing, take no locks and touch no global state.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "kdm/runtime/tileset.h"

namespace kdm {

/// How a point glides at an expected count c per tile between keyframes K_g0 ≤ c ≤ K_g1: its offset is
/// o_g0 · (1 − t) · scale0 + o_g1 · t · scale1 with t = (c − base) · inverse_gap, in 1/65536 tile sides.
/// Below the first keyframe and above the last g0 = g1 and t = 0: no motion there.
struct GlideSpan {
  std::uint32_t g0 = 0, g1 = 0;
  double base = 0, inverse_gap = 0;  ///< K_g0 and 1 / (K_g1 − K_g0) (0 when g0 = g1)
  double scale0 = 0, scale1 = 0;     ///< Tileset::glide_scale of g0 and g1
};

/// A loaded tile set, ready for queries (immutable).
class KDM_RUNTIME_API Tileset {
 public:
  /// Loads and validates a file / memory buffer (untrusted input; see decode_tileset). On failure the
  /// returned status says why, `detail` (optional) says more, and `out` is left empty.
  static Status load_file(const std::string& path, Tileset& out, std::string* detail = nullptr);
  static Status load_memory(const void* data, std::size_t size, Tileset& out, std::string* detail = nullptr);
  /// The default tile set compiled into the library (tilesets/default.kdmt). Thread-safe. It is decoded on
  /// the first call, which takes about 0.1 s (docs/performance.md): call it once at start-up to
  /// keep that out of a frame. The C API's kdm_tileset_builtin() shares this copy.
  static const Tileset& builtin();

  const TilesetData& data() const { return set_; }
  bool empty() const { return set_.tiles.empty(); }
  /// The expected points per tile at which every tile has emitted all its points (the nominal count of
  /// the top pyramid level): the density limit is this per tile area.
  std::uint32_t max_points_per_tile() const {
    return set_.level_nominal.empty() ? 0 : set_.level_nominal.back();
  }
  /// Index into data().tiles of the tile shown at tile coordinates (tx, ty). Thread-safe.
  std::size_t tile_index_at(std::int64_t tx, std::int64_t ty) const;
  const Tile& tile_at(std::int64_t tx, std::int64_t ty) const { return set_.tiles[tile_index_at(tx, ty)]; }
  /// Emission thresholds of tile `index`'s points (TilesetData::emission_threshold), non-decreasing.
  const float* thresholds(std::size_t index) const { return thresholds_[index].data(); }
  /// The lowest threshold of any point: below it no tile emits anything.
  double min_threshold() const { return min_threshold_; }
  /// Whether the set has a gliding track (smooth queries then glide; without one they emit stable
  /// positions).
  bool has_glide() const { return !set_.keyframe_nominal.empty(); }
  /// Tile `index`'s start of each keyframe's offsets in Tile::glide, in offset pairs (keyframes + 1
  /// entries: keyframe g's pairs are [start[g], start[g + 1]), one per rank below keyframe_count).
  const std::uint32_t* glide_start(std::size_t index) const { return glide_start_[index].data(); }
  /// The largest distance any point glides from its stable position, per axis, in tile sides, at keyframe
  /// g or at any: smooth queries look this far beyond their region for points that glide into it.
  double glide_reach(std::size_t g) const { return glide_reach_[g]; }
  double glide_reach() const {
    double r = 0;
    for (double v : glide_reach_) r = std::max(r, v);
    return r;
  }
  /// The largest of glide_reach(g') for g' >= g.
  double glide_reach_from(std::size_t g) const { return glide_reach_from_[g]; }
  /// Per keyframe g, how many of the tile's points are present there (TilesetData::keyframe_count).
  const std::uint32_t* keyframe_ranks(std::size_t index) const { return keyframe_ranks_[index].data(); }
  /// Per keyframe, 1/65536 tile sides per glide offset unit (65536 · TilesetData::glide_unit(g)).
  const double* glide_scale() const { return glide_scale_.data(); }
  /// The keyframe counts K_g as doubles, then +∞ (keyframes + 1 entries): searches stop without a bound.
  const double* keyframe_counts() const { return keyframe_counts_.data(); }
  /// Per g = first_keyframe_at_least(count) (keyframes + 1 entries), how a count there glides.
  const GlideSpan* glide_spans() const { return glide_spans_.data(); }
  /// Smooth mode: the ranks of tile `index`'s points that can glide across its side `side` (0: x = 0,
  /// 1: x = 1, 2: y = 0, 3: y = 1), ascending; `count` receives how many. A point is listed when its
  /// stable position lies within glide_reach_from(the keyframe it appears after) · 65536 + kEdgeSlack
  /// position units of that side, so a tile beside a region is scanned through one list, not in full.
  const std::uint32_t* edge_ranks(std::size_t index, int side, std::uint32_t& count) const {
    const std::uint32_t* start = edge_start_.data() + 5 * index;
    count = start[side + 1] - start[side];
    return edge_ranks_[index].data() + start[side];
  }
  /// Position units (1/65536 tile side) edge_ranks adds to each point's reach, for rounding.
  static constexpr double kEdgeSlack = 8;
  /// The first keyframe whose count is at least `expected` (> 0), or the keyframe count if none: a table
  /// lookup on the number's exponent and leading bits, then a step or two.
  std::uint32_t first_keyframe_at_least(double expected) const;
  /// Its table: per bucket of counts (32 per power of two from 2^-32 to 2^32, by the double's exponent and
  /// leading mantissa bits), the first keyframe at least the bucket's smallest count; null if not loaded.
  const std::uint16_t* keyframe_guess() const {
    return keyframe_guess_.empty() ? nullptr : keyframe_guess_.data();
  }
  /// Whether one step from keyframe_guess() always finds first_keyframe_at_least (true when consecutive
  /// keyframes are over 3.1% apart, as in baked sets).
  bool keyframe_one_step() const { return keyframe_one_step_; }
  /// Heap bytes this tile set holds once loaded (positions, keys, level tables, per-point emission
  /// thresholds, recipe text), not counting allocator overhead. The builtin set's decoded copy is the
  /// same size; its compressed bytes in the library's data section are extra. Thread-safe.
  std::size_t resident_bytes() const;

 private:
  void adopt(TilesetData&& set);
  void index_edges();  ///< edge_ranks_ and edge_start_, from the glide tables adopt has built
  TilesetData set_;
  TilesetArray<TilesetArray<float>> thresholds_;
  TilesetArray<TilesetArray<std::uint32_t>> glide_start_;
  double min_threshold_ = 0;
  TilesetArray<double> glide_reach_;
  TilesetArray<double> glide_reach_from_;
  TilesetArray<double> glide_scale_;
  TilesetArray<TilesetArray<std::uint32_t>> keyframe_ranks_;
  TilesetArray<std::uint16_t> keyframe_guess_;  ///< first_keyframe_at_least per count_bucket
  bool keyframe_one_step_ = false;
  TilesetArray<double> keyframe_counts_;
  TilesetArray<GlideSpan> glide_spans_;
  TilesetArray<TilesetArray<std::uint32_t>> edge_ranks_;  ///< per tile, its four sides' lists in turn
  TilesetArray<std::uint32_t> edge_start_;                ///< per tile, 5 offsets into its edge_ranks_
};

/// A point's stable identity: its tile and its rank there (the level follows from the rank).
struct PointId {
  std::int64_t tile_x = 0, tile_y = 0;
  std::uint32_t rank = 0;
  friend bool operator==(const PointId& a, const PointId& b) {
    return a.tile_x == b.tile_x && a.tile_y == b.tile_y && a.rank == b.rank;
  }
};

struct QueryPoint {
  double x = 0, y = 0;  ///< world position minus the query origin
  PointId id;
};

/// A density image over a world rectangle: bilinear between texel centres, clamped at the edges.
/// Values must be finite and >= 0 (validated by make_density_max_mip). Built once, shared read-only.
struct KDM_RUNTIME_API DensityImageView {
  int width = 0, height = 0;
  double x0 = 0, y0 = 0, x1 = 1, y1 = 1;  ///< world rectangle covered; row 0 at y0
  const float* values = nullptr;          ///< width·height, row-major, owned by the caller
  const float* max_mip = nullptr;         ///< per 8×8 texel block maximum (see make_density_max_mip)
  const float* min_mip = nullptr;         ///< per 8×8 texel block minimum (optional: null means 0)
  int mip_width = 0, mip_height = 0;
  double at(double x, double y) const;
  /// Upper bound of the density over a world rectangle (from the max-mip; exact bound, maybe loose).
  double max_over(double x0, double y0, double x1, double y1) const;
  /// Lower bound of the density over a world rectangle (from the min-mip; 0 without one).
  double min_over(double x0, double y0, double x1, double y1) const;
};

/// Fills `mip` (resized to 2·ceil(w/8)·ceil(h/8)) with the 8×8 block maxima of `image.values`, then their
/// minima, each block widened by one texel so they bound bilinear values too, and points the image's
/// max_mip and min_mip at them. Returns kInvalidArgument for empty images or values that are negative or
/// not finite.
KDM_RUNTIME_API Status make_density_max_mip(DensityImageView& image, std::vector<float>& mip);

/// The density of a query: constant, an image, or a callback (called once per candidate point, and in
/// smooth mode once more at each emitted point's glided position, with world coordinates; must be
/// thread-safe if queries run concurrently). Negative, NaN and infinite values
/// from a callback are treated as 0 (documented: a bad value never emits points or crashes).
struct QueryDensity {
  enum class Kind { kConstant, kImage, kCallback } kind = Kind::kConstant;
  double constant = 1;
  const DensityImageView* image = nullptr;
  double (*callback)(void* user, double x, double y) = nullptr;
  void* user = nullptr;
  /// For callbacks: an upper bound of the density (lets the query skip ranks that can never be emitted).
  double callback_max = 1;
};

/// How emitted points move as the density changes.
enum class QueryMode : int {
  /// A point never moves once it appears: for placing objects that must not shift when the density or the
  /// level of detail changes. The sets are nested, so densities between the tile set's levels (×4 apart)
  /// are poorer blue noise than the levels themselves (docs/quality.md).
  kStable = 0,
  /// Points glide continuously with the density (never jump), so every density is a good blue-noise set:
  /// for stippling and sample patterns. Ids, emission densities and zoom coherence by id are those of
  /// stable mode, except that no point shows where the density is zero. A tile set without a gliding
  /// track emits its stable positions.
  kSmooth = 1,
};

struct QueryParams {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;  ///< half-open world region [x0, x1) × [y0, y1)
  double origin_x = 0, origin_y = 0;      ///< subtracted from every output position
  double tile_size = 1;                   ///< world units per tile side
  double scale = 1;                       ///< points per unit area at density 1
  QueryDensity density;
  QueryMode mode = QueryMode::kStable;
};

/// Most tiles one query may cover (2^24): a bound on the work of a single call, whatever the region.
/// Larger regions are refused (kInvalidArgument); split them.
inline constexpr std::uint64_t kMaxQueryTiles = std::uint64_t(1) << 24;

/// Most candidate points one call examines (2^24, a few milliseconds): a call that reaches it returns
/// kBufferFull with the cursor saved, even if the buffer has room, so no call runs unbounded.
inline constexpr std::uint64_t kMaxQueryCandidates = std::uint64_t(1) << 24;

/// Where a query stopped, so a full buffer can be resumed. Zero-initialise before the first call; a cursor
/// belongs to the parameters of the call that started it (their fingerprint), and is refused with others.
struct QueryCursor {
  std::int64_t tile_x = 0, tile_y = 0;
  std::uint32_t rank = 0;
  bool started = false, finished = false;
  std::uint64_t fingerprint = 0;  ///< of the parameters that started it (query_fingerprint)
};

/// Why query_points returned kInvalidArgument: which parameter and, for a limit, the limit and the
/// largest value that passes (Detour-style detail, in plain values: nothing is allocated).
struct QueryProblem {
  enum class Kind : int {
    kNone = 0,         ///< no problem
    kMissingArgument,  ///< `parameter` ("written", "cursor", "out", "tileset") is null or empty
    kNotFinite,        ///< `parameter` is NaN or infinite; `value` holds it
    kNotPositive,      ///< `parameter` ("tile_size") must be > 0; `value` holds it
    kNegative,         ///< `parameter` ("scale", "density.callback_max") must be >= 0; `value` holds it
    kBadDensity,       ///< `parameter` ("density.image", "density.callback") is missing or not prepared
    kTooManyTiles,     ///< the region covers `value` tiles, more than `limit` (kMaxQueryTiles): split it
    kDensityTooHigh,   ///< `value` expected points per tile exceed `limit` (max_points_per_tile):
                       ///< `largest_valid` is the largest scale that fits, `largest_tile_size` the
                       ///< largest tile size that fits this scale
    kCursorMismatch,   ///< the cursor was started by a call with other parameters (or damaged)
    kBadMode,          ///< `parameter` ("mode") is not a QueryMode; `value` holds it
  };
  Kind kind = Kind::kNone;
  const char* parameter = "";  ///< the QueryParams field (or argument) at fault; static storage
  double value = 0, limit = 0, largest_valid = 0, largest_tile_size = 0;
};

/// A short English description of a problem kind (static storage).
KDM_RUNTIME_API const char* query_problem_message(QueryProblem::Kind kind);

/// A hash of every field of `params` (their bits, and the image and callback pointers): the identity a
/// cursor keeps of the call that started it.
KDM_RUNTIME_API std::uint64_t query_fingerprint(const QueryParams& params);

/// Writes the region's points into `out[0..capacity)` in a fixed order (tiles row by row, ranks
/// ascending); `*written` receives the count, and slots from there to capacity may be overwritten too (a
/// candidate is written before it is known to be kept). Returns kOk when the region is complete (a finished
/// cursor called again with the same params gives kOk and no points), kBufferFull when `out` filled up first
/// or the call examined kMaxQueryCandidates points — call again with the same cursor and params to continue.
/// Empty or inverted regions and scale 0 give no points. kInvalidArgument, with `problem` (optional)
/// saying which parameter and limit, for: null arguments, non-finite params, tile_size <= 0, a negative
/// scale, a missing image or callback, a region of more than kMaxQueryTiles tiles, a density beyond the
/// tile set's top level (scale · max density · tile_size² > max_points_per_tile: use smaller tiles or a
/// lower scale), or a cursor started with other params. No allocation.
KDM_RUNTIME_API Status query_points(const Tileset& tileset, const QueryParams& params, QueryPoint* out,
                                    std::size_t capacity, std::size_t* written, QueryCursor* cursor,
                                    QueryProblem* problem = nullptr);

}  // namespace kdm
