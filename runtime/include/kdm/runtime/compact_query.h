// The query of query.h written compactly: positions as float32 pairs and, if asked for, a 64-bit key per
// point, in separate arrays (structure of arrays), so a caller that needs only positions writes only
// positions: 8 bytes a point, or 16 with keys, instead of QueryPoint's 40. The points, their order, the
// statuses, the cursor and every guarantee are query_points' own; only the output's form differs.
//
// Float positions are relative to the query origin (QueryParams::origin_x, origin_y): keep the origin
// near the region (a chunk's corner, the camera), as float32 carries about 7 significant digits.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "kdm/runtime/export.h"
#include "kdm/runtime/query.h"
#include "kdm/runtime/status.h"
#include "kdm/runtime/tileset.h"

namespace kdm {

/// Bits of a point key: the low bits of the tile coordinates, the rank, the depth (from the lowest bit).
inline constexpr int kKeyTileBits = 21, kKeyRankBits = 19, kKeyDepthBits = 3;

/// A point's id in 64 bits: tile_x and tile_y modulo 2^21, the rank (below 2^19) and the depth. Two
/// points have the same key only if their tiles, at their depth, lie a multiple of 2^21 tiles apart: keys
/// are unique within any region less than 2,097,152 tiles (of the points' depth) across, and the same in
/// every query, so a caller can follow a point across frames or seed its own randomness from it.
constexpr std::uint64_t point_key(const PointId& id) {
  constexpr std::uint64_t tile_mask = (std::uint64_t(1) << kKeyTileBits) - 1;
  return (std::uint64_t(id.tile_x) & tile_mask) | (std::uint64_t(id.tile_y) & tile_mask) << kKeyTileBits |
         std::uint64_t(id.rank) << (2 * kKeyTileBits) |
         std::uint64_t(id.depth) << (2 * kKeyTileBits + kKeyRankBits);
}

/// The id `key` stands for (point_key's inverse), for emission_threshold and the like: its tile is the one
/// whose coordinates, modulo 2^21, are the key's and that lies nearest (near_tile_x, near_tile_y), given in
/// tiles of side tile_size (depth 0; at depth d the point's tile coordinates are m^d times those, m =
/// subtiles_per_side()). Any tile of the query's region serves as the near one, floor(x0 / tile_size) and
/// floor(y0 / tile_size) say, as long as the region is under 2^20 tiles of the point's depth across. A near
/// tile too far out to scale to the key's depth gives an id of no depth the set has (emission_threshold
/// then refuses it).
inline PointId point_id_of_key(const Tileset& tileset, std::uint64_t key, std::int64_t near_tile_x,
                               std::int64_t near_tile_y) {
  constexpr std::uint64_t tile_mask = (std::uint64_t(1) << kKeyTileBits) - 1;
  constexpr std::int64_t half = std::int64_t(1) << (kKeyTileBits - 1);
  PointId id;
  id.rank = std::uint32_t(key >> (2 * kKeyTileBits)) & ((std::uint32_t(1) << kKeyRankBits) - 1);
  id.depth = std::uint32_t(key >> (2 * kKeyTileBits + kKeyRankBits));
  std::int64_t scale = 1;  // depth-0 tiles to the point's depth
  const std::int64_t m = std::max<std::int64_t>(1, tileset.data().subtiles_per_side());
  for (std::uint32_t d = 0; d < id.depth && d <= kMaxQueryDepth; ++d) scale *= m;
  // A near tile too far out to scale to the key's depth names no tile: a depth the set has not.
  const std::int64_t reach = std::numeric_limits<std::int64_t>::max() / scale / 2;
  if (near_tile_x > reach || near_tile_x < -reach || near_tile_y > reach || near_tile_y < -reach)
    id.depth = std::numeric_limits<std::uint32_t>::max();
  auto unwrap = [&](std::uint64_t bits, std::int64_t near) {
    near = near > reach ? reach : near < -reach ? -reach : near;
    near *= scale;  // the key's low bits, taken to the nearest tile congruent to them
    std::int64_t delta = std::int64_t((bits - std::uint64_t(near)) & tile_mask);
    if (delta >= half) delta -= 2 * half;
    return near + delta;
  };
  id.tile_x = unwrap(key & tile_mask, near_tile_x);
  id.tile_y = unwrap((key >> kKeyTileBits) & tile_mask, near_tile_y);
  return id;
}

/// Where query_points_compact writes, caller-owned: `xy` is required (room for 2 · capacity floats), `keys`
/// optional (null: no keys are written; else room for capacity keys).
struct CompactPoints {
  float* xy = nullptr;            ///< x, y of each point, world position minus the query origin
  std::uint64_t* keys = nullptr;  ///< point_key of each point's id
};

/// query_points into a compact output: the same points in the same order, point i's position as floats
/// at xy[2i], xy[2i + 1] and, if keys is not null, keys[i] = point_key(its id). A position lies within
/// 2^-21 · (|position| + tile_size) + 2^-50 · |world coordinate| of the double query_points writes (the
/// second term is that double's own rounding, far from the world origin, where the float is the nearer
/// to the exact place): with a constant density it is computed in float from the tile's corner relative
/// to the origin (and the point's glide offsets), so that whole tiles convert as fast as a copy. Either
/// way it depends only on the point and the parameters, so partitions of a region give the same bits. Slots
/// from *written to capacity may be overwritten. Statuses, resumption (a cursor serves query_points and this
/// function alike) and refusals as query_points', with parameter "out.xy" for a null xy with room in it,
/// "origin_x" or "origin_y" (kTooFarFromOrigin, `limit` the farthest allowed) for a region so far from the
/// origin that a float's step there passes a quarter of the densest points' spacing (2^21 spacings) or
/// reaches a tile (2^23 tiles), and
/// kKeysUnsupported when keys are asked of a set whose tiles hold more than 2^19 points (ranks would not fit
/// a key). No allocation.
KDM_RUNTIME_API Status query_points_compact(const Tileset& tileset, const QueryParams& params,
                                            const CompactPoints& out, std::size_t capacity,
                                            std::size_t* written, QueryCursor* cursor,
                                            QueryProblem* problem = nullptr);

}  // namespace kdm
