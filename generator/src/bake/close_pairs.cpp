// Removing the later point of near-coincident pairs; see close_pairs.h.
#include "close_pairs.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
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
  std::size_t tile;           ///< the tile its stable position lies in
  std::uint16_t key;
  auto order() const { return std::tie(threshold, kind, level, patch, index); }
};

using Victims = std::set<PointKey>;

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
      for (std::size_t i = 0; i < keys.size(); ++i) {
        const std::size_t tile = col.tile_at(static_cast<std::int64_t>(std::floor(x0 + xy[2 * i])),
                                             static_cast<std::int64_t>(std::floor(y0 + xy[2 * i + 1])));
        points.push_back({xy[2 * i], xy[2 * i + 1],
                          shape.emission_threshold(static_cast<std::uint32_t>(k), keys[i]),
                          static_cast<int>(kind), k, std::size_t(refs[i].patch - patches.data()),
                          refs[i].index, refs[i].patch, refs[i].anchor_x, refs[i].anchor_y, tile, keys[i]});
      }
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

/// Adds to `crowded` the later of every two points of `at` (positions, in the order of `points`, which is
/// by Candidate::order) closer than `radius`, with its tile and `apart` (the next density sampled, from
/// which it may be shown there); only the first `present` points are shown.
void find_close(const std::vector<Candidate>& points, const std::vector<double>& at, std::size_t present,
                double x0, double y0, double x1, double y1, double radius, double apart, Crowded& crowded) {
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
            double& from = crowded[{p.level, p.kind, p.patch, p.index}][p.tile];
            from = std::max(from, apart);
          }
    grid[std::size_t(cell_y(y)) * nx + cell_x(x)].push_back(i);
  }
}

/// The glide track's close pairs among `points` (stable positions in a window): at every sampled density,
/// the points shown there at their glided positions, those inside [x0, x1) × [y0, y1).
void find_close_glides(std::vector<Candidate> points, const TilesetShape& shape, double separation, double x0,
                       double y0, double x1, double y1, Crowded& crowded) {
  std::sort(points.begin(), points.end(),
            [](const Candidate& a, const Candidate& b) { return a.order() < b.order(); });
  const auto& K = shape.keyframe_nominal;
  std::vector<double> at(2 * points.size());
  constexpr int kSteps = 8;
  for (std::size_t g = 0; g < K.size(); ++g)
    for (int step = 0; step < (g + 1 < K.size() ? kSteps : 1); ++step) {
      const double t = double(step) / kSteps;
      const double count = g + 1 < K.size() ? K[g] + t * (double(K[g + 1]) - K[g]) : K[g];
      const double next = g + 1 < K.size() ? K[g] + (step + 1.0) / kSteps * (double(K[g + 1]) - K[g])
                                           : std::numeric_limits<double>::infinity();
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
      find_close(points, at, present, x0, y0, x1, y1, radius, next, crowded);
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

PointKey key_of(const Candidate& p) {
  return {p.level, p.kind, p.patch, p.index};
}

/// The move (dx, dy) within kFillReach × `spacing` of `at`, inside [lo, hi], that takes it farthest from
/// every point of `nearby` (offsets from `at`, each with the spacing of the density where both are shown),
/// in those spacings; true if that is at least `push` from each (else no move: the caller pushes).
bool fill_place(const std::vector<std::array<double, 3>>& nearby, double spacing, const double* at,
                const double* lo, const double* hi, double push, double& dx, double& dy) {
  const double reach = kFillReach * spacing, step = 0.04 * spacing;
  const int n = static_cast<int>(reach / step);
  double best = -1;
  for (int j = -n; j <= n; ++j)
    for (int i = -n; i <= n; ++i) {
      const double x = i * step, y = j * step;
      if (x * x + y * y > reach * reach || at[0] + x < lo[0] || at[0] + x > hi[0] || at[1] + y < lo[1] ||
          at[1] + y > hi[1])
        continue;
      double worst = std::numeric_limits<double>::infinity();
      for (const auto& o : nearby) worst = std::min(worst, std::hypot(x - o[0], y - o[1]) / o[2]);
      if (worst > best) best = worst, dx = x, dy = y;
    }
  return best >= push;
}

}  // namespace

std::size_t drop_close_pairs(std::vector<LevelPatches>& levels, std::uint32_t colours,
                             const TilesetShape& shape, double separation) {
  if (!(separation > 0)) return 0;
  Victims victims;
  for_each_close_pair(levels, colours, shape, separation,
                      [&](const Candidate& later, const Candidate&) { victims.insert(key_of(later)); });
  remove_points(levels, victims);
  return victims.size();
}

SeparationResult push_close_pairs_apart(std::vector<LevelPatches>& levels, std::uint32_t colours,
                                        const TilesetShape& shape, double separation, double push, bool split,
                                        bool fill) {
  SeparationResult result;
  if (!(separation > 0)) return result;
  if (split) {  // where a tile can keep the point as it is, it does; what is left is pushed
    Crowded crowded;
    for_each_close_pair(levels, colours, shape, separation, [&](const Candidate& later, const Candidate&) {
      crowded[key_of(later)][later.tile] = std::numeric_limits<double>::infinity();
    });
    const std::set<PointKey> done = split_crowded_points(levels, colours, shape, crowded);
    remove_points(levels, done);
    result.split = done.size();
  }
  // Each later point of a close pair, and where the earlier points within `push` spacings of it sit in
  // any tile: their offsets from it (the same in every window, since a patch moves as a whole).
  const double reach = std::max(push, separation);
  std::set<PointKey> crowded;
  std::map<PointKey, std::vector<std::array<double, 2>>> around;
  std::map<PointKey, double> radius_of;
  const double lowest = std::max(1.0, double(shape.level_nominal.front()));
  std::set<PointKey> moved;
  auto spacing = [&](double threshold) {
    return std::sqrt(2.0 / (std::sqrt(3.0) * std::max(threshold, lowest)));
  };
  // With `fill`: every point near each crowded one, in any tile, as (offset, spacing at the density where
  // both are shown).
  std::map<PointKey, std::vector<std::array<double, 3>>> nearby;
  for (int round = 0;; ++round) {
    crowded.clear(), around.clear(), nearby.clear();
    for_each_close_pair(levels, colours, shape, separation,
                        [&](const Candidate& later, const Candidate&) { crowded.insert(key_of(later)); });
    if (crowded.empty() || round == kPushRounds) break;
    if (fill)
      for_each_close_pair(
          levels, colours, shape, kFillReach + 1, [&](const Candidate& later, const Candidate& earlier) {
            const double d = spacing(later.threshold);
            if (crowded.count(key_of(later)))
              nearby[key_of(later)].push_back({earlier.x - later.x, earlier.y - later.y, d});
            if (crowded.count(key_of(earlier)))
              nearby[key_of(earlier)].push_back({later.x - earlier.x, later.y - earlier.y, d});
          });
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
      if (fill) {  // the deepest empty place within kFillReach spacings, if it is wide enough
        double dx = 0, dy = 0;
        if (fill_place(nearby[key], r / reach, at, lo, hi, push, dx, dy)) {
          at[0] += dx, at[1] += dy;
          moved.insert(key);
          continue;
        }
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
  remove_points(levels, victims);
  result.removed = victims.size();
  for (const PointKey& key : victims) moved.erase(key);
  result.moved = moved.size();
  return result;
}

SeparationResult drop_close_glides(std::vector<LevelPatches>& levels, std::uint32_t colours,
                                   const TilesetShape& shape, double separation, bool split) {
  SeparationResult result;
  if (!(separation > 0) || shape.keyframe_nominal.empty()) return result;
  const double s = separation + kGlideMargin;
  Crowded victims;
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
  std::set<PointKey> gone;
  if (split) gone = split_crowded_points(levels, colours, shape, victims);
  result.split = gone.size();
  for (const auto& entry : victims)
    if (!gone.count(entry.first)) gone.insert(entry.first), ++result.removed;
  remove_points(levels, gone);
  return result;
}

void remove_points(std::vector<LevelPatches>& levels, const std::set<PointKey>& points) {
  for (auto it = points.rbegin(); it != points.rend(); ++it) {  // highest index first: the others keep theirs
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

std::set<PointKey> split_crowded_points(std::vector<LevelPatches>& levels, std::uint32_t colours,
                                        const TilesetShape& shape, const Crowded& crowded) {
  // Every tile's view of each crowded point: where it lies there, and the key it keeps (none: no copy).
  struct Copy {
    std::size_t tile;
    Candidate point;
    std::uint16_t key;
  };
  std::map<PointKey, std::vector<Copy>> copies;
  const std::size_t tiles = std::size_t(colours) * colours * colours * colours;
  for (std::size_t t = 0; t < tiles; ++t)
    for (const Candidate& p : collect(levels, Colouring::around_tile(colours, t), shape, 0, 0, 1, 1)) {
      const auto it = crowded.find(key_of(p));
      if (it == crowded.end()) continue;
      const auto from = it->second.find(t);
      std::uint16_t key = p.key;
      if (from != it->second.end()) {  // the lowest key whose threshold is not below `from`
        const double lo = p.level == 0 ? 0.0 : shape.level_nominal[p.level - 1],
                     hi = shape.level_nominal[p.level];
        const double need = std::ceil((from->second - lo) / (hi - lo) * 65536.0 - 0.5);
        if (!(need <= 65535)) continue;
        key = static_cast<std::uint16_t>(std::max(need, double(p.key)));
        if (shape.emission_threshold(static_cast<std::uint32_t>(p.level), key) < from->second) {
          if (key == 65535) continue;
          ++key;  // rounding of the float threshold
        }
      }
      copies[key_of(p)].push_back({t, p, key});
    }
  std::set<PointKey> split;
  for (const auto& [point, kept] : copies) {
    if (kept.empty()) continue;
    split.insert(point);
    for (const Copy& c : kept) {
      // Within its tile's window the point lies at (x, y) from the tile's corner, the interior's anchor.
      Patch& interior = levels[c.point.level].interiors[c.tile];
      const Patch& source = *c.point.source;
      const std::size_t n = interior.size();
      if (interior.frames.size() < source.frames.size()) interior.frames.resize(source.frames.size());
      for (std::size_t g = 0; g < interior.frames.size(); ++g) {
        const bool moved = g < source.frames.size() && !source.frames[g].empty();
        std::vector<double>& frame = interior.frames[g];
        if (frame.empty() && !moved) continue;
        if (frame.empty()) frame = interior.xy;  // points not yet present keep their stable position
        const std::size_t i = 2 * std::size_t(c.point.index);
        frame.insert(frame.end(), {moved ? c.point.anchor_x + source.frames[g][i] : c.point.x,
                                   moved ? c.point.anchor_y + source.frames[g][i + 1] : c.point.y});
      }
      interior.add(c.point.x, c.point.y, c.key);
      KDM_CHECK(interior.size() == n + 1);
    }
  }
  return split;
}

}  // namespace kdm::gen
