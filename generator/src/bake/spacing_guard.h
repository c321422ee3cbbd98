// A hard-core test for the baker's new points: constrained sampling with γ = 1 has a flat energy where the
// fixed points already cover the density (A ≥ ρ), so a new kernel that wanders into a fixed patch can
// settle on top of a fixed point (docs/design.md §3.4). The guard keeps every point at least a minimum
// distance from every point kept before it.
//
// Thread safety: a plain value; one guard per run.
#pragma once

#include <cstdint>
#include <vector>

namespace kdm::gen {

/// Points on a w×h torus (tile units) kept at least `min_distance` apart. A dense grid of cells about
/// one expected point spacing wide, each holding a linked list of its points: O(1) per test and insert.
class SpacingGuard {
 public:
  /// `expected_points`: about how many points will be added (sizes the grid; any count works).
  SpacingGuard(double width, double height, double min_distance, std::size_t expected_points);
  /// True if (x, y) is at least min_distance (torus distance) from every point added so far.
  bool clear(double x, double y) const;
  /// Adds (x, y) whether or not it is clear.
  void add(double x, double y);

 private:
  std::int64_t cell_of(double x, double y) const;
  double width_, height_, min_distance_, cell_ = 1;
  std::int64_t nx_ = 1, ny_ = 1;
  std::vector<std::int32_t> head_, next_;  // -1 ends a list
  std::vector<double> xy_;
};

}  // namespace kdm::gen
