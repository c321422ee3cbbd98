// One-call analysis of a collection of point sets: reads the sets (UTK/psa text format via
// kdm::tools::read_point_sets), runs every metric of docs/design.md §6 that applies (NN statistics,
// periodogram and RAPS statistics, g(r), density accuracy, tiling diagnostics) and formats a short text
// summary.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "kdm/analysis/common.h"
#include "kdm/analysis/density.h"
#include "kdm/analysis/empty_circles.h"
#include "kdm/analysis/nearest_neighbour.h"
#include "kdm/analysis/pair_correlation.h"
#include "kdm/analysis/periodogram.h"
#include "kdm/analysis/tiling.h"
#include "point_io.h"

namespace kdm::analysis {

/// Reads and concatenates the sets of every file in `paths` (in order). Throws InvalidInput with a one-line
/// message for a missing/empty/malformed/non-finite file, mixed dimensions or points outside [0,1]. With
/// `warnings`, appends a line for what reads but is likely a mistake (a file of 3D points whose z are all
/// 0 or 1: a class column without a header). Thread-safe (touches only the named files).
std::vector<tools::PointSet> load_point_sets(const std::vector<std::string>& paths,
                                             std::vector<std::string>* warnings = nullptr);

struct AnalysisOptions {
  bool torus = true;             ///< periodic distances (else bounded box)
  double fmax = 2.5;             ///< periodogram limit in normalised frequency f = |k|/√n (2D only)
  bool spectrum = true;          ///< compute the periodogram (2D)
  double gr_rmax = 3.0;          ///< g(r) range, units of the reference spacing
  int gr_bins = 60;              ///< g(r) bins
  DensityFunction density;       ///< target density for the density test (empty: skip)
  double min_expected = 20;      ///< density-test windows expect at least this many points
  int density_bands = 10;        ///< bands of the per-band bias table (equal steps in log ρ)
  double tile_size = 0;          ///< tile side for the tiling diagnostics (0: skip)
  double holes_min_density = 0;  ///< empty circles: only where ρ ≥ this fraction of its largest value
  /// Relative side lengths x y z of the domain the points were drawn in (as gen::SamplerOptions::extent;
  /// the first `dim` are read): the normalised points are measured in that box scaled to unit area
  /// (volume), common.h's unit_measure_sides. Tiling diagnostics and classes need equal sides.
  double extent[3] = {1, 1, 1};
  int threads = 0;  ///< worker threads, 0 = gen::default_thread_count()
  /// Called from the calling thread between the measures and the sets (optional): an exception it throws
  /// stops the analysis there (Python's Ctrl-C).
  std::function<void()> checkpoint;
};

struct AnalysisReport {
  int dim = 2;
  bool torus = true;
  Sides sides = kUnitSides;  ///< the domain the sets were measured in (unit area or volume)
  std::size_t sets = 0, points_min = 0, points_max = 0;
  double points_mean = 0;
  NNStats nn;                        ///< pooled over sets, each normalised by its own spacing (spacing = 1)
  std::vector<double> dmin_per_set;  ///< δmin of each set
  double dmin_mean = 0;              ///< mean of dmin_per_set (nn.dmin is the worst)
  std::size_t coincident = 0;  ///< points at distance 0 from another (duplicates): holes and g(r) mislead
  bool has_spectrum = false;
  std::string spectrum_skipped;  ///< why a 2D analysis has none (sets more than 10% apart in count), or ""
  Periodogram spectrum;          ///< set-averaged periodogram
  SpectrumStats spectrum_stats;
  /// Why the set is not uniform (a target density that varies; window counts far beyond Poisson), or "":
  /// then the spectrum's low frequencies measure the density's own variation, not blue-noise quality.
  std::string spectrum_nonuniform;
  PairCorrelation gr;
  bool has_empty_circles = false;     ///< 2D sets of at least 3 points that span an area
  std::string empty_circles_skipped;  ///< why a 2D analysis has none (few or degenerate points), or ""
  EmptyCircles empty_circles;         ///< holes: radii in local d_hex (of the target density, if given)
  bool has_density = false;
  DensityAccuracy density;  ///< pooled: rms/max over all windows of all sets, summed counts
  /// The windows' least expected count asked for: a set with fewer points has one window (z = 0).
  double density_min_expected = 0;
  bool has_tiling = false;
  double tile_size = 0;
  PeriodicityResult periodicity;  ///< needs the spectrum (NaN ratio otherwise)
  SeamStats seams;
  EdgeBands edges;     ///< density near tile edges (2D)
  double seconds = 0;  ///< wall time of analyze()
  /// E / n under the KDM model (mean over sets). The analysis library has no model of its own: callers
  /// that link the generator fill this in (kdm analyze does, via kdm::gen::energy_per_point).
  bool has_energy = false;
  double energy_per_point = 0;
};

/// Runs the analysis. Throws InvalidInput for an empty list, mixed dimensions, invalid points, sets with
/// fewer than 2 points, or invalid options (among them sides that are not positive finite numbers, and a
/// tile size with unequal sides). Thread-safe (no shared state).
AnalysisReport analyze(const std::vector<tools::PointSet>& sets, const AnalysisOptions& options);

/// A one-screen human-readable summary of `report` (several lines, '\n'-terminated). Thread-safe.
std::string format_summary(const AnalysisReport& report);

}  // namespace kdm::analysis
