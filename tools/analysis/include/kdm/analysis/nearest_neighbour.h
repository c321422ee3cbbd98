// Nearest-neighbour (NN) statistics of a point set (docs/design.md §6): per-point NN distance and index, and
// the summary δmin, δavg, NN1% (1st percentile) and a histogram, all normalised by the reference spacing
// (d_hex in 2D, FCC spacing in 3D). Uses a uniform cell list: O(n) expected time.
#pragma once

#include <cstddef>
#include <vector>

#include "kdm/analysis/common.h"

namespace kdm::analysis {

/// Per-point nearest neighbours. distance[i] is in unit-domain lengths (not normalised; the domain's, of
/// unit area or volume, for other sides); index[i] is the neighbour's point index; offset[i*dim + a] is the
/// displacement to that neighbour along axis a in the same lengths (the minimum image on the torus), so the
/// link can be located (e.g. whether it crosses a tile edge).
struct NearestNeighbours {
  int dim = 2;
  std::vector<double> distance;
  std::vector<std::size_t> index;
  std::vector<double> offset;
};

/// Finds every point's nearest other point. `coords`: interleaved, `dim` ∈ {2,3}, in [0,1]^dim; `torus`:
/// periodic distances. Ties go to the lowest index. Needs n ≥ 2 (throws InvalidInput otherwise, and for
/// invalid coordinates). `threads`: 0 = gen::default_thread_count(). `sides`: the domain's (common.h; the
/// unit square's by default), as unit_measure_sides gives them. Thread-safe (no shared state); result
/// independent of the thread count.
NearestNeighbours nearest_neighbours(const std::vector<double>& coords, int dim, bool torus, int threads = 0,
                                     const Sides& sides = kUnitSides);

/// Summary of NN distances, normalised by the reference spacing.
struct NNStats {
  std::size_t count = 0;  ///< number of distances summarised
  double spacing = 0;     ///< the reference spacing used (unit-domain lengths)
  double dmin = 0;        ///< δmin: min NN distance / spacing
  double davg = 0;        ///< δavg: mean NN distance / spacing
  double nn1 = 0;         ///< NN1%: 1st percentile (nearest-rank) of NN distance / spacing
  double dmax = 0;        ///< max NN distance / spacing
  double hist_max = 0;  ///< histogram covers [0, hist_max) in normalised units; last bin also counts overflow
  std::vector<std::size_t> histogram;
  std::size_t overflow = 0;  ///< distances ≥ hist_max: counted in the histogram's last bin
};

/// Summarises `distances` (unit-domain lengths) divided by `spacing`. Empty input gives count 0 and NaN
/// statistics. `bins` histogram bins over [0, hist_max). Thread-safe (pure).
NNStats summarise_nn(const std::vector<double>& distances, double spacing, int bins = 60,
                     double hist_max = 1.5);

/// nearest_neighbours + summarise_nn with spacing = reference_spacing(dim, n).
NNStats nn_stats(const std::vector<double>& coords, int dim, bool torus, int threads = 0,
                 const Sides& sides = kUnitSides);

/// The q-quantile (q in [0,1]) of `values` by the nearest-rank rule (value of rank ceil(q·m), ≥ 1).
/// Returns NaN for empty input. Thread-safe (works on a copy).
double quantile(std::vector<double> values, double q);

}  // namespace kdm::analysis
