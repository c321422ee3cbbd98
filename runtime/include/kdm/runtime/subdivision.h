// How a tile splits into m×m subtiles for the hand-over between depths (docs/design.md §3, "Unbounded
// zoom"): past its top level a tile's points glide onto points of its subtiles, which are tiles of the same
// set at 1/m the size. For neighbouring tiles to agree, a sub-vertex's colour depends only on the zone of
// the tile it lies in, as a patch does: within `zone` sub-steps of a corner (both axes) on that corner's
// colour, within `zone` of an edge on its two end colours, elsewhere on all four; and on its place there.
// The runtime lays out subtiles with it, and the baker matches each tile's points to its own subtiles'.
//
// Thread safety: a plain value; every function is pure.
#pragma once

#include <cstddef>
#include <cstdint>

#include "kdm/runtime/hash.h"

namespace kdm {

struct Subdivision {
  std::uint32_t colours = 1;  ///< corner colours C of the set
  std::uint32_t m = 0;        ///< subtiles per tile side (0: the set has no hand-over)
  std::uint32_t zone = 0;  ///< half-width of the corner squares and edge bands, in sub-steps; 2·zone + 1 < m

  /// Where a sub-vertex lies.
  enum class Zone : int { kCorner = 0, kHorizontalEdge = 1, kVerticalEdge = 2, kInterior = 3 };
  Zone zone_of(std::uint32_t i, std::uint32_t j) const {
    const bool near_x = i <= zone || i + zone >= m, near_y = j <= zone || j + zone >= m;
    return near_x && near_y ? Zone::kCorner
           : near_y         ? Zone::kHorizontalEdge
           : near_x         ? Zone::kVerticalEdge
                            : Zone::kInterior;
  }

  /// Colour of sub-vertex (i, j), 0 ≤ i, j ≤ m (1/m tile sides from the south-west corner), of the tile
  /// with corner colours (sw, se, ne, nw). Positions count from the zone's own corner or edge line, so
  /// the tiles on both sides of an edge (or around a corner) give a shared sub-vertex the same colour.
  std::uint32_t vertex_colour(std::uint32_t sw, std::uint32_t se, std::uint32_t ne, std::uint32_t nw,
                              std::uint32_t i, std::uint32_t j) const {
    const std::int64_t di = 2 * std::int64_t(i) <= m ? std::int64_t(i) : std::int64_t(i) - m;
    const std::int64_t dj = 2 * std::int64_t(j) <= m ? std::int64_t(j) : std::int64_t(j) - m;
    const bool east = 2 * i > m, north = 2 * j > m;
    std::uint64_t key = 0;
    switch (zone_of(i, j)) {
      case Zone::kCorner: {
        const std::uint32_t c = north ? (east ? ne : nw) : (east ? se : sw);
        key = hash(0, c, di, dj);
        break;
      }
      case Zone::kHorizontalEdge:  // along x, from its west end
        key = hash(1, north ? nw * colours + ne : sw * colours + se, i, dj);
        break;
      case Zone::kVerticalEdge:  // along y, from its south end
        key = hash(2, east ? se * colours + ne : sw * colours + nw, di, j);
        break;
      case Zone::kInterior:
        key = hash(3, ((std::uint64_t(sw) * colours + se) * colours + ne) * colours + nw, i, j);
        break;
    }
    return static_cast<std::uint32_t>(key % colours);
  }

 private:
  static std::uint64_t hash(std::uint64_t kind, std::uint64_t colours_key, std::int64_t a, std::int64_t b) {
    std::uint64_t h = mix64(0x53554254494c45ull ^ kind);  // "SUBTILE"
    h = mix64(h ^ colours_key);
    h = mix64(h ^ static_cast<std::uint64_t>(a + 0x8000));
    return mix64(h ^ static_cast<std::uint64_t>(b + 0x8000));
  }
};

}  // namespace kdm
