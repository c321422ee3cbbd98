// The baker's internals that its tests reach: a bake that also plans the hand-over between depths
// (bake/handover.h), before the file format carries it.
#pragma once

#include <cstdint>
#include <vector>

#include "bake/handover.h"
#include "kdm/generator/bake.h"

namespace kdm::gen {

/// Bakes `recipe` as bake_tileset does, into `set`, and plans its hand-over with corner squares and edge
/// bands `zone` sub-steps wide. Throws InvalidArgument unless the top level holds a square number of
/// base levels (m² · N_0 = N_top) with 2 · zone + 1 < m.
std::vector<TileHandover> bake_with_handover(const BakeRecipe& recipe, std::uint32_t zone, int threads,
                                             TilesetData& set);

}  // namespace kdm::gen
