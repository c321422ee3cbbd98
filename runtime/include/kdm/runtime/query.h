// Real-time blue noise from a baked tile set: the points of a region for a spatially varying density.
//
// World space is tiled by squares of side `tile_size`; tile (tx, ty) covers [tx·S, (tx+1)·S) × [ty·S,
// (ty+1)·S) and shows the set's tile chosen by the colours of its four corners (a hash of the corner's
// integer coordinates, so any region is assembled locally). A tile's points are sorted by rank; point c of a
// tile of area A is emitted iff ρ(x_c) · A · scale > t_c, its emission threshold (tileset_format.h: about c +
// ½, but equal for the points that neighbouring tiles share, so mid-level densities have no seams). Density
// responds continuously, raising the scale only adds points (zoom coherence), and every decision depends
// only on the point's canonical tile coordinates, so query(A ∪ B) = query(A) ⊎ query(B) bit for bit.
//
// Two emission modes (QueryMode): stable, where a point sits at one position from the density it appears
// at on, and smooth, where points glide with the density between the set's keyframes (tileset_format.h), so
// every density is a good blue-noise set. Both emit the same points (the same ids at the same densities); in
// smooth mode the expected count that decides emission, taken at the point's stable position, also sets
// where it glides to, so chunk consistency and determinism hold the same way. One exception to "the same
// points": a smooth point whose glided position has zero density is not emitted, so no point shows where
// the density is zero (it could glide up to a spacing past a sharp edge of the density).
//
// Thread safety: a Tileset is immutable after loading; any number of threads may query it at once.
// Queries allocate nothing, take no locks and touch no global state.
#pragma once

#include <cstddef>
#include <cstdint>

#include "kdm/runtime/density_image.h"
#include "kdm/runtime/export.h"
#include "kdm/runtime/status.h"
#include "kdm/runtime/tileset.h"

namespace kdm {

/// A point's stable identity: its tile and its rank there (the level follows from the rank). Past the
/// top level (smooth mode, sets with a hand-over) points come from subtiles: at depth d the tile grid is
/// m^d times finer (m = TilesetShape::subtiles_per_side), so (tile_x, tile_y) index tiles of side
/// tile_size / m^d; a point that glides from a tile onto a subtile's point keeps the tile's id.
struct PointId {
  std::int64_t tile_x = 0, tile_y = 0;
  std::uint32_t rank = 0;
  std::uint32_t depth = 0;  ///< 0 for the tiles of side tile_size; at most kMaxQueryDepth
  friend bool operator==(const PointId& a, const PointId& b) {
    return a.tile_x == b.tile_x && a.tile_y == b.tile_y && a.rank == b.rank && a.depth == b.depth;
  }
};

/// One emitted point.
struct QueryPoint {
  double x = 0, y = 0;  ///< world position minus the query origin
  PointId id;           ///< the same in every query that emits the point (key instances on it)
};

/// The density of a query: constant, an image, or a callback (called once per candidate point, and in
/// smooth mode once more at each emitted point's glided position, with world coordinates; must be
/// thread-safe if queries run concurrently). Negative, NaN and infinite values
/// from a callback are treated as 0 (documented: a bad value never emits points or crashes).
struct QueryDensity {
  enum class Kind { kConstant, kImage, kCallback } kind = Kind::kConstant;  ///< which of the fields below
  double constant = 1;  ///< kConstant: finite and >= 0, or the query is refused
  /// kImage: the image with its mips (make_density_max_mip), outliving the query; values as `constant`'s.
  const DensityImageView* image = nullptr;
  /// kCallback: the density at world (x, y) (set this or batch_callback).
  double (*callback)(void* user, double x, double y) = nullptr;
  /// For callbacks, instead of `callback` (set one of the two): the densities at n positions at once,
  /// out[i] at (x[i], y[i]), 1 ≤ n ≤ kDensityBatch, with callback's rules (thread-safe, values that are
  /// not finite and ≥ 0 count as 0). A query gathers each tile's (and past the top level each
  /// subtile's) reads into such batches, so a vectorised function (SIMD, numpy) pays one call per batch;
  /// past the top level, where one value decides which the next is, the points the subtiles' ancestors
  /// hold are read a block of ranks ahead, in several smaller batches (about 50 positions a call). The
  /// points are those of `callback` giving the same values (18 KiB more stack past the top level).
  void (*batch_callback)(void* user, std::size_t n, const double* x, const double* y, double* out) = nullptr;
  void* user = nullptr;  ///< passed to callback, batch_callback and bounds
  /// For callbacks: an upper bound of the density (lets the query skip ranks that can never be emitted).
  /// Values above it break that promise: stable mode then emits as if they were capped there, smooth mode
  /// glides its points as their own values ask, and a class query gives such a class more than its share
  /// (at the later classes' expense). Smooth mode also reads positions up to twice the glide's reach
  /// (Tileset::glide_reach) outside the region, a point's stable place and where it glides from there, so
  /// the bound must hold there too.
  double callback_max = 1;
  /// For callbacks, optional: bounds of the density over a world rectangle, *lo ≤ ρ ≤ *hi everywhere in
  /// [x0, x1] × [y0, y1] (must be thread-safe, like the callback). A query asks once per tile and then
  /// calls `callback` only where a point's emission is in doubt: in stable mode the points whose threshold
  /// lies between lo and hi (those below lo are emitted, those above hi skipped, unseen), and of those
  /// only the ones the bounds over their quarter-by-quarter cell of the tile leave in doubt too (asked
  /// when a point first lies in the cell: up to 16 more calls a tile); in smooth mode
  /// the points below hi, without the second call at a glided position where lo > 0. Bounds that are not
  /// true bounds make points appear or vanish as if the density were lo or hi there; NaN bounds, and
  /// *lo > *hi, are ignored (0 and callback_max serve).
  void (*bounds)(void* user, double x0, double y0, double x1, double y1, double* lo, double* hi) = nullptr;
};

/// Most positions one QueryDensity::batch_callback call is asked for.
inline constexpr std::size_t kDensityBatch = 128;

/// How emitted points move as the density changes.
enum class QueryMode : int {
  /// A point never moves once it appears: for placing objects that must not shift when the density or the
  /// level of detail changes. The sets are nested, so densities between the tile set's levels (×4 apart)
  /// are poorer blue noise than the levels themselves (docs/quality.md).
  kStable = 0,
  /// Points glide continuously with the density (never jump), so every density is a good blue-noise set:
  /// for stippling and sample patterns. Ids, emission densities and zoom coherence by id are those of
  /// stable mode, except that no point shows where the density is zero: near a sharp edge of the density
  /// a point whose glide carries it past the edge as the scale rises leaves for good (99 of a disc's
  /// rim points between 0.5 and 16 points per unit area); objects that must stay are placed in stable
  /// mode. A tile set without a glide track emits its stable positions.
  kSmooth = 1,
};

/// What a query asks for: a region, where its positions are measured from, the tiling, and the density
/// (a tile expects density · scale · tile_size² points).
struct QueryParams {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;  ///< half-open world region [x0, x1) × [y0, y1); none if x1 ≤ x0
  double origin_x = 0, origin_y = 0;      ///< subtracted from every output position
  double tile_size = 1;                   ///< world units per tile side
  double scale = 1;                       ///< points per unit area at density 1
  QueryDensity density;                   ///< multiplies scale: constant, image or callback
  QueryMode mode = QueryMode::kStable;    ///< stable (points never move) or smooth (points glide)
  /// Smooth mode with a varying density: each point glides by the most density around it (at the corners
  /// of lattice cells about its spacing wide) rather than by its own alone, so that neighbours glide
  /// together and do not close up where the density changes from one dot to the next (a photograph, a
  /// texture). The same points are emitted; only where they glide changes. Costs 8 density reads per
  /// emitted point: a varying-density smooth query takes about twice as long. Use it for pictures and
  /// sample patterns; ignored in stable mode and with a constant density.
  bool glide_together = false;
};

/// Most tiles a query's region may cover (2^24), whatever its density: larger regions are refused
/// (kInvalidArgument, kTooManyTiles); split them.
inline constexpr std::uint64_t kMaxQueryTiles = std::uint64_t(1) << 24;

/// Deepest subtiles a smooth query descends into past a set's top level: densities up to N_top · m^(2 ·
/// kMaxQueryDepth) points per tile (query_density_limit), 2^40 times the top for m = 32.
inline constexpr std::uint32_t kMaxQueryDepth = 4;

/// Most candidate points one call examines (2^24), a tile visited counting as kTileCandidates of them, a
/// class query's candidate as 1 + the classes it reads, glide_together's as 8 times more: a call that
/// reaches it returns kBufferFull with the cursor saved, even if the buffer has room, so no call runs
/// unbounded: 40-80 ms at a constant density, about 0.1 s with callbacks read at every candidate
/// (docs/limits.md, "The longest call"). A caller with a frame budget queries smaller regions per frame,
/// or off its main thread.
inline constexpr std::uint64_t kMaxQueryCandidates = std::uint64_t(1) << 24;
/// What a tile visited counts for in kMaxQueryCandidates: a tile costs about as much as 16 candidates.
inline constexpr std::uint64_t kTileCandidates = 16;

/// Where a query stopped, so a full buffer can be resumed. Zero-initialise before the first call; a cursor
/// belongs to the parameters and the tile set of the call that started it (their fingerprint), and is
/// refused with others (a copy of the same set serves, another set or one reloaded with other tiles not).
struct QueryCursor {
  std::int64_t tile_x = 0, tile_y = 0;  ///< the tile the query stopped in
  std::uint32_t rank = 0;  ///< in the tile or subtile reached; past its ranks, its appearing sub-points
  bool started = false, finished = false;  ///< set by the first call, and once the region is complete
  std::uint64_t fingerprint = 0;  ///< of the parameters (query_fingerprint) and tile set that started it
  std::uint32_t depth = 0;        ///< how deep into tile (tile_x, tile_y) the query stopped
  /// The subtiles it went through, 16 bits per depth from the lowest; at depth 0 in a tile visited cell by
  /// cell (query_points), the cell it stopped in plus one.
  std::uint64_t path = 0;
};

/// Why query_points returned kInvalidArgument: which parameter and, for a limit, the limit and the
/// largest value that passes (Detour-style detail, in plain values: nothing is allocated).
struct QueryProblem {
  enum class Kind : int {
    kNone = 0,          ///< no problem
    kMissingArgument,   ///< `parameter` ("written", "cursor", "out", "tileset") is null or empty
    kNotFinite,         ///< `parameter` is NaN or infinite; `value` holds it
    kNotPositive,       ///< `parameter` ("tile_size") must be > 0; `value` holds it (a C struct's
                        ///< "query.struct_size": at least `limit`, its first version's size)
    kNegative,          ///< `parameter` ("scale", "density.constant", "density.callback_max") must be
                        ///< >= 0; `value` holds it
    kBadDensity,        ///< `parameter` ("density.image", "density.callback") is missing or not prepared,
                        ///< or both callbacks are set; "density.kind" is not a QueryDensity::Kind;
                        ///< "image_sums" built for another count (`limit`; 0: empty) than the query's
                        ///< classes (`value`), or beside a joint density
    kTooManyTiles,      ///< the region covers `value` tiles, more than `limit` (kMaxQueryTiles): split it
                        ///< (`parameter` "x0"; "tile_size" when they are too many to count: value inf)
    kDensityTooHigh,    ///< `value` expected points per tile exceed `limit` (query_density_limit):
                        ///< `largest_valid` is the largest scale that fits, `largest_tile_size` the
                        ///< largest tile size that fits this scale
    kCursorMismatch,    ///< the cursor was started by a call with other parameters or on another tile set
                        ///< (or damaged)
    kBadMode,           ///< `parameter` ("mode") is not a QueryMode; `value` holds it
    kBadClassCount,     ///< query_classes: `value` classes, not 1 … `limit` (kMaxQueryClasses)
    kKeysUnsupported,   ///< query_points_compact: keys asked of a set whose tiles hold `value` points,
                        ///< more than a key's ranks (`limit`, 2^19)
    kTooFarFromOrigin,  ///< `parameter` "x0" or "y0": the region lies `value` world units from the world
                        ///< origin, farther than `limit`, where a double's step is over a 16th of the
                        ///< points' spacing (or a quarter of the region's side, if that is wider than the
                        ///< spacing at the density's depth): move the world's origin nearer, or query a
                        ///< larger region at a lower density. "origin_x" or "origin_y": the region lies
                        ///< `value` from the query's origin, farther than `limit`, where the output's
                        ///< step (a double's, or a compact output's float) is over a 16th (a float's: a
                        ///< quarter) of the densest points' spacing, or a float's reaches a tile: set
                        ///< the origin nearer the region
    kRunnerIncomplete,  ///< a parallel query's task runner ("runner.run") returned before its tasks had
                        ///< done the query: `value` of its `limit` units were taken (0: it ran no task)
  };
  Kind kind = Kind::kNone;
  const char* parameter = "";    ///< the QueryParams field (or argument) at fault; static storage
  double value = 0;              ///< the value refused, where it is a number
  double limit = 0;              ///< the limit it broke, where there is one (see each kind)
  double largest_valid = 0;      ///< kDensityTooHigh: the largest scale that fits
  double largest_tile_size = 0;  ///< kDensityTooHigh: the largest tile size that fits this scale
};

/// The most expected points per tile a query in `mode` may ask for: the top level's count, or in smooth
/// mode with a set that has a hand-over (TilesetShape::handover_zone), that times m^(2 · kMaxQueryDepth).
KDM_RUNTIME_API double query_density_limit(const Tileset& tileset, QueryMode mode);

/// How evenly a tile set serves a density on tiles of a size. A tile that expects fewer points than the
/// set's coarsest level holds gives part of that level, less even; below one point a tile's expected count
/// rounds to steps of 1/(the set's tile count) of a point (the built-in set: 0.05 points per tile give
/// +25%, 0.02 none). A map whose sparse parts fall there is no mistake; a densest value there is a tile
/// size too small for the density. kdm query and kdm.Tileset.query warn by it.
struct TileSizeAdvice {
  enum class Kind : int {
    kEven = 0,            ///< the densest value fills at least the coarsest level
    kUnderCoarsestLevel,  ///< the densest value asks under the coarsest level: less even everywhere
    kUnderOnePoint,       ///< under one point per tile: counts off by up to tens of percent
  };
  Kind kind = Kind::kEven;
  double points_per_tile = 0;  ///< the densest value's expected points per tile
  double coarsest = 0;         ///< the set's coarsest level's points per tile
  double tile_size = 0;        ///< the smallest tile size whose tiles hold the coarsest level at that density
  std::size_t tiles = 0;       ///< the set's tile count (1/tiles: the step of a count below one point)
};

/// The advice for a query whose density is at most `max_density` (a constant's value, an image's or the
/// classes' summed maximum, a callback's bound) at `scale` points per unit area on tiles of `tile_size`.
/// kEven where any of them is not a positive finite number (nothing to advise), or for an empty set.
KDM_RUNTIME_API TileSizeAdvice tile_size_advice(const Tileset& tileset, double max_density, double scale,
                                                double tile_size);

/// The tile (of data().tiles) that point `id` belongs to, at any depth: its rank indexes that tile's
/// points, so its level is tile_of(…).level_of(id.rank). Null for a depth the set does not have (or tile
/// coordinates beyond ±2^62, which no query emits).
KDM_RUNTIME_API const Tile* tile_of(const Tileset& tileset, const PointId& id);

/// The expected count per tile above which point `id` is emitted: where its tile's expected count,
/// ρ · scale · (tile_size / m^depth)² with ρ the density at the point's stable position (stable_position),
/// exceeds it (in smooth mode also only where the density at its glided position is above 0). A caller
/// fading objects in as the density rises, so that they do not pop up, weighs each by (count / threshold −
/// 1) / f clamped to [0, 1]: it appears at weight 0 and is fully shown once the density has risen a
/// fraction f. Past the top level a sub-point that appears in its parent's hand-over has the count at
/// which it appears there, found by a scan of the parent's list (about 900 entries in the built-in set);
/// other ids cost a table lookup. Negative for an id the set does not have (a depth it does not reach, a
/// rank past its tile's points).
KDM_RUNTIME_API double emission_threshold(const Tileset& tileset, const PointId& id);

/// Where point `id` lies unmoved, for tiles of side `tile_size` at depth 0, in world units less (origin_x,
/// origin_y) as a query's output is: where a stable query puts it, where a smooth query's point glides
/// from, and where the density that decides its emission is read, so that a fade weight (emission_threshold)
/// read there follows the query's own rule even where a glide carries the point across a change of density.
/// False (and *x, *y untouched) for an id the set does not have or a tile_size that is not finite and > 0.
KDM_RUNTIME_API bool stable_position(const Tileset& tileset, const PointId& id, double tile_size,
                                     double origin_x, double origin_y, double* x, double* y);

/// A short English description of a problem kind (static storage).
KDM_RUNTIME_API const char* query_problem_message(QueryProblem::Kind kind);

/// How a caller names the parameters a refusal's advice speaks of (`--scale` on a command line, `scale=`
/// in Python); a name ending in '=' is shown without it where it names the parameter at fault.
struct QueryParameterNames {
  const char* scale = "scale";
  const char* tile_size = "tile_size";
  const char* origin = "origin";  ///< null where the caller cannot set one (the world origin is the query's)
};

/// `problem` in one line for a log or an error message: the parameter at fault, the limit it broke and
/// what would be accepted ("... 409600 points per tile where it serves at most 32768; use scale 0.08 or
/// less, or tile_size 18.1019 or less"). Writes at most `size` bytes of it into `text`, NUL included (cut
/// to fit; nothing with size 0), and returns the whole line's length without the NUL, as snprintf does.
/// Allocates nothing.
KDM_RUNTIME_API std::size_t describe_query_problem(const QueryProblem& problem, char* text, std::size_t size,
                                                   const QueryParameterNames& names = {});

/// A hash of every field of `params` (their bits, and the image and callback pointers): the identity a
/// cursor keeps of the call that started it.
KDM_RUNTIME_API std::uint64_t query_fingerprint(const QueryParams& params);

/// Writes the region's points into `out[0..capacity)` in a fixed order (tiles row by row, ranks
/// ascending, then past the top level each tile's appearing sub-points and its subtiles, depth first; a
/// tile of which the region, widened by the glide's reach (a constant density's at its count, else the
/// farthest any point glides), meets at most half gives its points cell by cell instead, cells of a
/// 32 × 32 grid row by row, ranks ascending in each);
/// `*written` receives the count, and slots from there to capacity may be overwritten too (a candidate is
/// written before it is known to be kept). Returns kOk when the region is complete (a finished cursor called
/// again with the same params gives kOk and no points), kBufferFull when `out` filled up first or the call
/// examined kMaxQueryCandidates points (and tiles) — call again with the same cursor and params. Empty or
/// inverted regions and scale 0 give no points (a region past 9e15 tiles from the world origin, where its
/// sides round together, is refused as too far). kInvalidArgument, with `problem` (optional) saying which
/// parameter and limit, for: null arguments, non-finite params, tile_size <= 0, a negative scale, a bad
/// mode, a missing image or callback (or both callbacks set), a region of more than kMaxQueryTiles tiles,
/// a density beyond the density limit (scale · max density · tile_size² > query_density_limit: use smaller
/// tiles or a lower scale), a region too far from the world origin or from the query's origin
/// (kTooFarFromOrigin), or a cursor started with other params. Capacity 0 (`out` may then be null) only
/// checks the query: kInvalidArgument, or kBufferFull at its first point with the cursor unmoved (so a
/// loop resuming while kBufferFull must give room for a point), or kOk for a region without points; to
/// count a region, count_points (one thread) or ParallelQuery::run with capacity 0. No allocation.
KDM_RUNTIME_API Status query_points(const Tileset& tileset, const QueryParams& params, QueryPoint* out,
                                    std::size_t capacity, std::size_t* written, QueryCursor* cursor,
                                    QueryProblem* problem = nullptr);

/// How many points query_points would write for `params`, into `*count`, writing none: to size a buffer
/// before the query. Whole tiles of a constant density cost nothing to count, other tiles what their
/// query does. Returns kOk with the count; kBufferFull after kMaxQueryCandidates candidates, with the
/// count so far: call again with the same cursor and params and add; kInvalidArgument where query_points
/// refuses the params (`count` null: kMissingArgument), with `problem` (optional) saying why. A counting
/// cursor is one of its own: query_points refuses it (kCursorMismatch), and count_points a query's. No
/// allocation.
KDM_RUNTIME_API Status count_points(const Tileset& tileset, const QueryParams& params, std::size_t* count,
                                    QueryCursor* cursor, QueryProblem* problem = nullptr);

}  // namespace kdm
