// The glide track of a tile set (kdm/runtime/tileset_format.h): keyframes between the pyramid's levels, at
// each of which the points present are relaxed as a whole, so that a query in smooth mode shows a good
// blue-noise set at every density, not only at the levels.
//
// Nested sets cannot do that: when no point ever moves, the worst density between two levels ×4 apart is
// far from it whatever the ranking (docs/design.md §3). Here the points present at keyframe g (a prefix of
// every tile's ranks, chosen by the same thresholds as the stable emission) start where keyframe g − 1 left
// them, the new ones at their stable positions, and descend the KDM energy (T = 0) for a few sweeps; each
// moves at most a bounded step, and pairs are kept apart at the keyframe and on the straight paths between
// keyframes that smooth queries follow (glide_paths.h).
//
// Shared patches stay shared: keyframes are relaxed with the pyramid's own schedule of runs (run_stages.h).
// A run of stage s moves every point of patches of kind >= s on its torus, with the kinds before s fixed at
// their positions of this keyframe, and keeps the moves of the patches of kind s it is the first to hold,
// so each point moves once per keyframe, the same way in every tile that holds it. With consensus, every
// torus of the schedule that holds a patch of kind s is relaxed as a run of stage s too, and the patch
// takes the mean of its moves on all of them: moved on one torus only, it moves away from neighbours
// (later kinds' points) that other tiles do not show, and leaves a hole in those tiles. The means are then
// kept apart on the stage's own tori, as a run's moves are: the mean of two separated layouts need not be.
//
// Thread safety: relax_keyframe uses up to `threads` threads of its own; calls must not overlap.
#pragma once

#include <cstdint>
#include <vector>

#include "bake/corner_layout.h"
#include "kdm/runtime/tileset_format.h"

namespace kdm::gen {

/// The keyframe counts: N_0, then `per_level` steps per level in geometric progression, each level's last
/// step its nominal count (rounded to whole points). Empty if per_level is 0.
std::vector<std::uint32_t> make_keyframe_nominal(const std::vector<std::uint32_t>& nominal,
                                                 std::uint32_t per_level);

/// Up to which keyframe counts (points per tile) shared patches move by consensus: every kind up to
/// `all`, the corner patches alone up to `corners` (the costliest tori are the interiors', which every
/// earlier stage's consensus relaxes again; corners are where one run's moves leave most holes).
struct Consensus {
  std::uint32_t all = 0;
  std::uint32_t corners = 0;
  /// Whether the patches of stage `stage` (a PatchKind) move by consensus at keyframe count `count`.
  bool covers(std::uint32_t count, int stage) const {
    return count <= all || (stage == 0 && count <= corners);
  }
};

/// Relaxes keyframe g: every patch of the levels up to `shape.keyframe_nominal[g]` gets frames[g] (keyframe
/// g − 1 must be done). `shape` supplies the colours and the level and keyframe counts. Descends
/// `sweeps` sweeps; `seed` picks the sweep order. `consensus` says which keyframes move which shared patches
/// by consensus (above; for every kind it costs about 3.6 times the relaxation with 2 colours).
/// With `late_from` in (0, 1), the points new at g that are shown later than that fraction of the way from
/// keyframe g − 1 are left out of g's descent (kept apart only), so their room is made after they appear.
void relax_keyframe(std::vector<LevelPatches>& levels, const std::vector<BakeRun>& runs,
                    const std::vector<PatchWidths>& widths, const TilesetShape& shape, std::size_t g,
                    int sweeps, std::uint64_t seed, int threads, Consensus consensus = {},
                    double late_from = 0);

}  // namespace kdm::gen
