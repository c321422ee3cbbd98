// Labelled point sets (several classes, multi-class blue noise as in L.-Y. Wei, "Multi-class blue noise
// sampling", SIGGRAPH 2010): each class alone, and how close points of different classes come.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "kdm/analysis/density.h"
#include "kdm/analysis/report.h"
#include "point_io.h"

namespace kdm::analysis {

/// The classes present in `set` (ascending); empty for an unlabelled set.
std::vector<std::uint8_t> classes_present(const tools::PointSet& set);

/// The points of `set` whose class is `k`, unlabelled.
tools::PointSet class_subset(const tools::PointSet& set, std::uint8_t k);

/// The distance between the closest two points of different classes, in hexagonal spacings of the whole
/// set (hex_spacing(n)); NaN with fewer than two classes. With a target `density`, in local spacings
/// instead: each pair's distance over hex_spacing(n) · √(mean ρ / ρ) at its midpoint, among pairs within
/// two local spacings of a point (NaN if there are none). 2D points in [0, 1]²; `torus`: periodic
/// distances. Throws InvalidInput for an unlabelled or 3D set, or a density zero everywhere.
double cross_class_closest(const tools::PointSet& set, bool torus, const DensityFunction& density = {});

/// A class's count against the share of the points its density's integral predicts, when the classes'
/// densities are given together: p_k = ∫ρ_k / Σ_j ∫ρ_j (each integral a mean over a 256² grid of
/// midpoints, as density_scale takes it), as a multiclass sampler splits its points (gen::class_counts).
struct ClassShare {
  std::uint8_t cls = 0;
  double share = 0;       ///< p_k, the predicted fraction of all points
  std::size_t count = 0;  ///< the class's points, summed over the sets
  double expected = 0;    ///< Σ over sets of n_set · p_k
  /// Binomial sd of the count, √(Σ n_set · p_k (1 − p_k)): what independent draws of each point's class
  /// would scatter by. A sampler that fixes its counts (gen::sample_classes) lies far inside it.
  double sd = 0;
  double z = 0;  ///< (count − expected) / sd; 0 when sd = 0 (then count = expected)
};

/// Each class's count over `sets` against the share of the points its density's integral predicts
/// (ClassShare), one per density: `densities` hold one per class, class 0 first, at least as many as the
/// labels run (largest label + 1; classes after it have no points, as a sampled class of density 0).
/// Throws InvalidInput for fewer densities, an empty one, one negative or not finite, a class with points
/// whose density is zero everywhere, or densities all zero: the checks analyze_classes makes, for a caller
/// that wants them before it measures anything.
std::vector<ClassShare> class_shares(const std::vector<tools::PointSet>& sets,
                                     const std::vector<DensityFunction>& densities);

/// Labelled sets analysed class by class: each class alone as the whole sets are (analyze), and the
/// closest pair of points of different classes over the sets.
struct ClassesReport {
  double cross_class_closest =
      0;  ///< d_hex of all points (local, with a density); NaN when no two classes meet
  std::vector<std::uint8_t> classes;    ///< analysed, ascending
  std::vector<AnalysisReport> reports;  ///< one per analysed class
  std::vector<std::uint8_t> too_small;  ///< present, but with fewer than 2 points in every set
  /// With class densities: one per class 0 … K−1 (those without points too), else empty.
  std::vector<ClassShare> shares;
};

/// E/n of class `k`'s points (its subsets of the sets; see AnalysisReport::energy_per_point).
using ClassEnergy = std::function<double(std::uint8_t k, const std::vector<tools::PointSet>& subsets)>;

/// The sum of `densities` (each called at every point; empty ones count as 0): the union's target when
/// classes have densities of their own. Empty for an empty list.
DensityFunction summed_density(const std::vector<DensityFunction>& densities);

/// Each class of `sets` (every set labelled; else InvalidInput) alone, under `options`; `energy`, if set,
/// gives each class's E/n from its subsets.
///
/// `class_densities` (optional): one target density per class, class 0 first, at least as many as the
/// labels run (largest label + 1 over all sets; classes without points may have any density, 0 too). Each
/// class is then judged against its own density instead of options.density: density windows, per-band
/// bias, empty circles in local spacings of its density, the spectrum's non-uniform note. Only each
/// density's shape matters there (the windows are normalised to the class's count); their scales together
/// predict each class's share of the points (ClassesReport::shares), so give them as the sampler had them
/// (kdm sample --class: const:1 and const:2 give a third and two thirds). The closest pair of different
/// classes is then in local spacings of their sum (summed_density). The union itself is the caller's
/// analyze(): its target is options.density if the caller chose one, else summed_density(class_densities).
/// Throws InvalidInput for fewer densities than the labels run to, an empty density, one that is negative
/// or not finite, a class with points whose density is zero everywhere, densities all zero, or
/// options.extent other than a square's (cube's).
ClassesReport analyze_classes(const std::vector<tools::PointSet>& sets, const AnalysisOptions& options,
                              const ClassEnergy& energy = {},
                              const std::vector<DensityFunction>& class_densities = {});

/// The shares' text for a summary: a heading and one line per class (count, expected ± sd, share, z);
/// "" without class densities.
std::string format_class_shares(const ClassesReport& report);

/// classes.json's text: {"cross_class_closest": …, "classes": [{"class": k, "metrics": {metrics.json}}],
/// "too_small": [classes with fewer than 2 points in every set]}, and with class densities "shares":
/// [{"class": k, "share": p_k, "count": …, "expected": …, "sd": …, "z": …}] (ClassShare).
std::string classes_json(const ClassesReport& report, const std::vector<std::string>& inputs);

}  // namespace kdm::analysis
