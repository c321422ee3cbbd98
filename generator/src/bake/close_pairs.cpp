// Removing the later point of near-coincident pairs; see close_pairs.h.
#include "close_pairs.h"

#include <algorithm>
#include <cmath>
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
  auto order() const { return std::tie(threshold, kind, level, patch, index); }
};

using Victims = std::set<std::tuple<std::size_t, int, std::size_t, std::uint32_t>>;

/// The points of `levels` in the window [x0, x1) × [y0, y1) of the arrangement `col`.
std::vector<Candidate> collect(const std::vector<LevelPatches>& levels, const Colouring& col,
                               const TilesetData& table, double x0, double y0, double x1, double y1) {
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
        points.push_back(
            {xy[2 * i], xy[2 * i + 1], table.emission_threshold(static_cast<std::uint32_t>(k), keys[i]),
             static_cast<int>(kind), k, std::size_t(refs[i].patch - patches.data()), refs[i].index});
    }
  return points;
}

/// Adds to `victims` the later point of every pair of `points` (in a window `width` × `height`) closer
/// than `radius` of the later one.
template <class Radius>
void find_pairs(std::vector<Candidate> points, double width, double height, const Radius& radius,
                Victims& victims) {
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
          if (std::hypot(points[j].x - p.x, points[j].y - p.y) < r)
            victims.insert({p.level, p.kind, p.patch, p.index});
    grid[std::size_t(cell_y(p.y)) * nx + cell_x(p.x)].push_back(i);
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

}  // namespace

std::size_t drop_close_pairs(std::vector<LevelPatches>& levels, std::uint32_t colours,
                             const TilesetData& table, double separation) {
  if (!(separation > 0)) return 0;
  // Densities below the first level are outside the set's range: a pair counts from there on.
  const double lowest = std::max(1.0, double(table.level_nominal.front()));
  auto radius = [&](const Candidate& p) {
    return separation * std::sqrt(2.0 / (std::sqrt(3.0) * std::max(double(p.threshold), lowest)));
  };
  Victims victims;  // (level, kind, patch, index)
  const std::size_t tiles = std::size_t(colours) * colours * colours * colours;
  for (std::size_t t = 0; t < tiles; ++t)
    find_pairs(collect(levels, Colouring::around_tile(colours, t), table, 0, 0, 1, 1), 1, 1, radius, victims);
  // Pairs across a tile edge, for every two tiles that can meet there (their shared edge's colours, and
  // two more on each side): a strip as wide as the largest radius on either side of the edge.
  const double reach = separation * std::sqrt(2.0 / (std::sqrt(3.0) * lowest));
  std::vector<std::uint32_t> v(6);
  for (std::size_t code = 0; code < std::size_t(tiles) * colours * colours; ++code) {
    std::size_t rest = code;
    for (std::uint32_t& c : v) c = static_cast<std::uint32_t>(rest % colours), rest /= colours;
    find_pairs(collect(levels, pair_of_tiles(colours, true, v), table, 1 - reach, 0, 1 + reach, 1), 2 * reach,
               1, radius, victims);
    find_pairs(collect(levels, pair_of_tiles(colours, false, v), table, 0, 1 - reach, 1, 1 + reach), 1,
               2 * reach, radius, victims);
  }
  // Remove them, highest index first so the others keep theirs.
  for (auto it = victims.rbegin(); it != victims.rend(); ++it) {
    const auto& [level, kind, patch_index, index] = *it;
    Patch& patch = levels[level].of(static_cast<PatchKind>(kind))[patch_index];
    KDM_CHECK(patch.frames.empty() && index < patch.size());
    patch.xy.erase(patch.xy.begin() + 2 * std::ptrdiff_t(index),
                   patch.xy.begin() + 2 * std::ptrdiff_t(index) + 2);
    patch.keys.erase(patch.keys.begin() + index);
  }
  return victims.size();
}

}  // namespace kdm::gen
