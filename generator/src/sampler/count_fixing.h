// Exact point counts for Algorithm 2 of Fattal 2011 (multiscale.h): the greedy initial configuration
// gives about n points, and kernels are then removed where that raises E = Σ|R| least. The paper has no
// such step; users ask for exactly n points.
#pragma once

#include <cstdint>
#include <vector>

#include "sampler/chain.h"
#include "sampler/particle.h"

namespace kdm::gen {

/// Removes kernels from `particles` (every one of them in `chain`'s R) while their total weight `w` exceeds
/// `n`: each time the one whose removal raises E least per unit of weight, however heavy (`w` may end
/// below `n`: the caller adds kernels back); ties go to the lowest index. Takes each removed kernel out of
/// R and lowers `w`.
/// Returns how many were removed. Chooses exactly what working out every cost before each choice would,
/// but works out again only the costs that a removal changed and that might now be the lowest.
/// Not thread-safe (one chain, one thread).
template <int D>
std::int64_t remove_surplus(Chain<D>& chain, std::vector<Particle<D>>& particles, double n, double& w);

/// How far Chain::energy_change_if_removed() (float sums of |r| - |r - k| over the footprint) may lie from
/// the same sum in exact arithmetic on the same R, for the footprint `fp` it built, when |r| <= max_abs_r
/// at every node. Thread-safe.
template <int D>
double removal_rounding_bound(const Footprint<D>& fp, double max_abs_r);

/// remove_surplus() as kdm's first versions did it, kept for Numerics::kOriginal: kernels no heavier than
/// the surplus preferred, and every cost worked out again after each removal by taking the kernel out of R
/// and putting it back, which may change R's last bits and so the choices after.
template <int D>
std::int64_t remove_surplus_as_first_versions(Chain<D>& chain, std::vector<Particle<D>>& particles, double n,
                                              double& w);

}  // namespace kdm::gen
