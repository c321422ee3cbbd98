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

/// Labelled sets analysed class by class: each class alone as the whole sets are (analyze), and the
/// closest pair of points of different classes over the sets.
struct ClassesReport {
  double cross_class_closest =
      0;  ///< d_hex of all points (local, with a density); NaN when no two classes meet
  std::vector<std::uint8_t> classes;    ///< analysed, ascending
  std::vector<AnalysisReport> reports;  ///< one per analysed class
  std::vector<std::uint8_t> too_small;  ///< present, but with fewer than 2 points in every set
};

/// Each class of `sets` (every set labelled; else InvalidInput) alone, under `options`; `energy`, if set,
/// gives each class's E/n from its subsets.
ClassesReport analyze_classes(const std::vector<tools::PointSet>& sets, const AnalysisOptions& options,
                              const std::function<double(const std::vector<tools::PointSet>&)>& energy = {});

/// classes.json's text: {"cross_class_closest": …, "classes": [{"class": k, "metrics": {metrics.json}}],
/// "too_small": [classes with fewer than 2 points in every set]}.
std::string classes_json(const ClassesReport& report, const std::vector<std::string>& inputs);

}  // namespace kdm::analysis
