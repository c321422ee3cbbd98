// Corner-tile geometry; see corner_layout.h.
#include "bake/corner_layout.h"

#include "kdm/generator/bake.h"
#include "kdm/runtime/check.h"

#include <algorithm>
#include <cmath>

namespace kdm::gen {
namespace {

std::int64_t floor_int(double v) {
  return static_cast<std::int64_t>(std::floor(v));
}

}  // namespace

Colouring Colouring::torus(std::uint32_t colours, int w, int h, std::vector<std::uint32_t> grid) {
  Colouring c;
  c.colours = colours;
  c.at = [w, h, grid = std::move(grid)](std::int64_t vx, std::int64_t vy) {
    const std::int64_t x = ((vx % w) + w) % w, y = ((vy % h) + h) % h;
    return grid[static_cast<std::size_t>(y * w + x)];
  };
  return c;
}

Colouring Colouring::around_tile(std::uint32_t colours, std::size_t index) {
  const auto nw = static_cast<std::uint32_t>(index % colours);
  const auto ne = static_cast<std::uint32_t>(index / colours % colours);
  const auto se = static_cast<std::uint32_t>(index / colours / colours % colours);
  const auto sw = static_cast<std::uint32_t>(index / colours / colours / colours);
  return torus(colours, 2, 2, {sw, se, nw, ne});
}

Placement classify(double x, double y, PatchWidths w, const Colouring& col) {
  const std::int64_t vx = floor_int(x + 0.5), vy = floor_int(y + 0.5);
  const double dx = x - double(vx), dy = y - double(vy);
  const std::int64_t fx = floor_int(x), fy = floor_int(y);
  const std::size_t C = col.colours;
  if (std::fabs(dx) < w.corner && std::fabs(dy) < w.corner)
    return {PatchKind::kCorner, col.at(vx, vy), vx, vy, dx, dy};
  if (std::fabs(dy) < w.edge)
    return {PatchKind::kHorizontalEdge, col.at(fx, vy) * C + col.at(fx + 1, vy), fx, vy, x - double(fx), dy};
  if (std::fabs(dx) < w.edge)
    return {PatchKind::kVerticalEdge, col.at(vx, fy) * C + col.at(vx, fy + 1), vx, fy, dx, y - double(fy)};
  return {PatchKind::kInterior, col.tile_at(fx, fy), fx, fy, x - double(fx), y - double(fy)};
}

bool place_new_point(double x, double y, PatchKind kind, PatchWidths w, const Colouring& col,
                     Placement& out) {
  out = classify(x, y, w, col);
  if (out.kind == kind) return true;
  if (out.kind > kind) return false;  // a region sampled later
  const std::int64_t vx = floor_int(x + 0.5), vy = floor_int(y + 0.5);
  const std::int64_t fx = floor_int(x), fy = floor_int(y);
  const std::size_t C = col.colours;
  const double dx = x - double(vx), dy = y - double(vy);
  // Depth inside the corner square, and inside the horizontal and vertical bands (0 if outside).
  const double corner = std::fabs(dx) < w.corner && std::fabs(dy) < w.corner
                            ? std::min(w.corner - std::fabs(dx), w.corner - std::fabs(dy))
                            : 0.0;
  const double in_h = std::max(0.0, w.edge - std::fabs(dy)), in_v = std::max(0.0, w.edge - std::fabs(dx));
  switch (kind) {
    case PatchKind::kCorner:
      return false;
    case PatchKind::kHorizontalEdge:  // slipped into a corner patch
      if (!(std::fabs(dy) < w.edge)) return false;
      out = {kind, col.at(fx, vy) * C + col.at(fx + 1, vy), fx, vy, x - double(fx), dy, corner};
      return true;
    case PatchKind::kVerticalEdge:  // slipped into a corner patch (a horizontal edge lies inside one)
      if (!(std::fabs(dx) < w.edge)) return false;
      out = {kind, col.at(vx, fy) * C + col.at(vx, fy + 1), vx, fy, dx, y - double(fy), corner};
      return true;
    case PatchKind::kInterior:  // slipped into its tile's band
      out = {kind,           col.tile_at(fx, fy),           fx, fy, x - double(fx),
             y - double(fy), std::max({corner, in_h, in_v})};
      return true;
  }
  return false;
}

void gather(const LevelPatches& level, const Colouring& col, std::array<bool, 4> kinds, double x0, double y0,
            double x1, double y1, std::vector<double>& xy, std::vector<std::uint16_t>* keys,
            std::vector<PatchPointRef>* refs) {
  const std::size_t C = col.colours;
  const std::int64_t ax0 = floor_int(x0) - 1, ax1 = floor_int(x1) + 1;
  const std::int64_t ay0 = floor_int(y0) - 1, ay1 = floor_int(y1) + 1;
  auto emit = [&](const Patch& patch, std::int64_t anchor_x, std::int64_t anchor_y) {
    for (std::size_t i = 0; i < patch.size(); ++i) {
      const double x = double(anchor_x) + patch.xy[2 * i], y = double(anchor_y) + patch.xy[2 * i + 1];
      if (x < x0 || x >= x1 || y < y0 || y >= y1) continue;
      xy.insert(xy.end(), {x - x0, y - y0});
      if (keys) keys->push_back(patch.keys[i]);
      if (refs)
        refs->push_back(
            {&patch, static_cast<std::uint32_t>(i), double(anchor_x) - x0, double(anchor_y) - y0});
    }
  };
  for (std::int64_t ay = ay0; ay <= ay1; ++ay)
    for (std::int64_t ax = ax0; ax <= ax1; ++ax) {
      if (kinds[0]) emit(level.corners[col.at(ax, ay)], ax, ay);
      if (kinds[1]) emit(level.horizontal[col.at(ax, ay) * C + col.at(ax + 1, ay)], ax, ay);
      if (kinds[2]) emit(level.vertical[col.at(ax, ay) * C + col.at(ax, ay + 1)], ax, ay);
      if (kinds[3]) emit(level.interiors[col.tile_at(ax, ay)], ax, ay);
    }
}

std::vector<PatchWidths> patch_widths(double band, double erosion, double edge_gap,
                                      const std::vector<std::uint32_t>& nominal) {
  std::vector<PatchWidths> widths;
  for (std::size_t k = 0; k < nominal.size(); ++k) {
    const double spacing = 1.0 / std::sqrt(double(nominal[k]));
    const double corner = k == 0 ? band : widths.back().corner - erosion * spacing;
    widths.push_back({corner, corner - edge_gap * spacing});
    if (!(widths.back().edge >= 0.5 * spacing)) return {};
  }
  return widths;
}

std::vector<BakeRun> plan_runs(std::uint32_t colours) {
  std::vector<BakeRun> runs;
  for (std::uint32_t c = 0; c < colours; ++c) runs.push_back({0, 1, 1, {c}});
  for (int stage = 1; stage <= 2; ++stage) {
    for (std::uint32_t c = 0; c < colours; ++c) runs.push_back({stage, 1, 1, {c}});
    for (std::uint32_t a = 0; a < colours; ++a)
      for (std::uint32_t b = a + 1; b < colours; ++b)  // edges (a, b) and (b, a) along x, or along y
        runs.push_back(stage == 1 ? BakeRun{1, 2, 1, {a, b}} : BakeRun{2, 1, 2, {a, b}});
  }
  const std::size_t tiles = std::size_t(colours) * colours * colours * colours;
  std::vector<char> covered(tiles, 0);
  for (std::size_t t = 0; t < tiles; ++t) {
    if (covered[t]) continue;
    const Colouring around = Colouring::around_tile(colours, t);
    BakeRun run{3, 2, 2, {around.at(0, 0), around.at(1, 0), around.at(0, 1), around.at(1, 1)}};
    for (int ty = 0; ty < 2; ++ty)
      for (int tx = 0; tx < 2; ++tx) covered[around.tile_at(tx, ty)] = 1;
    runs.push_back(std::move(run));
  }
  return runs;
}

std::size_t tile_around(std::uint32_t colours, std::size_t index, int tx, int ty) {
  KDM_CHECK(colours > 0 && tx >= 0 && tx < 2 && ty >= 0 && ty < 2);
  return Colouring::around_tile(colours, index).tile_at(tx, ty);
}

}  // namespace kdm::gen
