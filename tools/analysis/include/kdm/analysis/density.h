// Density accuracy of a 2D point set against a target density over the unit square: the square is cut
// into windows of (nearly) equal expected count μ ≥ min_expected (a k-d tree of equal-mass splits of the
// rasterised density), and each window gets z = (count − μ)/√μ. A uniform random set gives RMS z ≈ 1
// (binomial counts); blue-noise and stratified sets give RMS z < 1; bias shows in the totals.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

namespace kdm::analysis {

/// Target density ρ(x, y) ≥ 0 on [0,1]² (x right, y up; any scale — it is normalised). Must be a pure
/// function (called from one thread only).
using DensityFunction = std::function<double(double x, double y)>;

struct DensityOptions {
  double min_expected = 20;  ///< every window has expected count μ ≥ this (unless the whole set has fewer)
  double expected_total = 0;  ///< expected total count; 0 = the set's own point count
  int raster = 0;             ///< density raster per axis; 0 = automatic (≥ 8 cells per window side)
};

struct DensityAccuracy {
  std::size_t points = 0;    ///< points in the set
  std::size_t windows = 0;   ///< windows with μ > 0
  double mean_expected = 0;  ///< mean μ over those windows
  double rms_z = 0;          ///< sqrt(mean z²) over those windows
  double max_abs_z = 0;      ///< max |z|
  double bias = 0;  ///< (Σcount − Σμ) / Σμ over windows with μ > 0 (zero-density points excluded)
  std::size_t zero_density = 0;  ///< points where ρ(point) = 0 (not counted in any window)
};

/// Measures one 2D set (interleaved x y in [0,1]²) against `density`. Throws InvalidInput for invalid
/// points, dim ≠ 2, a density that is negative, non-finite or zero everywhere, or min_expected ≤ 0.
/// Thread-safe if `density` is.
DensityAccuracy density_accuracy(const std::vector<double>& coords, int dim, const DensityFunction& density,
                                 const DensityOptions& options = {});

}  // namespace kdm::analysis
