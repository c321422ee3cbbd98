// Holes in a 2D point set: the empty circles of its Delaunay triangulation (each triangle's circumcircle
// holds no point), their radii in local hexagonal spacings (docs/design.md §6). A good blue-noise set has
// none larger than about 0.8 d_hex; a missing point leaves one near 1.0, and one tile edge that two
// patches both avoided leaves a row of them.
#pragma once

#include <cstddef>
#include <vector>

#include "kdm/analysis/common.h"
#include "kdm/analysis/density.h"
#include "point_io.h"

namespace kdm::analysis {

struct EmptyCircleOptions {
  bool torus =
      true;  ///< periodic (else a box: circles centred within `border` spacings of a side are left out)
  /// Box sets: the spacings between a judged circle's centre and the window's sides. A rule on the centre
  /// alone, so that a large circle is no likelier left out than a small one; two spacings put every
  /// circle up to that radius wholly inside, away from the sides' half-empty triangles.
  double border = 2;
  /// Target density: radii are divided by the local spacing at each circle's centre (d_hex of the set's
  /// count, scaled by √(mean ρ / ρ(centre))); circles centred where ρ = 0 are left out. Empty: uniform.
  DensityFunction density;
  double tile_size = 0;  ///< > 0: also count the large circles centred within one spacing of a tile edge
  /// The domain's sides (common.h; only x and y are read): a rectangle's set is triangulated in its own
  /// lengths, its torus copies shifted by them, a box's border kept inside them. Tiles need the square.
  Sides sides = kUnitSides;
  /// With a density: judge only circles centred where ρ is at least this fraction of its largest value
  /// (e.g. 0.5: the dark half of a stippled picture).
  double min_relative_density = 0;
  /// Sets triangulated at once (0: the default thread count); the result does not depend on it. With
  /// more than one, `density` is called from several threads.
  int threads = 1;
};

/// Thrown for a set whose points span no area (all coincident or on one line): it has no triangulation.
struct DegenerateSet : InvalidInput {
  using InvalidInput::InvalidInput;
};

struct EmptyCircles {
  std::size_t points = 0;     ///< points of the sets, pooled
  std::size_t triangles = 0;  ///< Delaunay triangles judged
  double largest = 0;         ///< largest circumradius / local d_hex
  /// Where the largest is: its set (0-based, in the order given) and its centre in the set's coordinates
  /// ([0, 1), wrapped on a torus).
  std::size_t largest_set = 0;
  double largest_x = 0, largest_y = 0;
  double p999 = 0;                         ///< its 99.9th percentile (nearest rank) over the judged triangles
  std::size_t over_085 = 0, over_100 = 0;  ///< triangles with a radius above 0.85 and 1.0 local d_hex
  std::size_t over_085_near_edge = 0;      ///< of over_085, centred within one spacing of a tile edge
  double near_edge_share = 0;  ///< the share of the judged triangles centred there (what even spread gives)
  /// The points the judged triangles stand for: half their count (a triangulation has two triangles per
  /// point), so that a rate does not depend on how much of a box's border or of a density's pale part was
  /// left out. A torus without a density: exactly `points`.
  double judged_points() const { return 0.5 * double(triangles); }
  double over_085_per_1e5() const { return triangles ? over_085 * 1e5 / judged_points() : 0; }
  double over_100_per_1e5() const { return triangles ? over_100 * 1e5 / judged_points() : 0; }
};

/// Empty circles pooled over `sets` (2D, each of at least 3 points, in [0,1]²; each normalised by its own
/// count). Throws DegenerateSet for a set that spans no area, InvalidInput for other input (tile_size with
/// a rectangle's sides too). O(n log n) (Qhull's Delaunay triangulation).
EmptyCircles empty_circles(const std::vector<tools::PointSet>& sets, const EmptyCircleOptions& options = {});

}  // namespace kdm::analysis
