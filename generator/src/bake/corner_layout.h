// The geometry of corner tiles (A. Lagae, P. Dutré, "An alternative for Wang tiles: colored edges versus
// colored corners", ACM TOG 25(4), 2006), as kdm bakes them with nested density levels.
//
// World space is cut into unit tiles whose integer vertices carry colours. Around every vertex lies a
// corner patch (|x − v|∞ < h) that depends on that vertex's colour only; along every edge between two
// corner patches lies an edge patch (|y − edge| < b, b < h) that depends on its two end colours; what
// remains of a tile is its interior, which depends on all four corner colours. A tile (sw, se, ne, nw) is
// the union of its quarters of four corner patches, halves of four edge patches and its interior, so tiles
// that agree on shared corner colours agree on everything near their shared edges: no seams. Edge patches
// are narrower than corner patches so that a horizontal and a vertical one never meet (they would at the
// corner patch's corners, and each depends on a colour the other does not know): the interior, sampled
// last with everything fixed, fills the gap of h − b between them.
//
// Nested levels: level k's half-width h_k shrinks with k by `erosion` times level k's point spacing, so
// a level-k corner (edge) patch only ever sees level-<k points of the corner (corner and edge) patches of
// the same colours within that distance: the context it was sampled in is the same in every tile.
//
// Thread safety: plain values and pure functions.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

namespace kdm::gen {

enum class PatchKind : int { kCorner = 0, kHorizontalEdge = 1, kVerticalEdge = 2, kInterior = 3 };

/// Points of one patch relative to its anchor (the vertex of a corner patch; the left / bottom vertex of
/// an edge patch; the south-west corner of an interior), with their emission keys.
struct Patch {
  std::vector<double> xy;
  std::vector<std::uint16_t> keys;
  bool done = false;
  /// Glide track: frames[g] holds every point's position (relative to the anchor, like xy) at keyframe
  /// g; points not present there keep their stable position. Empty until keyframe g is relaxed.
  std::vector<std::vector<double>> frames;
  std::size_t size() const { return keys.size(); }
  void add(double x, double y, std::uint16_t key) {
    xy.insert(xy.end(), {x, y});
    keys.push_back(key);
  }
};

/// Every patch of one density level. Edge patches are indexed by (first, second) end colour:
/// first·C + second, left→right or bottom→top; interiors by TilesetShape::tile_index(sw, se, ne, nw).
struct LevelPatches {
  std::vector<Patch> corners, horizontal, vertical, interiors;
  explicit LevelPatches(std::uint32_t colours = 1)
      : corners(colours),
        horizontal(std::size_t(colours) * colours),
        vertical(std::size_t(colours) * colours),
        interiors(std::size_t(colours) * colours * colours * colours) {}
  std::vector<Patch>& of(PatchKind kind) {
    return kind == PatchKind::kCorner           ? corners
           : kind == PatchKind::kHorizontalEdge ? horizontal
           : kind == PatchKind::kVerticalEdge   ? vertical
                                                : interiors;
  }
  const std::vector<Patch>& of(PatchKind kind) const { return const_cast<LevelPatches*>(this)->of(kind); }
};

/// Vertex colours of a (finite or periodic) arrangement of tiles.
struct Colouring {
  std::uint32_t colours = 1;
  /// Colour of the integer vertex (vx, vy).
  std::function<std::uint32_t(std::int64_t, std::int64_t)> at;
  std::size_t tile_at(std::int64_t tx, std::int64_t ty) const {
    return ((std::size_t(at(tx, ty)) * colours + at(tx + 1, ty)) * colours + at(tx + 1, ty + 1)) * colours +
           at(tx, ty + 1);
  }
  /// A w×h torus of tiles whose vertex colours are `grid` (row-major, w·h values).
  static Colouring torus(std::uint32_t colours, int w, int h, std::vector<std::uint32_t> grid);
  /// The neighbourhood of tile `index` (sw, se, ne, nw): a 2×2 torus whose tile (0, 0) is that tile.
  static Colouring around_tile(std::uint32_t colours, std::size_t index);
};

/// Half-widths of one level's patches (tile units): corner patches h, edge patches b < h.
struct PatchWidths {
  double corner = 0, edge = 0;
};

/// Where a point at tile-space position (x, y) lies: the patch kind, the patch index under `colouring`,
/// its anchor and its position relative to the anchor.
struct Placement {
  PatchKind kind;
  std::size_t patch;
  std::int64_t anchor_x, anchor_y;
  double rx, ry;
  /// How deep (tile units) the point lies inside the region of a patch kind sampled before its own
  /// (place_new_point); 0 when it lies in its own kind's region.
  double slip = 0;
};
Placement classify(double x, double y, PatchWidths widths, const Colouring& colouring);

/// The patch of kind `kind` a point sampled for that kind's patches joins, if any. Like classify, but a
/// point that slipped into a region sampled before it (a patch of an earlier kind: corner < horizontal
/// edge < vertical edge < interior) stays with its own kind: it was sampled with that region fixed, and
/// every later patch is sampled with it fixed. Returns false for points that belong to later kinds.
bool place_new_point(double x, double y, PatchKind kind, PatchWidths widths, const Colouring& colouring,
                     Placement& out);

/// One point of a patch as gather() finds it: the patch, the point's index there and the anchor (minus the
/// window's origin) its copy hangs from.
struct PatchPointRef {
  const Patch* patch = nullptr;
  std::uint32_t index = 0;
  double anchor_x = 0, anchor_y = 0;
};

/// Appends the points of `level`'s patches of the given kinds that fall in the window [x0, x1) × [y0, y1)
/// (tile units) of the arrangement `colouring`, as (x − x0, y − y0) pairs to `xy` and their keys to `keys`
/// (optional) and where they come from to `refs` (optional). Patches not yet sampled are empty and add
/// nothing.
void gather(const LevelPatches& level, const Colouring& colouring, std::array<bool, 4> kinds, double x0,
            double y0, double x1, double y1, std::vector<double>& xy, std::vector<std::uint16_t>* keys,
            std::vector<PatchPointRef>* refs = nullptr);

/// One sampler run of the bake: a w×h torus of tiles with its vertex colours, producing the patches of
/// one stage (corners; horizontal edges; vertical edges; interiors) that are not done yet.
struct BakeRun {
  int stage = 0;  ///< the PatchKind it makes
  int w = 1, h = 1;
  std::vector<std::uint32_t> grid;  ///< vertex colours, row-major
};

/// The runs of one level (the same for every level), stage by stage: corners, horizontal edges, vertical
/// edges (after the horizontal ones, so that the 1×1 runs see both), interiors. Each patch comes from the
/// first run that holds it.
std::vector<BakeRun> plan_runs(std::uint32_t colours);

/// The patch half-widths of each level: corner h_0 = band, then shrinking by erosion / sqrt(points of
/// level k per tile) per level; edge b_k = h_k − edge_gap spacings of level k (H and V edge patches then
/// stay √2 · edge_gap spacings apart). Edge bands thus shrink by (erosion − edge_gap) spacings per level:
/// the margin between a level's edge patches and the interiors of the level before it. Empty if some b_k
/// would be below half a spacing of its own level (too thin to hold a patch).
std::vector<PatchWidths> patch_widths(double band, double erosion, double edge_gap,
                                      const std::vector<std::uint32_t>& nominal);

}  // namespace kdm::gen
