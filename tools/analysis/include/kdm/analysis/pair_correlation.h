// The pair-correlation function g(r) of 2D/3D point sets, normalised so that a uniform random (binomial /
// Poisson) set gives g ≡ 1: g(bin) = Σ_pairs w / (n(n−1) · |shell|), ordered pairs, w = 1 on the torus and
// the translation edge correction w = 1 / Π_a (1 − |Δ_a|) in the box (Ohser & Stoyan's estimator).
#pragma once

#include <cstddef>
#include <vector>

#include "kdm/analysis/common.h"
#include "point_io.h"

namespace kdm::analysis {

/// g(r) on `bins` equal bins of r / spacing over [0, r_max) (spacing = d_hex in 2D, FCC spacing in 3D).
struct PairCorrelation {
  double spacing = 0;     ///< reference spacing of the (mean) point count, unit-domain lengths
  double r_max = 0;       ///< upper end, in units of spacing (clamped to half the shortest side)
  std::vector<double> r;  ///< bin centres, units of spacing
  std::vector<double> g;  ///< g at those bins (dimensionless; 1 = uncorrelated)
};

/// g(r) pooled over `sets` (numerators and expected counts are summed over sets, each set using its own n).
/// `r_max` in units of the reference spacing (default 3), `bins` ≥ 1. O(n · pairs within r_max) with a cell
/// list. `sides`: the domain's (common.h; the unit square's by default). Throws InvalidInput for
/// empty/invalid sets or mixed dimensions. Thread-safe; `threads` 0 = gen::default_thread_count().
PairCorrelation pair_correlation(const std::vector<tools::PointSet>& sets, bool torus, double r_max = 3.0,
                                 int bins = 60, int threads = 0, const Sides& sides = kUnitSides);

}  // namespace kdm::analysis
