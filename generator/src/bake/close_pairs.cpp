// Removing the later point of near-coincident pairs; see close_pairs.h.
#include "close_pairs.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <tuple>

#include "kdm/runtime/check.h"

namespace kdm::gen {
namespace {

/// One point of a tile, with what decides which of a pair goes: its threshold, then (for equal
/// thresholds) where it comes from.
struct Candidate {
  double x, y;
  float threshold;
  int kind;
  std::size_t level, patch;
  std::uint32_t index;
  const Patch* source;        ///< for its frames
  double anchor_x, anchor_y;  ///< of its patch, in the window
  auto order() const { return std::tie(threshold, kind, level, patch, index); }
};

using Victims = std::set<std::tuple<std::size_t, int, std::size_t, std::uint32_t>>;

/// The points of `levels` in the window [x0, x1) × [y0, y1) of the arrangement `col`.
std::vector<Candidate> collect(const std::vector<LevelPatches>& levels, const Colouring& col,
                               const TilesetShape& shape, double x0, double y0, double x1, double y1) {
  constexpr PatchKind kKinds[] = {PatchKind::kCorner, PatchKind::kHorizontalEdge, PatchKind::kVerticalEdge,
                                  PatchKind::kInterior};
  std::vector<Candidate> points;
  for (std::size_t k = 0; k < levels.size(); ++k)
    for (const PatchKind kind : kKinds) {
      std::array<bool, 4> only{};
      only[static_cast<int>(kind)] = true;
      std::vector<double> xy;
      std::vector<std::uint16_t> keys;
      std::vector<PatchPointRef> refs;
      gather(levels[k], col, only, x0, y0, x1, y1, xy, &keys, &refs);
      const std::vector<Patch>& patches = levels[k].of(kind);
      for (std::size_t i = 0; i < keys.size(); ++i)
        points.push_back({xy[2 * i], xy[2 * i + 1],
                          shape.emission_threshold(static_cast<std::uint32_t>(k), keys[i]),
                          static_cast<int>(kind), k, std::size_t(refs[i].patch - patches.data()),
                          refs[i].index, refs[i].patch, refs[i].anchor_x, refs[i].anchor_y});
    }
  return points;
}

/// Calls on_pair(later, earlier) for every pair of `points` (in a window `width` × `height`) closer than
/// `radius` of the later one.
template <class Radius, class OnPair>
void find_pairs(std::vector<Candidate> points, double width, double height, const Radius& radius,
                OnPair&& on_pair) {
  if (points.empty()) return;
  // Earlier points first; each point looks back for earlier ones within its own radius, on a grid whose
  // cells are the smallest radius wide (the largest radii, at the coarsest levels, are few).
  std::sort(points.begin(), points.end(),
            [](const Candidate& a, const Candidate& b) { return a.order() < b.order(); });
  const double cell = std::max(radius(points.back()), 1.0 / 1024);
  const int nx = static_cast<int>(std::ceil(width / cell)), ny = static_cast<int>(std::ceil(height / cell));
  std::vector<std::vector<std::uint32_t>> grid(std::size_t(nx) * ny);
  auto cell_x = [&](double v) { return std::clamp(static_cast<int>(v / cell), 0, nx - 1); };
  auto cell_y = [&](double v) { return std::clamp(static_cast<int>(v / cell), 0, ny - 1); };
  for (std::uint32_t i = 0; i < points.size(); ++i) {
    const Candidate& p = points[i];
    const double r = radius(p);
    for (int cy = cell_y(p.y - r); cy <= cell_y(p.y + r); ++cy)
      for (int cx = cell_x(p.x - r); cx <= cell_x(p.x + r); ++cx)
        for (std::uint32_t j : grid[std::size_t(cy) * nx + cx])
          if (std::hypot(points[j].x - p.x, points[j].y - p.y) < r) on_pair(p, points[j]);
    grid[std::size_t(cell_y(p.y)) * nx + cell_x(p.x)].push_back(i);
  }
}

/// Adds to `victims` the later of every two points of `at` (positions, in the order of `points`, which is
/// by Candidate::order) closer than `radius`; only the first `present` points are shown.
void find_close(const std::vector<Candidate>& points, const std::vector<double>& at, std::size_t present,
                double x0, double y0, double x1, double y1, double radius, Victims& victims) {
  const int nx = std::max(1, static_cast<int>((x1 - x0) / radius)),
            ny = std::max(1, static_cast<int>((y1 - y0) / radius));
  std::vector<std::vector<std::uint32_t>> grid(std::size_t(nx) * ny);
  auto cell_x = [&](double v) { return std::clamp(static_cast<int>((v - x0) / (x1 - x0) * nx), 0, nx - 1); };
  auto cell_y = [&](double v) { return std::clamp(static_cast<int>((v - y0) / (y1 - y0) * ny), 0, ny - 1); };
  for (std::uint32_t i = 0; i < present; ++i) {
    const double x = at[2 * i], y = at[2 * i + 1];
    if (x < x0 || x >= x1 || y < y0 || y >= y1) continue;
    for (int cy = cell_y(y - radius); cy <= cell_y(y + radius); ++cy)
      for (int cx = cell_x(x - radius); cx <= cell_x(x + radius); ++cx)
        for (std::uint32_t j : grid[std::size_t(cy) * nx + cx])
          if (std::hypot(at[2 * j] - x, at[2 * j + 1] - y) < radius) {
            const Candidate& p = points[i];
            victims.insert({p.level, p.kind, p.patch, p.index});
          }
    grid[std::size_t(cell_y(y)) * nx + cell_x(x)].push_back(i);
  }
}

/// The glide track's close pairs among `points` (stable positions in a window): at every sampled density,
/// the points shown there at their glided positions, those inside [x0, x1) × [y0, y1).
void find_close_glides(std::vector<Candidate> points, const TilesetShape& shape, double separation, double x0,
                       double y0, double x1, double y1, Victims& victims) {
  std::sort(points.begin(), points.end(),
            [](const Candidate& a, const Candidate& b) { return a.order() < b.order(); });
  const auto& K = shape.keyframe_nominal;
  std::vector<double> at(2 * points.size());
  constexpr int kSteps = 8;
  for (std::size_t g = 0; g < K.size(); ++g)
    for (int step = 0; step < (g + 1 < K.size() ? kSteps : 1); ++step) {
      const double t = double(step) / kSteps;
      const double count = g + 1 < K.size() ? K[g] + t * (double(K[g + 1]) - K[g]) : K[g];
      std::size_t present = 0;
      while (present < points.size() && TilesetShape::emits(points[present].threshold, count)) ++present;
      for (std::size_t i = 0; i < present; ++i) {
        const Candidate& p = points[i];
        const std::vector<double>& f0 = p.source->frames[g];
        const std::vector<double>& f1 = p.source->frames[g + 1 < K.size() ? g + 1 : g];
        for (int a = 0; a < 2; ++a)
          at[2 * i + a] =
              (a ? p.anchor_y : p.anchor_x) + (1 - t) * f0[2 * p.index + a] + t * f1[2 * p.index + a];
      }
      const double radius = separation * std::sqrt(2.0 / (std::sqrt(3.0) * count));
      find_close(points, at, present, x0, y0, x1, y1, radius, victims);
    }
}

/// Removes `victims` from their patches (and their frames), highest index first so the others keep theirs.
void remove(std::vector<LevelPatches>& levels, const Victims& victims) {
  for (auto it = victims.rbegin(); it != victims.rend(); ++it) {
    const auto& [level, kind, patch_index, index] = *it;
    Patch& patch = levels[level].of(static_cast<PatchKind>(kind))[patch_index];
    KDM_CHECK(index < patch.size());
    const auto at = 2 * std::ptrdiff_t(index);
    patch.xy.erase(patch.xy.begin() + at, patch.xy.begin() + at + 2);
    patch.keys.erase(patch.keys.begin() + index);
    for (std::vector<double>& frame : patch.frames)
      if (!frame.empty()) frame.erase(frame.begin() + at, frame.begin() + at + 2);
  }
}

/// Two tiles side by side (`across`: left and right, else bottom and top) with the given vertex colours
/// (row-major over their 3 × 2 or 2 × 3 vertices); other vertices are never reached by a window near
/// their shared edge.
Colouring pair_of_tiles(std::uint32_t colours, bool across, std::vector<std::uint32_t> vertices) {
  Colouring col;
  col.colours = colours;
  const int w = across ? 3 : 2, h = across ? 2 : 3;
  col.at = [vertices = std::move(vertices), w, h](std::int64_t x, std::int64_t y) -> std::uint32_t {
    return (x >= 0 && x < w && y >= 0 && y < h) ? vertices[std::size_t(y) * w + x] : 0;
  };
  return col;
}

/// Calls on_pair(later, earlier) for every pair closer than separation · d_hex of the later point (at its
/// threshold, or the first level's count if higher), in every tile and across every edge two tiles can
/// share (their shared edge's colours, and two more on each side: a strip as wide as the largest radius on
/// either side of the edge).
template <class OnPair>
void for_each_close_pair(const std::vector<LevelPatches>& levels, std::uint32_t colours,
                         const TilesetShape& shape, double separation, OnPair&& on_pair) {
  // Densities below the first level are outside the set's range: a pair counts from there on.
  const double lowest = std::max(1.0, double(shape.level_nominal.front()));
  auto radius = [&](const Candidate& p) {
    return separation * std::sqrt(2.0 / (std::sqrt(3.0) * std::max(double(p.threshold), lowest)));
  };
  const std::size_t tiles = std::size_t(colours) * colours * colours * colours;
  for (std::size_t t = 0; t < tiles; ++t)
    find_pairs(collect(levels, Colouring::around_tile(colours, t), shape, 0, 0, 1, 1), 1, 1, radius, on_pair);
  const double reach = separation * std::sqrt(2.0 / (std::sqrt(3.0) * lowest));
  std::vector<std::uint32_t> v(6);
  for (std::size_t code = 0; code < std::size_t(tiles) * colours * colours; ++code) {
    std::size_t rest = code;
    for (std::uint32_t& c : v) c = static_cast<std::uint32_t>(rest % colours), rest /= colours;
    find_pairs(collect(levels, pair_of_tiles(colours, true, v), shape, 1 - reach, 0, 1 + reach, 1), 2 * reach,
               1, radius, on_pair);
    find_pairs(collect(levels, pair_of_tiles(colours, false, v), shape, 0, 1 - reach, 1, 1 + reach), 1,
               2 * reach, radius, on_pair);
  }
}

using PointKey = std::tuple<std::size_t, int, std::size_t, std::uint32_t>;  // (level, kind, patch, index)

PointKey key_of(const Candidate& p) {
  return {p.level, p.kind, p.patch, p.index};
}

}  // namespace

std::size_t drop_close_pairs(std::vector<LevelPatches>& levels, std::uint32_t colours,
                             const TilesetShape& shape, double separation) {
  if (!(separation > 0)) return 0;
  Victims victims;
  for_each_close_pair(levels, colours, shape, separation,
                      [&](const Candidate& later, const Candidate&) { victims.insert(key_of(later)); });
  remove(levels, victims);
  return victims.size();
}

SeparationResult push_close_pairs_apart(std::vector<LevelPatches>& levels, std::uint32_t colours,
                                        const TilesetShape& shape, double separation, double push) {
  SeparationResult result;
  if (!(separation > 0)) return result;
  // Each later point of a close pair, and where the earlier points within `push` spacings of it sit in
  // any tile: their offsets from it (the same in every window, since a patch moves as a whole).
  const double reach = std::max(push, separation);
  std::set<PointKey> crowded;
  std::map<PointKey, std::vector<std::array<double, 2>>> around;
  std::map<PointKey, double> radius_of;
  const double lowest = std::max(1.0, double(shape.level_nominal.front()));
  std::set<PointKey> moved;
  for (int round = 0;; ++round) {
    crowded.clear(), around.clear();
    for_each_close_pair(levels, colours, shape, separation,
                        [&](const Candidate& later, const Candidate&) { crowded.insert(key_of(later)); });
    if (crowded.empty() || round == kPushRounds) break;
    for_each_close_pair(levels, colours, shape, reach, [&](const Candidate& later, const Candidate& earlier) {
      if (!crowded.count(key_of(later))) return;
      around[key_of(later)].push_back({earlier.x - later.x, earlier.y - later.y});
      radius_of[key_of(later)] =
          reach * std::sqrt(2.0 / (std::sqrt(3.0) * std::max(double(later.threshold), lowest)));
    });
    for (const auto& [key, offsets] : around) {
      const auto& [level, kind, patch_index, index] = key;
      Patch& patch = levels[level].of(static_cast<PatchKind>(kind))[patch_index];
      double* at = &patch.xy[2 * std::size_t(index)];
      // The move keeps the point in the part of the tile grid that its patch is shown from: an interior
      // point in its tile, an edge point between the vertices of its edge, a quarter spacing in (as the
      // glide track keeps interiors). Pushed across a tile edge, a point would be shown by whichever tile
      // the baker's torus put there, not by its own.
      const double r = radius_of[key], margin = 0.25 * r / reach;
      double lo[2], hi[2];
      for (int a = 0; a < 2; ++a) {
        const bool bounded = kind == static_cast<int>(PatchKind::kInterior) ||
                             (a == 0 && kind == static_cast<int>(PatchKind::kHorizontalEdge)) ||
                             (a == 1 && kind == static_cast<int>(PatchKind::kVerticalEdge));
        lo[a] = bounded ? std::min(at[a], margin) : -1e300,
        hi[a] = bounded ? std::max(at[a], 1 - margin) : 1e300;
      }
      // A small move that takes it `push` spacings from every earlier neighbour: push off each in turn
      // until none is nearer (or give up; the next round finds it again if it is still too close).
      double dx = 0, dy = 0;
      for (int step = 0; step < 32; ++step) {
        bool clear = true;
        for (const auto& o : offsets) {
          double ex = dx - o[0], ey = dy - o[1];
          double d = std::hypot(ex, ey);
          if (d >= r) continue;
          clear = false;
          if (d < 1e-12 * r) {  // on top of it: any fixed direction, the same in every tile
            ex = 1, ey = 0, d = 1;
          }
          dx += (r - d) * ex / d, dy += (r - d) * ey / d;
          dx = std::clamp(at[0] + dx, lo[0], hi[0]) - at[0],
          dy = std::clamp(at[1] + dy, lo[1], hi[1]) - at[1];
        }
        if (clear) break;
      }
      at[0] += dx, at[1] += dy;
      moved.insert(key);
    }
  }
  // What the rounds could not part goes, as drop_close_pairs would take it.
  Victims victims(crowded.begin(), crowded.end());
  remove(levels, victims);
  result.removed = victims.size();
  for (const PointKey& key : victims) moved.erase(key);
  result.moved = moved.size();
  return result;
}

std::size_t drop_close_glides(std::vector<LevelPatches>& levels, std::uint32_t colours,
                              const TilesetShape& shape, double separation) {
  if (!(separation > 0) || shape.keyframe_nominal.empty()) return 0;
  const double s = separation + kGlideMargin;
  Victims victims;
  const std::size_t tiles = std::size_t(colours) * colours * colours * colours;
  for (std::size_t t = 0; t < tiles; ++t)
    find_close_glides(collect(levels, Colouring::around_tile(colours, t), shape, 0, 0, 1, 1), shape, s, 0, 0,
                      1, 1, victims);
  // Across a tile edge: points whose stable positions lie within the farthest glide of it, shown within the
  // pair distance of it.
  double reach = 0;
  for (const LevelPatches& level : levels)
    for (const PatchKind kind :
         {PatchKind::kCorner, PatchKind::kHorizontalEdge, PatchKind::kVerticalEdge, PatchKind::kInterior})
      for (const Patch& patch : level.of(kind))
        for (const std::vector<double>& frame : patch.frames)
          for (std::size_t i = 0; i < frame.size(); ++i)
            reach = std::max(reach, std::fabs(frame[i] - patch.xy[i]));
  const double near = s * std::sqrt(2.0 / (std::sqrt(3.0) * shape.keyframe_nominal.front()));
  std::vector<std::uint32_t> v(6);
  for (std::size_t code = 0; code < std::size_t(tiles) * colours * colours; ++code) {
    std::size_t rest = code;
    for (std::uint32_t& c : v) c = static_cast<std::uint32_t>(rest % colours), rest /= colours;
    const double w = reach + near;
    find_close_glides(collect(levels, pair_of_tiles(colours, true, v), shape, 1 - w, 0, 1 + w, 1), shape, s,
                      w - near, 0, w + near, 1, victims);
    find_close_glides(collect(levels, pair_of_tiles(colours, false, v), shape, 0, 1 - w, 1, 1 + w), shape, s,
                      0, w - near, 1, w + near, victims);
  }
  remove(levels, victims);
  return victims.size();
}

}  // namespace kdm::gen
