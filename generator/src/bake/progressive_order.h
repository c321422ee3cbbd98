// Progressive ranking of a patch's new points (void-and-cluster), which gives each its emission key:
// an internal of the baker (bake.cpp), declared here for it and its tests.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace kdm::gen {

/// Input of progressive_order: positions in tile units on a width × height torus.
struct RankingInput {
  double width = 1, height = 1;
  std::vector<double> candidates;         ///< x y pairs to rank
  std::vector<double> fixed;              ///< present from the start
  std::vector<double> timed;              ///< present once the ranking reaches their key:
  std::vector<std::uint16_t> timed_keys;  ///< before candidate s of n is chosen, keys < rank_key(s, n)
  /// x y pairs present in proportion: before candidate s of n is chosen, each weighs s / n of a point.
  /// Stand-ins for regions ranked apart that fill at the same pace, so that no candidate sees a void
  /// there that the runtime will have filled.
  std::vector<double> pending;
  double filter_width = 0.1;    ///< σ of the Gaussian filter at the first pick, tile units
  double filter_width_end = 0;  ///< σ at the last pick (0: the same); 1/σ² moves linearly
};

/// The emission key of the s-th of n ranked points: floor((s + ½) / n · 65536).
std::uint16_t rank_key(std::size_t s, std::size_t n);

/// The progressive order of the candidates: indices, first = rank 0; each next one is the candidate in
/// the deepest void of a Gaussian-filtered density of everything present. O(n log n) for a filter a few
/// spacings wide. Deterministic.
std::vector<std::uint32_t> progressive_order(const RankingInput& input);

}  // namespace kdm::gen
