// The hand-over between depths (docs/design.md §3, "Unbounded zoom"): past the top keyframe every point of
// a tile glides onto a point of one of its m×m subtiles (tiles of the same set at 1/m the size, laid out
// by kdm/runtime/subdivision.h) as they stand at keyframe 1, the first past their level 0; the sub-points
// no point takes appear on the way. Each point is matched within the tile that shows it, least total
// squared distance, patch by patch so that a point's target depends on its patch's colours alone, as its
// keyframes do: corner patches take sub-points whose every sub-vertex lies in their corner's zone, edge
// patches those of their band and the ones their corners left in their sector, interiors what is left.
//
// Thread safety: plan_handover is a pure function of its arguments.
#pragma once

#include <cstdint>
#include <vector>

#include "bake/corner_layout.h"
#include "kdm/runtime/subdivision.h"
#include "kdm/runtime/tileset_format.h"

namespace kdm::gen {

/// One tile's hand-over. A sub-point is packed as (j << 16) | q: subtile j = row · m + column of the
/// tile's m×m subtiles (row 0 at the south), q its rank in the tile that subtile shows.
struct TileHandover {
  std::vector<std::uint32_t> target;     ///< per rank of the tile: the sub-point it glides onto
  std::vector<std::uint32_t> appearing;  ///< the sub-points no point takes, in the order they appear
};

/// Plans the hand-over of every tile of `set` (assembled from `levels`, which hold every keyframe's
/// frames). `ranked[t]` says where each point of tile t comes from, by rank (the refs gather() gives with
/// the window [0, 1)², anchors relative to the tile). `sub` must have m² = top nominal / base nominal and
/// the set's colours; `top_widths` (the top level's patch half-widths) decide which points join a corner
/// or edge group rather than their tile's interior. Throws std::runtime_error if some patch finds too few
/// sub-points (a zone too narrow for the patches).
std::vector<TileHandover> plan_handover(const std::vector<LevelPatches>& levels, const TilesetData& set,
                                        const std::vector<std::vector<PatchPointRef>>& ranked,
                                        const Subdivision& sub, PatchWidths top_widths);

}  // namespace kdm::gen
