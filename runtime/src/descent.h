// Internal: smooth queries past a tile set's top level (docs/design.md §3, "Unbounded zoom"). Past N_top a
// tile's points glide onto points of its m×m subtiles at their keyframe h (Tile::handover), and the
// subtiles' points no point takes appear on the way (Tile::appearing). Where a subtile's expected count at
// such a sub-point's stable position exceeds K_h the subtile emits it itself, with the id of the point it
// came from, and the same happens one depth further down, to kMaxQueryDepth.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "density_bounds.h"
#include "image_sampler.h"
#include "kdm/runtime/query.h"
#include "keyframe_lookup.h"
#include "query_tables.h"

namespace kdm::detail {

/// What one query's descending tiles share.
struct DescentQuery {
  const TilesetData* set = nullptr;
  const QueryTables* tables = nullptr;
  KeyframeTable keyframes;
  const QueryParams* params = nullptr;
  const ImageSampler* sampler = nullptr;
  double side[kMaxQueryDepth + 1] = {};  ///< a tile's side at each depth, world units
  double area[kMaxQueryDepth + 1] = {};  ///< expected points per tile per unit of density, at each depth
  double origin_frac_x = 0, origin_frac_y = 0;  ///< the origin's place in its depth-0 tile, world units
  std::int64_t origin_tile_x = 0, origin_tile_y = 0;
  double reach = 0;  ///< the farthest a tile's points (and its subtiles') lie outside it, in its sides
  double top = 0, kh = 0, appearing_end = 0;  ///< N_top, K_h (h: the hand-over keyframe) and m² K_h

  /// Prepares a query that query_points has validated.
  DescentQuery(const Tileset& tileset, const QueryParams& q, const ImageSampler& sampler);
  double density_at(double x, double y) const;
  /// Lower and upper bounds of the density over a rectangle (the callback's: 0 and callback_max).
  void density_bounds(double x0, double y0, double x1, double y1, double& lo, double& hi) const;
};

/// Where a descending tile's emission stopped (QueryCursor's depth, path and rank).
struct DescentPlace {
  std::uint32_t depth = 0;
  std::uint64_t path = 0;  ///< the subtile index at each depth, 16 bits each from the lowest
  std::uint32_t rank = 0;  ///< in the tile reached; from its point count on, its appearing list
};

/// Emits tile (tx, ty), set tile `index`, and its subtiles from `at` on into out[written, capacity),
/// examining at most `budget` candidates (reduced by those examined). Returns true when the tile is done,
/// false with `at` where it stopped (the buffer full or the budget spent).
bool emit_descending(const DescentQuery& q, std::int64_t tx, std::int64_t ty, std::size_t index,
                     QueryPoint* out, std::size_t capacity, std::size_t& written, std::uint64_t& budget,
                     DescentPlace& at);

}  // namespace kdm::detail
