// Internal: the two ways empty_circles copies a torus set around the unit square before triangulating it,
// for the test that both find the same circles.
#pragma once

#include <vector>

namespace kdm::analysis::detail {

enum class TorusCopies {
  kAroundHoles,  ///< copies only where a circle through the square may reach (what empty_circles uses)
  kMargin,       ///< copies in a margin around the whole square, widened until every circle lies in it
};

/// The circumradii of a torus set's (distinct, 2D, interleaved) Delaunay triangles, each once, in the order
/// found. kAroundHoles returns none where empty_circles falls back to kMargin (a flat triangle). A torus of
/// sides lx × ly takes `coords` in its lengths.
std::vector<double> torus_circumradii(const std::vector<double>& coords, TorusCopies copies, double lx = 1,
                                      double ly = 1);

}  // namespace kdm::analysis::detail
