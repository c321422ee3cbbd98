// Empty circles of a baker's run, found on a grid: with γ = 1 a constrained run that ends a point short
// pays the same energy whether the deficit is spread out or gathered in one hole, so patches can freeze
// a hole at their border (docs/design.md §3, "Holes and the tile lattice"). The baker fills the holes it
// finds with new points before ranking.
//
// Thread safety: a plain value; one finder per run.
#pragma once

#include <cstddef>
#include <vector>

namespace kdm::gen {

/// The distance from every node of a grid over a w×h torus (tile units) to the nearest of a set of
/// points: a node farther than r from every point is the centre of an empty circle of radius r. Nodes
/// are `step` apart, so the largest empty circle is found to within step / √2.
class HoleFinder {
 public:
  /// `points`: x y pairs on the torus. `reach`: distances beyond it are not resolved (they read as reach).
  HoleFinder(double width, double height, double step, double reach, const std::vector<double>& points);
  /// Adds a point, shrinking the distances of the nodes within reach of it.
  void add(double x, double y);
  /// The nodes farther than `radius` from every point, deepest first, as x y pairs.
  std::vector<double> centres_beyond(double radius) const;

 private:
  double height_, step_, reach_;
  std::size_t nx_, ny_;
  std::vector<float> distance_;  ///< per node, row-major; at most reach
};

}  // namespace kdm::gen
