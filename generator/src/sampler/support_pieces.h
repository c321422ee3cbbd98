// Point counts per connected piece of a density's support, for the multi-scale sampler of Fattal 2011
// (KDM, SIGGRAPH 2011, §3.3; multiscale.h).
//
// A kernel never crosses zero density: neither the chain's moves nor the count balance (count_balance.h)
// carry mass from one piece of the support to another. So the coarsest level's whole kernels would decide
// each piece's count: a piece narrower than a coarse kernel (an island, a glyph, the dot of an i) gets none
// or one, and keeps that to the end (16 points where 220 belong). After each level's start, whole kernels
// move from pieces holding too much weight to pieces holding too little, where that brings both nearer
// their shares; the finer the level, the lighter its kernels, and on the finest every piece is within a
// point of its share.
#pragma once

#include <cstdint>
#include <vector>

#include "sampler/chain.h"
#include "sampler/grid.h"
#include "sampler/particle.h"

namespace kdm::gen {

/// The connected pieces of one level's support: nodes with ρ > 0, joined across faces (periodic on a
/// torus).
struct SupportPieces {
  std::vector<std::int32_t> piece;  ///< per node, its piece, or -1 where ρ is 0
  std::vector<double> mass;         ///< per piece, Σρ over its nodes
};

/// The pieces of `level`'s support, or none (both vectors empty) when it is one piece: then there is
/// nothing to balance.
template <int D>
SupportPieces support_pieces(const DensityGrid<D>& level);

/// Moves whole kernels (every one of them in `chain`'s R, positions in its grid's units) between the
/// `pieces` of the chain's grid while a move brings a piece holding more than its share of the kernels'
/// weight and one holding less both nearer their shares (a piece's share: its part of Σρ). A move takes the
/// kernel nearest the surplus piece's node of highest R = A − ρ to the deficit piece's node of lowest R,
/// where the level's sweeps then relax it. Returns how many kernels moved. Not thread-safe.
template <int D>
std::int64_t balance_pieces(Chain<D>& chain, std::vector<Particle<D>>& particles,
                            const SupportPieces& pieces);

}  // namespace kdm::gen
