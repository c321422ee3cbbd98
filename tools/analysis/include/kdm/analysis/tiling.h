// Tiling diagnostics for point sets assembled from square tiles of side s (1/s an integer):
//  - periodicity ratio: mean periodogram power at the tile-lattice frequencies k = (i/s, j/s) ≠ 0 with
//    |k| inside the analysed rings, divided by the mean RAPS of the rings holding those |k|. ≈ 1 when tiles
//    do not repeat; ≫ 1 (up to the number of tiles) for a strictly periodic tiling.
//  - seam statistics: each point's nearest-neighbour link is "seam" when it crosses a tile edge (the domain
//    edge counts on the torus), else "interior"; δmin/δavg/NN1% per group and a two-sample Kolmogorov–Smirnov
//    test of the two normalised NN-distance distributions. Caveat: the split is not neutral — a longer link
//    is more likely to cross an edge, so even an untiled set shows seam δavg slightly above interior δavg
//    and, with many points, a small KS p-value (docs/design.md §6). Compare against the same statistics
//    of an untiled set of the same kind.
//  - edge bands: the point density at each distance from the nearest tile edge, in steps of a quarter of
//    the hexagonal spacing d_hex up to 2 d_hex, against the set's mean density. Tiles whose edges hold too
//    few or too many points show as lines in a blurred picture; this measures them.
#pragma once

#include <cstddef>
#include <limits>
#include <vector>

#include "kdm/analysis/nearest_neighbour.h"
#include "kdm/analysis/periodogram.h"
#include "point_io.h"

namespace kdm::analysis {

/// Returns the number of tiles per axis, round(1/s); throws InvalidInput unless 0 < s ≤ 1 and 1/s is an
/// integer (within 1e-6). Thread-safe.
int tiles_per_axis(double tile_size);

struct PeriodicityResult {
  std::size_t frequencies = 0;  ///< lattice frequencies used
  double mean_power = 0;        ///< mean P at them
  double mean_raps = 0;         ///< mean RAPS of their rings
  double ratio = 0;             ///< mean_power / mean_raps (NaN when no lattice frequency is in range)
  /// The tile lattice's own frequencies, up to two whole cycles per tile on either axis (k = (i, j) · tiles
  /// per axis, 1 ≤ max(|i|, |j|) ≤ 2): mean P there over the mean P of their eight off-lattice neighbours
  /// (k ± 1). 1: the lattice does not show; a repeated motif raises it by about the number of tiles. NaN
  /// when they lie outside the periodogram; infinite for a strictly periodic set (no power off the lattice
  /// beyond the transform's rounding).
  double lattice_ratio = 0;
  /// The lattice frequencies lattice_ratio compares (0: NaN, none inside the periodogram), so that a JSON
  /// null (non-finite) reads as infinite when there were some.
  std::size_t lattice_frequencies = 0;
};

/// Periodicity ratio of a (set-averaged) periodogram `p` with radial statistics `stats` for tile side
/// `tile_size` (unit-domain lengths). Throws InvalidInput for a rectangle's periodogram (lx ≠ 1). Thread-safe
/// (pure).
PeriodicityResult periodicity_ratio(const Periodogram& p, const SpectrumStats& stats, double tile_size);

/// Two-sample Kolmogorov–Smirnov test.
struct KsResult {
  double statistic = 0;  ///< D = sup |F_a − F_b|
  double p_value = 1;    ///< asymptotic p (Kolmogorov distribution with Stephens' small-sample correction)
};

/// KS test of samples `a` and `b` (any units). Empty input gives D = 0, p = 1. Thread-safe (pure).
KsResult ks_two_sample(std::vector<double> a, std::vector<double> b);

/// One-sided two-sample Kolmogorov–Smirnov test of "a tends to be smaller than b": D+ = sup (F_a − F_b),
/// p ≈ exp(−2 m D+²) with m = n_a n_b / (n_a + n_b) (Smirnov's asymptotic bound). Seam defects shorten
/// nearest-neighbour links, so this asks whether links across seams are shorter than elsewhere. With
/// `up_to`, the supremum runs over values below it only (e.g. b's median: the short half). Empty input
/// gives D = 0, p = 1. Thread-safe (pure).
KsResult ks_smaller(std::vector<double> a, std::vector<double> b,
                    double up_to = std::numeric_limits<double>::infinity());

struct SeamStats {
  NNStats seam;      ///< NN links crossing a tile edge (normalised by the reference spacing)
  NNStats interior;  ///< NN links inside one tile
  KsResult ks;       ///< seam vs interior NN distances
};

/// Seam statistics pooled over `sets` (each set normalised by its own reference spacing), tile side
/// `tile_size`. Throws InvalidInput for invalid sets or tile size. Thread-safe; `threads` 0 =
/// gen::default_thread_count().
SeamStats seam_stats(const std::vector<tools::PointSet>& sets, bool torus, double tile_size, int threads = 0);

/// Seam statistics of one set from precomputed neighbours `nn` (from nearest_neighbours on `coords`).
/// Appends normalised NN distances to `seam` / `interior`. Thread-safe (pure).
void split_by_seam(const std::vector<double>& coords, int dim, const NearestNeighbours& nn, double tile_size,
                   std::vector<double>& seam, std::vector<double>& interior);

/// Density by distance from the nearest tile edge: band b holds the points whose distance to their tile's
/// nearest edge is in [b, b + 1) · d_hex / 4 (d_hex of each set's own count), for b < kBands.
struct EdgeBands {
  static constexpr int kBands = 8;
  double count[kBands] = {};     ///< points in each band, pooled over sets
  double expected[kBands] = {};  ///< their expected count at the mean density
  double ratio(int b) const { return expected[b] > 0 ? count[b] / expected[b] : 0; }
  /// The first spacing from the edges (bands 0–3): the figure to quote.
  double first_spacing_ratio() const {
    double c = 0, e = 0;
    for (int b = 0; b < 4; ++b) c += count[b], e += expected[b];
    return e > 0 ? c / e : 0;
  }
};

/// Adds one 2D set's points (interleaved x y in [0, 1)²) to `bands` for tile side `tile_size` (1/s an
/// integer). Throws InvalidInput for a bad tile size or dim != 2. Thread-safe (pure but for `bands`).
void add_edge_bands(const std::vector<double>& coords, int dim, double tile_size, EdgeBands& bands);

}  // namespace kdm::analysis
