// Keeps the points of the glide track apart: at a keyframe (separate_points) and on the straight paths
// between two keyframes (separate_paths).
//
// With γ = 1 the energy's pull towards a gap next to a point is as strong as the push of overlapping
// kernels, so a descent can settle a point right beside another one. And smooth queries move every point
// linearly from its position at one keyframe to its position at the next (kdm/runtime/query.h). Two points
// that are well apart at both keyframes can still pass close to each other on the way: a point entering next
// to one that is still moving away, or two neighbours turning around each other. separate_paths() finds such
// pairs and moves the ends it may move (the later keyframe's positions, and the entry point of a point that
// appears between the keyframes) just far enough apart, so that no pair comes closer than the radius at any
// fraction where both are shown.
//
// Thread safety: plain functions over caller-owned data.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

namespace kdm::gen {

/// Pushes apart the moving points (indices into xy, torus coordinates) that lie closer than `r` to any
/// other point, moving or fixed (`fixed`: coordinates normalised to the unit square), in up to 4 passes.
/// After each pass confine(xy, i) may pull point i back into where it may be.
void separate_points(std::vector<double>& xy, const std::vector<std::size_t>& moving,
                     const std::vector<double>& fixed, int w, int h, double r,
                     const std::function<void(std::vector<double>&, std::size_t)>& confine);

/// One point's path on a w×h torus between keyframes g − 1 (fraction 0, at a) and g (fraction 1, at b).
/// It is shown from fraction `appear` on (0 for a point present at g − 1), up to `vanish` (an obstacle
/// known only near the start).
struct GlidePath {
  double ax = 0, ay = 0, bx = 0, by = 0;
  double appear = 0, vanish = 1;
  bool move_a = false, move_b = false;  ///< which ends may be moved
  bool obstacle = false;                ///< only paths whose entry may move keep off it
};

/// The shortest distance between paths p and q over the fractions where both are shown, on a w×h torus,
/// and the fraction t where it is reached (infinity if they are never shown together).
double closest_approach(const GlidePath& p, const GlidePath& q, int w, int h, double& t);

/// Moves the movable ends of paths that come closer than radius(t) (torus units, t the fraction) until
/// none does, or `passes` passes are done. `max_radius` bounds radius(t). After each move,
/// confine(path, index) may pull the ends back into where the point may be (it must keep them on the
/// torus's [0, w) × [0, h)). Returns how many pairs were still too close in the last pass.
std::size_t separate_paths(std::vector<GlidePath>& paths, int w, int h,
                           const std::function<double(double)>& radius, double max_radius,
                           const std::function<void(GlidePath&, std::size_t)>& confine, int passes);

}  // namespace kdm::gen
