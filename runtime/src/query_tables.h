// Internal: the tables a loaded Tileset keeps for the query loop, built once per load from its
// TilesetData (emission thresholds, the glide track's starts, reaches and brackets, the edge lists).
// Installed headers never show them; tests reach them through kdm_runtime_internal.
#pragma once

#include <cstddef>
#include <cstdint>

#include "kdm/runtime/allocator.h"
#include "kdm/runtime/tileset.h"

namespace kdm::detail {

/// How a point glides at an expected count c per tile between keyframes K_g0 ≤ c ≤ K_g1: its offset is
/// o_g0 · (1 − t) · scale0 + o_g1 · t · scale1 with t = (c − base) · inverse_gap, in 1/65536 tile sides.
/// Below the first keyframe and above the last g0 = g1 and t = 0: no motion there.
struct GlideSpan {
  std::uint32_t g0 = 0, g1 = 0;
  double base = 0, inverse_gap = 0;  ///< K_g0 and 1 / (K_g1 − K_g0) (0 when g0 = g1)
  double scale0 = 0, scale1 = 0;     ///< QueryTables::glide_scale of g0 and g1
};

/// Position units (1/65536 tile side) the edge lists add to each point's reach, for rounding.
inline constexpr double kEdgeSlack = 8;

/// QueryTables::cell_ranks cuts a tile into 2^kIndexCellBits × 2^kIndexCellBits cells.
inline constexpr std::uint32_t kIndexCellBits = 5, kIndexCells = 1u << kIndexCellBits;

/// coarsest_level_thresholds (tileset_format.h) into `out`, whose tiles' arrays already hold at least
/// their coarsest level's ranks (the rest is left as it is): no scratch outside the tile-set allocator.
void coarsest_level_thresholds_into(const TilesetData& set, TilesetArray<TilesetArray<float>>& out);

struct QueryTables {
  /// Per tile, its points' emission thresholds (TilesetShape::emission_threshold), non-decreasing.
  TilesetArray<TilesetArray<float>> thresholds;
  /// The lowest threshold of any point: below it no tile emits anything.
  double min_threshold = 0;
  /// The most points any tile holds (a rank is always below it).
  std::uint64_t most_points = 0;
  /// A hash of the set's tiles (their points, thresholds and glides), mixed into a cursor's fingerprint:
  /// a cursor is refused on another set, a set reloaded from another file included.
  std::uint64_t identity = 0;
  /// Per tile, where each keyframe's offsets start in Tile::glide, in offset pairs (keyframes + 1 entries:
  /// keyframe g's pairs are [start[g], start[g + 1]), one per rank below TilesetShape::offsets_at_keyframe).
  TilesetArray<TilesetArray<std::uint32_t>> glide_start;
  /// The largest distance any point glides from its stable position, per axis, in tile sides, at keyframe
  /// g (smooth queries look this far beyond their region), and the largest of those from keyframe g on.
  TilesetArray<double> glide_reach, glide_reach_from;
  /// Per keyframe, 1/65536 tile sides per glide offset unit (65536 · TilesetShape::glide_unit(g)).
  TilesetArray<double> glide_scale;
  /// Per tile and keyframe g, how many of its points are present there (TilesetShape::points_at_keyframe).
  TilesetArray<TilesetArray<std::uint32_t>> points_at_keyframe;
  /// TilesetShape::keyframe_nominal as doubles, then +∞ (keyframes + 1 entries): searches stop without a
  /// bound.
  TilesetArray<double> keyframe_nominal;
  /// Per g = first_keyframe_at_least(count) (keyframes + 1 entries), how a count there glides.
  TilesetArray<GlideSpan> glide_spans;
  /// Per bucket of counts (keyframe_lookup.h), the first keyframe at least the bucket's smallest count.
  TilesetArray<std::uint16_t> keyframe_guess;
  /// Whether one step from keyframe_guess always finds the first keyframe at least a count (true when
  /// consecutive keyframes are over 3.1% apart, as in baked sets).
  bool keyframe_one_step = false;
  /// Smooth mode: per tile, the ranks of its points that can glide across each side (0: x = 0, 1: x = 1,
  /// 2: y = 0, 3: y = 1), ascending, the four lists in turn; edge_start holds 5 offsets per tile into
  /// them. A point is listed when its stable position lies within glide_reach_from(the keyframe it
  /// appears after) · 65536 + kEdgeSlack position units of that side, so a tile beside a region is
  /// scanned through one list, not in full.
  TilesetArray<TilesetArray<std::uint32_t>> edge_ranks;
  TilesetArray<std::uint32_t> edge_start;
  /// Per tile, the ranks of its points in each of its kIndexCells² cells (point p lies in cell
  /// (p.y >> (16 − kIndexCellBits)) · kIndexCells + (p.x >> (16 − kIndexCellBits))), ascending, the cells in
  /// turn; cell_start holds kIndexCells² + 1 offsets per tile. A query whose region meets a few cells of a
  /// tile visits only their points. Empty when a tile holds more than 65,536 points, or every tile fewer
  /// than kIndexCells² (a whole tile is then a short scan).
  TilesetArray<TilesetArray<std::uint16_t>> cell_ranks;
  TilesetArray<std::uint32_t> cell_start;
  /// The hand-over between depths (sets with a handover_zone; else empty). Subtiles per side m, the
  /// hand-over keyframe h (TilesetShape::handover_keyframe), and per tile t and subtile j = row · m +
  /// column, the tile its subtile shows: child_type[t · m² + j].
  std::uint32_t subtiles = 0, handover_keyframe = 0;
  TilesetArray<std::uint32_t> child_type;
  /// Which point of tile t glides onto rank q of its subtile j: inherited[t][inherited_start[t · (m² + 1)
  /// + j] + q], a rank of t, or kAppearing | a for a sub-point that appears on its own, the a-th of t's
  /// Tile::appearing. A point emitted by a
  /// subtile keeps the id of the point it came from.
  TilesetArray<TilesetArray<std::uint32_t>> inherited;
  TilesetArray<std::uint32_t> inherited_start;
  static constexpr std::uint32_t kAppearing = 1u << 31;  // tiles hold fewer points (2^22 at most)
  static bool appearing(std::uint32_t from) { return (from & kAppearing) != 0; }
  /// Per tile and rank, the count where its subtile takes the point over (TilesetShape::handover_end of
  /// its glide, from its top-keyframe position to its sub-point's position at keyframe h), and per tile the
  /// largest of them.
  TilesetArray<TilesetArray<float>> handover_end;
  TilesetArray<double> handover_end_max;
  /// The farthest, per axis in tile sides, that a hand-over's straight path (from a point's top-keyframe
  /// position to its sub-point's glide track from K_h on) lies from the point's stable position; and the
  /// farthest any point of a tile or of its subtiles lies from its stable position at any count, the
  /// larger of that and glide_reach_from[0]: queries past the top level look this far beyond their region.
  double handover_reach = 0, descent_reach = 0;
  /// The allocator hooks this object itself came from (Tileset allocates it through them).
  AllocatorHooks hooks;

  /// Builds every table from `set` (validated).
  explicit QueryTables(const TilesetData& set);
  /// Heap bytes the tables hold, this object included.
  std::size_t resident_bytes() const;
  /// Side `side`'s list of tile `index` (see edge_ranks); `count` receives its length.
  const std::uint32_t* edges(std::size_t index, int side, std::uint32_t& count) const {
    const std::uint32_t* start = edge_start.data() + 5 * index;
    count = start[side + 1] - start[side];
    return edge_ranks[index].data() + start[side];
  }
  /// For a tile beside a region: the region's bounds in the tile's position units (1/65536 sides), widened
  /// for rounding, and the region lying beyond one of its sides (to within kEdgeSlack / 2 units) give the
  /// shortest such side's list, whose every other point a culling by those bounds and the points' reach
  /// would reject. Returns false (begin and end untouched) when the region lies beyond no side.
  bool edges_beyond(std::size_t index, double cull_x0, double cull_y0, double cull_x1, double cull_y1,
                    const std::uint32_t*& begin, const std::uint32_t*& end) const;

 private:
  void index_edges(const TilesetData& set);
  void index_cells(const TilesetData& set);
  void index_handover(const TilesetData& set);
};

/// A Tileset's tables: what the query loop reads besides its TilesetData.
struct TilesetInternals {
  static const QueryTables& tables(const Tileset& set) { return *set.tables_; }
};

/// QueryTables::identity of `set` (0 for an empty set).
inline std::uint64_t tileset_identity(const Tileset& set) {
  return set.empty() ? 0 : TilesetInternals::tables(set).identity;
}

/// The first keyframe of `set` whose count is at least `expected` (> 0), or the keyframe count if none
/// (0 without keyframes): a table lookup on the number's exponent and leading bits, then a step or two.
std::uint32_t first_keyframe_at_least(const Tileset& set, double expected);

}  // namespace kdm::detail
