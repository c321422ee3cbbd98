// Density accuracy of a 2D point set against a target density over the unit square: the square is cut
// into windows of (nearly) equal expected count μ ≥ min_expected (a k-d tree of equal-mass splits of the
// rasterised density), and each window gets z = (count − μ)/√μ. A uniform random set gives RMS z ≈ 1
// (binomial counts); blue-noise and stratified sets give RMS z < 1; bias shows in the totals.
// Density bands pool the same counts by target density instead of by place: the raster cells whose ρ lies
// in a band, the points in them against the count those cells should hold. A sampler that gives sparse
// regions too few points shows it there, where window z-scores of ~20 points each cannot.
#pragma once

#include <cstddef>
#include <functional>
#include <utility>
#include <vector>

#include "kdm/analysis/common.h"

namespace kdm::analysis {

/// Target density ρ(x, y) ≥ 0 on [0,1]² (x right, y up; any scale — it is normalised). Must be a pure
/// function (called from one thread only).
using DensityFunction = std::function<double(double x, double y)>;

struct DensityOptions {
  double min_expected = 20;  ///< every window has expected count μ ≥ this (unless the whole set has fewer)
  double expected_total = 0;  ///< expected total count; 0 = the set's own point count
  int raster = 0;             ///< density raster per axis; 0 = automatic (≥ 8 cells per window side)
  /// The domain's sides (common.h): a rectangle gets a raster of cells square in its lengths (`raster`
  /// along a side of 1) and windows about square there. Only x and y are read.
  Sides sides = kUnitSides;
  /// Bands of equal width in log ρ between the sparsest non-zero raster cell and the densest (one band
  /// when they differ by less than 1%).
  int bands = 10;
};

/// Raster cells whose target density, relative to the densest cell, lies in [lo, hi] (hi inclusive for
/// the densest band), with the points in them and the count they should hold.
struct DensityBand {
  double lo = 0, hi = 0;  ///< ρ / ρmax
  double expected = 0;    ///< Σμ of the band's cells
  double count = 0;       ///< points in those cells
  /// count / expected − 1: the band's relative bias (0 when nothing is expected).
  double bias() const { return expected > 0 ? count / expected - 1 : 0; }
};

struct DensityAccuracy {
  std::size_t points = 0;    ///< points in the set
  std::size_t windows = 0;   ///< windows with μ > 0
  double mean_expected = 0;  ///< mean μ over those windows
  double rms_z = 0;          ///< sqrt(mean z²) over those windows
  double max_abs_z = 0;      ///< max |z|
  double bias = 0;  ///< (Σcount − Σμ) / Σμ over windows with μ > 0 (zero-density points excluded)
  std::size_t zero_density = 0;    ///< points where ρ(point) = 0 (not counted in any window)
  std::vector<DensityBand> bands;  ///< sparsest first
};

/// Measures one 2D set (interleaved x y in [0,1]²; `density` takes the same normalised coordinates) against
/// `density`. Throws InvalidInput for invalid points, dim ≠ 2, a density that is negative, non-finite or zero
/// everywhere, min_expected ≤ 0, bands < 1 or sides that are not positive.
/// Thread-safe if `density` is.
DensityAccuracy density_accuracy(const std::vector<double>& coords, int dim, const DensityFunction& density,
                                 const DensityOptions& options = {});

/// Mean and largest ρ over the unit square, sampled on a 256² grid: the scale local spacings are taken
/// from (d_hex of the set's count where ρ is its mean, scaled by √(mean ρ / ρ) elsewhere).
std::pair<double, double> density_scale(const DensityFunction& rho);

}  // namespace kdm::analysis
