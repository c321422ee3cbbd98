// Baking tile sets (DESIGN.md §3): every tile is a toroidal multi-density pyramid sampled by the full KDM
// sampler with constrained sampling — level k+1 keeps all of level k fixed and adds 3× as many points —
// and the new points of each level are put in a progressive order (void-and-cluster ranking against the
// points of earlier levels), so any prefix is itself well spread, down to low frequencies.
//
// Status: one corner colour (a single periodic tile). Aperiodic corner tiles (colours > 1) are planned.
// Thread safety: bake_tileset is reentrant; it uses up to `threads` threads of its own.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "kdm/runtime/tileset.h"

namespace kdm::gen {

/// Everything that determines a baked tile set; `kdm bake` reads it from a small text file of
/// "key value" lines ('#' starts a comment). Baking the same recipe with the same kdm version gives
/// the same bytes, for any thread count.
struct BakeRecipe {
  std::uint64_t seed = 1;
  std::uint32_t colours = 1;       ///< corner colours (only 1 for now)
  std::uint32_t levels = 6;        ///< pyramid levels; level k holds base_points·4^k points
  std::uint32_t base_points = 16;  ///< points of level 0 per tile
  double temperature = 0.5;        ///< user-facing temperature, as in kdm sample
  int sweeps = 100;                ///< MH sweeps per sampler level (constrained sampling needs more than 15)

  /// Parses recipe text. Throws InvalidArgument naming the line and problem (unknown key, bad value,
  /// out-of-range count).
  static BakeRecipe parse(const std::string& text);
  /// The canonical text form (parse(to_text()) == *this).
  std::string to_text() const;
  /// MH sweeps for a level holding `level_points` points in all: `sweeps`, times 4096 / level_points
  /// (at most 64×) for small levels. They are cheap, and every finer level is built on them, so they get
  /// closer to equilibrium. The generator test draws its reference runs with the same schedule.
  int sweeps_for(std::uint64_t level_points) const;
  std::uint64_t top_level_points() const { return std::uint64_t(base_points) << (2 * (levels - 1)); }
};

/// Bakes `recipe`. `progress` (optional) receives the fraction done. Throws InvalidArgument on a bad
/// recipe.
TileSet bake_tileset(const BakeRecipe& recipe, int threads = 0,
                     const std::function<void(double)>& progress = {});

/// The progressive order of `new_points` (interleaved x y on the unit torus) given `fixed` points that
/// come first: returns indices into new_points, first = rank 0: each next point sits in the deepest void
/// of a Gaussian-filtered density of everything present. O(n²) time; n up to a few tens of thousands.
std::vector<std::uint32_t> progressive_order(const std::vector<double>& new_points,
                                             const std::vector<double>& fixed);

}  // namespace kdm::gen
