// Large-scale count balance of a refined configuration, before a level's sweeps.
//
// Fattal's coarse-to-fine scheme (KDM, SIGGRAPH 2011, §3.3) hands the finest chain a configuration whose
// low frequencies should already be at equilibrium. For spatially varying densities they are not: the
// coarse levels leave sparse regions short of points, and the finest chain moves mass across the domain
// far too slowly to repair it, while started from the right counts it keeps them (docs/design.md §2).
// So the counts are corrected where they go wrong, in the initialisation: after each refinement a smooth
// displacement (a linearised density-equalising map on a coarse grid) moves the kernels so that their
// counts match the target; the level's sweeps then relax them, and the finest sweeps sample the model.
#pragma once

#include <array>
#include <vector>

#include "sampler/grid.h"
#include "sampler/particle.h"

namespace kdm::gen {

/// What one call did, for the sampler's report and the tests.
struct CountBalanceReport {
  int grid[3] = {0, 0, 0};  ///< the coarse grid the counts were compared on
  int iterations = 0;       ///< displacement steps taken
  /// Σ|count − target| / Σtarget over the coarse grid's nodes, before and after (counts binned
  /// multilinearly, so a perfect set is not exactly 0).
  double mismatch_before = 0, mismatch_after = 0;
};

template <int D>
struct CountBalanceSettings {
  /// Nodes expecting fewer points than this are left as they are (too few points to compare), and so
  /// are the points near them.
  double min_target = 0;
  /// ρ / w below which a kernel is frozen (σ >= σmax) on the grid being balanced: no sweep there will
  /// relax a neighbourhood the balance changes. Such kernels are balanced on the coarser levels where they
  /// are still relaxed; on the finest level, what those levels' sweeps left is corrected too
  /// (`move_frozen`), but a kernel moved to frozen territory keeps half the local spacing to every other.
  double frozen_below = 0;
  bool move_frozen = false;
  /// The finest density, when `finest` is a coarser level, and its nodes per `finest` node: points are
  /// moved only where the finest density is positive all around (or to denser places).
  const DensityGrid<D>* support = nullptr;
  double support_scale = 1;
  int max_iterations = 12;    ///< displacement steps at most (fewer once a step gains under 2%)
  double mass_per_point = 1;  ///< of a unit kernel: the local spacing is (mass_per_point w / ρ)^(1/D)
};

/// Moves `particles` (positions in `finest` grid units, weights counted; `finest` is the level being
/// balanced) so that their counts on a coarse grid of `coarse_dims` nodes spanning the same domain (a
/// node covers finest.dims / coarse_dims finest nodes per axis, not necessarily a whole number) match
/// the target density there. `source` is a level of the density pyramid (its nodes each cover
/// `source_factor` finest nodes; its values need only be proportional to the target); the finer it is,
/// the more exact the target. Points are never moved onto zero density. Deterministic and
/// single-threaded (the coarse grid is small). Requires a source node no larger than a coarse one.
template <int D>
CountBalanceReport balance_counts(std::vector<Particle<D>>& particles, const DensityGrid<D>& finest,
                                  const DensityGrid<D>& source, int source_factor,
                                  const std::array<int, D>& coarse_dims,
                                  const CountBalanceSettings<D>& settings);

}  // namespace kdm::gen
