// Several classes from the full sampler: a KDM sample whose points carry classes, each class following
// its own density and all of them together the sum (multi-class blue noise, L.-Y. Wei, "Multi-class blue
// noise sampling", SIGGRAPH 2010). Built on constrained sampling (SamplerOptions::fixed_points), in
// priority order as the runtime's classes are: class 0 is a KDM sample at its own density; class k is then
// sampled with classes 0 … k−1 fixed, at the summed density of classes 0 … k, so it fills in around them.
// Fixed earlier classes keep the union from the spacing a free sample has (δavg .78 against .87 for
// 1 : 2 : 4), so all points are then relaxed together at the summed density for a few sweeps, which trades
// the earlier classes' spacing for the union's (docs/design.md, "Several classes", measures the trade).
#pragma once

#include <cstdint>
#include <vector>

#include "kdm/generator/sampler.h"

namespace kdm::gen {

/// sample_classes' joint sweeps by default: for 1 : 2 : 4, union δavg .870 (a free sample's .872) and
/// class 0 .781 (.871 before them); docs/design.md.
inline constexpr int kUnionSweeps = 30;

/// sample_classes' labelled points.
struct ClassSample {
  int dim = 2;                        ///< SamplerOptions::dim: 2 or 3
  std::vector<double> points;         ///< n * dim coordinates in [0, 1), class 0's points first
  std::vector<std::uint8_t> classes;  ///< each point's class
  std::vector<std::int64_t> counts;   ///< points per class
  std::vector<SampleReport> reports;  ///< one per run: each class with points, then the union's sweeps
  std::size_t size() const { return classes.size(); }
};

/// How `n` points split over classes of the given densities: in proportion to each density's integral
/// over the domain, rounded so the counts sum to exactly n. Throws InvalidArgument when every density is
/// zero.
std::vector<std::int64_t> class_counts(const SamplerOptions& options, const std::vector<Density>& densities,
                                       std::int64_t n);

/// The sum of densities (an image when all of them are images of one size or constants, else a function
/// calling each, with a batch function when any of them has one: positions of `dim` coordinates, 2 or 3).
Density sum_of_densities(const std::vector<Density>& densities, int dim = 2);

/// Samples options.n points (> 0) in 1 … 8 classes of `densities` (highest priority first), each class's
/// count from class_counts, every run seeded from options.seed and the class, then `union_sweeps` MH
/// sweeps of all points together at the summed density (0: none; classes keep their points). A point
/// where its class's density is zero then takes the class of the largest density there (a class never
/// lies where its density is zero), and gives its old class back the nearest point of its new one where
/// the old class's density is positive: the counts stay class_counts' (`counts` follow the labels, should
/// a class have no such point to take back).
/// Constrained-sampling and relaxation options (fixed_points, initial_points) must be empty. Seeded,
/// thread-independent as sample(). Throws InvalidArgument on bad options or densities.
ClassSample sample_classes(const SamplerOptions& options, const std::vector<Density>& densities,
                           int union_sweeps = kUnionSweeps);

}  // namespace kdm::gen
