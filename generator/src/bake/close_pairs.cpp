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

}  // namespace

std::size_t drop_close_pairs(std::vector<LevelPatches>& levels, std::uint32_t colours,
                             const TilesetData& table, double separation) {
  if (!(separation > 0)) return 0;
  // Where each patch sits in `levels`, to name a point by (level, kind, patch, index).
  std::set<std::tuple<std::size_t, int, std::size_t, std::uint32_t>> victims;
  const std::size_t tiles = std::size_t(colours) * colours * colours * colours;
  constexpr PatchKind kKinds[] = {PatchKind::kCorner, PatchKind::kHorizontalEdge, PatchKind::kVerticalEdge,
                                  PatchKind::kInterior};
  for (std::size_t t = 0; t < tiles; ++t) {
    const Colouring col = Colouring::around_tile(colours, t);
    std::vector<Candidate> points;
    for (std::size_t k = 0; k < levels.size(); ++k)
      for (const PatchKind kind : kKinds) {
        std::array<bool, 4> only{};
        only[static_cast<int>(kind)] = true;
        std::vector<double> xy;
        std::vector<std::uint16_t> keys;
        std::vector<PatchPointRef> refs;
        gather(levels[k], col, only, 0, 0, 1, 1, xy, &keys, &refs);
        const std::vector<Patch>& patches = levels[k].of(kind);
        for (std::size_t i = 0; i < keys.size(); ++i)
          points.push_back(
              {xy[2 * i], xy[2 * i + 1], table.emission_threshold(static_cast<std::uint32_t>(k), keys[i]),
               static_cast<int>(kind), k, std::size_t(refs[i].patch - patches.data()), refs[i].index});
      }
    // Earlier points first; each point looks back for earlier ones within its own radius, on a grid whose
    // cells are the smallest radius wide (the largest radii, at the coarsest levels, are few).
    std::sort(points.begin(), points.end(),
              [](const Candidate& a, const Candidate& b) { return a.order() < b.order(); });
    // Densities below the first level are outside the set's range: a pair counts from there on.
    const double lowest = std::max(1.0, double(table.level_nominal.front()));
    auto radius = [&](const Candidate& p) {
      return separation * std::sqrt(2.0 / (std::sqrt(3.0) * std::max(double(p.threshold), lowest)));
    };
    const double cell = std::max(radius(points.back()), 1.0 / 1024);
    const int n = static_cast<int>(std::ceil(1.0 / cell));
    std::vector<std::vector<std::uint32_t>> grid(std::size_t(n) * n);
    auto cell_of = [&](double v) { return std::clamp(static_cast<int>(v / cell), 0, n - 1); };
    for (std::uint32_t i = 0; i < points.size(); ++i) {
      const Candidate& p = points[i];
      const double r = radius(p);
      const int cx0 = cell_of(p.x - r), cx1 = cell_of(p.x + r), cy0 = cell_of(p.y - r),
                cy1 = cell_of(p.y + r);
      for (int cy = cy0; cy <= cy1; ++cy)
        for (int cx = cx0; cx <= cx1; ++cx)
          for (std::uint32_t j : grid[std::size_t(cy) * n + cx])
            if (std::hypot(points[j].x - p.x, points[j].y - p.y) < r)
              victims.insert({p.level, p.kind, p.patch, p.index});
      grid[std::size_t(cell_of(p.y)) * n + cell_of(p.x)].push_back(i);
    }
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
