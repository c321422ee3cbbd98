// The hand-over between depths (docs/design.md §3, "Unbounded zoom"): past the top keyframe every point of
// a tile glides onto a point of one of its m×m subtiles (tiles of the same set at 1/m the size, laid out
// by kdm/runtime/subdivision.h) as they stand at the hand-over keyframe h, the first past their level j
// (TilesetShape::handover_level) or handover_slack keyframes later; the sub-points no point takes appear
// on the way. Each tile's points are matched to its own sub-points as one whole,
// least total squared distance: straight paths of such a matching, travelled in step, never meet (the
// displacement interpolation of optimal transport), and the tile's whole surplus of sub-points is there
// for a point wherever it lies. Paths are not in step (a long glide is slow), so points whose paths come
// close to another's then swap sub-points with a nearby point where that parts them. The sub-points left
// over appear in an order that lets the gliders around each clear its place first.
//
// Thread safety: plan_handover is a pure function of its arguments.
#pragma once

#include <cstdint>
#include <vector>

#include "kdm/runtime/tileset_format.h"

namespace kdm::gen {

/// One tile's hand-over. A sub-point is packed as (j << 16) | q: subtile j = row · m + column of the
/// tile's m×m subtiles (row 0 at the south), q its rank in the tile that subtile shows.
struct TileHandover {
  std::vector<std::uint32_t> target;     ///< per rank of the tile: the sub-point it glides onto
  std::vector<std::uint32_t> appearing;  ///< the sub-points no point takes, in the order they appear
};

/// Plans the hand-over of every tile of `set`, whose levels, glide track and handover_zone are final (its
/// hand-over tables are not read). Positions are the file's (quantised), as the runtime shows them.
/// Throws std::runtime_error if a tile's subtiles hold fewer points at keyframe h than the tile holds.
std::vector<TileHandover> plan_handover(const TilesetData& set);

}  // namespace kdm::gen
