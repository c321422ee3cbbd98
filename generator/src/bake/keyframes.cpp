// Keyframes of the glide track; see keyframes.h.
#include "bake/keyframes.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "bake/glide_paths.h"
#include "bake/run_stages.h"
#include "kdm/generator/sampler.h"
#include "kdm/runtime/check.h"
#include "sampler/rng.h"

namespace kdm::gen {
namespace {

// Distances below are in hexagonal spacings d_hex of the keyframe's count (hex_spacing), the units the
// generator test and kdm analyze measure in; why each value, and what it was measured to do:
// docs/design.md §3 (the glide track).

/// No two points of a keyframe closer than this (separate_points).
constexpr double kMinDistance = 0.45;
/// No two paths between keyframes closer than this at any count on the way (separate_paths): the bar is 0.3.
constexpr double kPathDistance = 0.4;
/// No point moves farther than this from one keyframe to the next. The descent alone moves a few points
/// much farther; the cap costs the keyframes little δavg.
constexpr double kMaxMove = 0.55;
/// Interior points stay this far off their tile's edges (keep_in_bounds). The interiors of two
/// neighbouring tiles are never relaxed together (each meets a stand-in of the other on its own torus):
/// without this, points of both glide into the thin edge band between them and meet.
constexpr double kEdgeMargin = 0.25;

/// Entering points keep off the points of later kinds they meet in other tiles (entry_obstacles) where
/// they are shown before this fraction of the way to the next keyframe; from there on, the runs that move
/// those points can move them out of the way (a pair drifts apart by the fraction times their move).
constexpr double kObstacleFraction = 0.25;

/// Each keyframe starts the points this fraction of the way back to their stable positions. Relaxed from
/// where the last keyframe left them, points drift without bound (a random walk over the keyframes), and
/// a point whose emission is decided at its stable position then shows far from it: dots outside a sharp
/// edge of a density image. Pulled back by a quarter, offsets stay within about a spacing, and the
/// keyframes measure better than with no pull.
constexpr double kPull = 0.25;

/// The descent's grid and step. The sampler's default grid (peak density 0.43) resolves the γ = 1 energy
/// too coarsely for a descent: the keyframes stall whatever the sweeps. On a grid twice as fine per axis
/// they do not; the shorter step keeps the moves as small.
constexpr double kPeakDensity = 0.2;
constexpr double kStep = 0.2;

/// Offsets stay within this many square-grid spacings (1/√K) along each axis: what the file's 8-bit offsets
/// hold (kGlideUnitsPerSpacing), less a rounding margin. Rarely binding (kPull keeps offsets small).
constexpr double kMaxOffset = (127 - 2) / kGlideUnitsPerSpacing;

/// d_hex of `count` points per tile, in tile sides.
double hex_spacing(double count) {
  return std::sqrt(2.0 / (std::sqrt(3.0) * std::max(1.0, count)));
}

/// Sweeps of the descent at a keyframe of `count` points per tile: small counts get more (up to 4×), as
/// the pyramid's small levels do; they cost little, and on tiles of a few hundred points the patch
/// boundaries hold the descent back.
int sweeps_at(int sweeps, double count) {
  return static_cast<int>(std::lround(sweeps * std::clamp(std::sqrt(512.0 / count), 1.0, 4.0)));
}

/// A run's free points (patches of the run's kind and later) at one keyframe: where each comes from and
/// its path from keyframe g − 1 (a: its position there, or where it enters) to g (b: where it settled), in
/// torus coordinates.
struct FrameRun {
  std::vector<PatchPointRef> refs;
  std::vector<int> kinds;
  std::vector<std::uint32_t> levels;  ///< the level of each point's patch
  std::vector<std::uint64_t> ids;     ///< (kind, patch index): the same patch of every level
  std::vector<char> arrives;          ///< new at this keyframe: its entry point a is its own
  std::vector<GlidePath> paths;
};

/// The level whose nominal range holds keyframe count K: the first with N_L >= K.
std::uint32_t level_of_count(const TilesetShape& shape, std::uint32_t count) {
  std::uint32_t level = 0;
  while (level + 1 < shape.level_nominal.size() && shape.level_nominal[level] < count) ++level;
  return level;
}

/// Where a point new at this keyframe starts: its stable position moved as its older neighbours moved
/// since they were stable (a Gaussian-weighted mean over about two spacings). At its bare stable position a
/// new point can land on a neighbour that has drifted, and the descent barely separates the pair (the
/// kernels' force vanishes as they coincide); moved with its neighbours, it keeps the nested set's spacing.
class DriftField {
 public:
  DriftField(int w, int h, double spacing) : w_(w), h_(h), cell_(2 * spacing), sigma_(spacing) {
    nx_ = std::max(1, static_cast<int>(w / cell_)), ny_ = std::max(1, static_cast<int>(h / cell_));
    cells_.resize(std::size_t(nx_) * ny_);
  }
  void add(double x, double y, double dx, double dy) { cells_[cell(x, y)].push_back({x, y, dx, dy}); }
  void at(double x, double y, double& dx, double& dy) const {
    const int cx = static_cast<int>(x / w_ * nx_) % nx_, cy = static_cast<int>(y / h_ * ny_) % ny_;
    double sw = 0, sx = 0, sy = 0;
    for (int j = -1; j <= 1; ++j)
      for (int i = -1; i <= 1; ++i)
        for (const Sample& s : cells_[std::size_t((cy + j + ny_) % ny_) * nx_ + (cx + i + nx_) % nx_]) {
          double ex = s.x - x, ey = s.y - y;
          ex -= w_ * std::round(ex / w_), ey -= h_ * std::round(ey / h_);
          const double weight = std::exp(-(ex * ex + ey * ey) / (2 * sigma_ * sigma_));
          sw += weight, sx += weight * s.dx, sy += weight * s.dy;
        }
    dx = sw > 0 ? sx / sw : 0.0, dy = sw > 0 ? sy / sw : 0.0;
  }

 private:
  struct Sample {
    double x, y, dx, dy;
  };
  std::size_t cell(double x, double y) const {
    return std::size_t(static_cast<int>(y / h_ * ny_) % ny_) * nx_ + static_cast<int>(x / w_ * nx_) % nx_;
  }
  int w_, h_, nx_ = 1, ny_ = 1;
  double cell_, sigma_;
  std::vector<std::vector<Sample>> cells_;
};

/// Keeps a free point (patch coordinates `rel`) where no run misses a neighbour it can meet: an interior
/// point kEdgeMargin spacings (`margin`) off its tile's edges, an edge point out of the corner squares at
/// its ends (half-width `corner`, at its level). A run of vertical edges on a 1×2 torus sees the
/// horizontal edges of that torus, not those a tile puts at the edge's ends, so two edge points that
/// slipped into a corner square when the pyramid was sampled met nothing there that kept them apart
/// (the stable set's near-coincident pairs).
/// Bounds per axis, so keeping a point in moves it no farther from any point inside, and a capped move
/// (kMaxMove) stays so.
void keep_in_bounds(PatchKind kind, double margin, double corner, double* rel) {
  switch (kind) {
    case PatchKind::kInterior:  // anchored at its tile's corner
      rel[0] = std::clamp(rel[0], margin, 1.0 - margin), rel[1] = std::clamp(rel[1], margin, 1.0 - margin);
      break;
    case PatchKind::kHorizontalEdge:  // anchored at its left vertex
      rel[0] = std::clamp(rel[0], corner, 1.0 - corner);
      break;
    case PatchKind::kVerticalEdge:  // anchored at its bottom vertex
      rel[1] = std::clamp(rel[1], corner, 1.0 - corner);
      break;
    case PatchKind::kCorner:
      break;
  }
}

/// A patch of a later kind that the patch of `kind` and `index` meets in some tile, and its anchor relative
/// to that patch's anchor. Interiors meet none (their neighbours' interiors stay apart: kEdgeMargin), and
/// horizontal edges no vertical ones (they stay √2 edge gaps apart).
struct LaterNeighbour {
  PatchKind kind;
  std::size_t index;
  int dx, dy;
};

std::vector<LaterNeighbour> later_neighbours(PatchKind kind, std::size_t index, std::uint32_t colours) {
  const std::uint32_t C = colours;
  auto tile = [&](std::uint32_t sw, std::uint32_t se, std::uint32_t ne, std::uint32_t nw) {
    return ((std::size_t(sw) * C + se) * C + ne) * C + nw;
  };
  std::vector<LaterNeighbour> out;
  using K = PatchKind;
  if (kind == K::kCorner) {
    const auto c = static_cast<std::uint32_t>(index);
    for (std::uint32_t x = 0; x < C; ++x)
      out.insert(out.end(), {{K::kHorizontalEdge, std::size_t(c) * C + x, 0, 0},
                             {K::kHorizontalEdge, std::size_t(x) * C + c, -1, 0},
                             {K::kVerticalEdge, std::size_t(c) * C + x, 0, 0},
                             {K::kVerticalEdge, std::size_t(x) * C + c, 0, -1}});
    for (std::uint32_t a = 0; a < C; ++a)
      for (std::uint32_t b = 0; b < C; ++b)
        for (std::uint32_t d = 0; d < C; ++d)
          out.insert(out.end(), {{K::kInterior, tile(c, a, b, d), 0, 0},
                                 {K::kInterior, tile(a, c, b, d), -1, 0},
                                 {K::kInterior, tile(a, b, c, d), -1, -1},
                                 {K::kInterior, tile(a, b, d, c), 0, -1}});
  } else if (kind != K::kInterior) {
    const auto a = static_cast<std::uint32_t>(index / C), b = static_cast<std::uint32_t>(index % C);
    for (std::uint32_t x = 0; x < C; ++x)
      for (std::uint32_t y = 0; y < C; ++y) {
        if (kind == K::kHorizontalEdge)  // a left, b right: the tiles above and below
          out.insert(out.end(),
                     {{K::kInterior, tile(a, b, x, y), 0, 0}, {K::kInterior, tile(x, y, b, a), 0, -1}});
        else  // a bottom, b top: the tiles right and left
          out.insert(out.end(),
                     {{K::kInterior, tile(a, x, y, b), 0, 0}, {K::kInterior, tile(x, a, b, y), -1, 0}});
      }
  }
  return out;
}

/// Where the points of later kinds that a patch (kind, index) meets in some tile were at keyframe g − 1
/// (relative to its anchor, within `reach` of its region at level `top`): obstacles for its entering
/// points. No run moves them any more, and the runs that sample the patch know them only as stand-ins.
std::vector<double> entry_obstacles(const std::vector<LevelPatches>& levels, const PatchWidths& w,
                                    std::uint32_t top, PatchKind kind, std::size_t index,
                                    const TilesetShape& shape, std::size_t g, double reach) {
  std::vector<double> out;
  const double previous = shape.keyframe_nominal[g - 1];
  for (const LaterNeighbour& n : later_neighbours(kind, index, shape.colours))
    for (std::uint32_t j = 0; j <= top; ++j) {
      const Patch& patch = levels[j].of(n.kind)[n.index];
      const bool moved = patch.frames.size() > g - 1 && !patch.frames[g - 1].empty();
      const std::vector<double>& at = moved ? patch.frames[g - 1] : patch.xy;
      for (std::size_t i = 0; i < patch.size(); ++i) {
        if (!TilesetShape::emits(shape.emission_threshold(j, patch.keys[i]), previous)) continue;
        const double x = at[2 * i] + n.dx, y = at[2 * i + 1] + n.dy;
        const bool near = kind == PatchKind::kCorner
                              ? std::fabs(x) < w.corner + reach && std::fabs(y) < w.corner + reach
                          : kind == PatchKind::kHorizontalEdge
                              ? std::fabs(y) < w.edge + reach && x > -reach && x < 1 + reach
                              : std::fabs(x) < w.edge + reach && y > -reach && y < 1 + reach;
        if (near) out.insert(out.end(), {x, y});
      }
    }
  return out;
}

/// A point's position relative to its patch's anchor, taken to the copy nearest its stable position
/// (patch coordinates `stable`) from torus coordinates (x, y).
void relative(const PatchPointRef& ref, const double* stable, int w, int h, double x, double y, double* out) {
  const double dx = x - (ref.anchor_x + stable[0]), dy = y - (ref.anchor_y + stable[1]);
  out[0] = stable[0] + dx - w * std::round(dx / w);
  out[1] = stable[1] + dy - h * std::round(dy / h);
}

/// Relaxes keyframe g on one run's torus: the points of kinds >= run.stage descend from where keyframe
/// g - 1 left them, then are kept apart; with `late_from` > 0, the points new at g shown later than that
/// fraction of the way from g - 1 stay where they enter (only kept apart). With `part_only`, the points of
/// kind run.stage are already at g (their consensus mean) and are only kept apart, from each other and from
/// earlier kinds; later kinds are left out (their own stages keep them off these).
FrameRun relax_run(const std::vector<LevelPatches>& levels, const BakeRun& run,
                   const std::vector<PatchWidths>& widths, const TilesetShape& shape, std::size_t g,
                   int sweeps, std::uint64_t seed, int threads, double late_from, bool part_only = false) {
  const Colouring col = Colouring::torus(shape.colours, run.w, run.h, run.grid);
  const std::uint32_t count = shape.keyframe_nominal[g];
  const std::uint32_t previous = g ? shape.keyframe_nominal[g - 1] : 0;
  const double spacing = hex_spacing(count);
  const std::uint32_t top = level_of_count(shape, count);
  auto wrap = [&](double& x, double& y) {
    x -= run.w * std::floor(x / run.w), y -= run.h * std::floor(y / run.h);
    if (x >= run.w) x = 0;  // rounding of a tiny negative value
    if (y >= run.h) y = 0;
  };
  FrameRun out;
  std::vector<double> fixed,
      start;  // fixed: normalised, at keyframe g; start: where free points descend from
  std::vector<GlidePath> fixed_paths;
  std::vector<std::size_t> arrivals;  // free points new at this keyframe
  DriftField drift(run.w, run.h, 1.0 / std::sqrt(std::max<double>(1, previous)));
  std::vector<double> unused;
  std::vector<std::uint16_t> keys;
  std::vector<PatchPointRef> refs;
  for (std::uint32_t j = 0; j <= top; ++j)
    for (int kind = 0; kind < (part_only ? run.stage + 1 : 4); ++kind) {
      std::array<bool, 4> kinds{};
      kinds[kind] = true;
      unused.clear(), keys.clear(), refs.clear();
      gather(levels[j], col, kinds, 0, 0, run.w, run.h, unused, &keys, &refs);
      for (std::size_t i = 0; i < refs.size(); ++i) {
        const float threshold = shape.emission_threshold(j, keys[i]);
        if (!TilesetShape::emits(threshold, count)) continue;
        const bool arrives = !TilesetShape::emits(threshold, previous);
        const Patch& patch = *refs[i].patch;
        const std::size_t at = 2 * refs[i].index;
        const double ax = refs[i].anchor_x, ay = refs[i].anchor_y;
        // Where it is at keyframe g - 1: its frame there (an entering point's entry, set by its own run),
        // else its stable position. It is shown from fraction `appear` of the way to g on.
        const std::vector<double>& last = g > 0 && patch.frames.size() > g - 1 && !patch.frames[g - 1].empty()
                                              ? patch.frames[g - 1]
                                              : patch.xy;
        GlidePath path;
        path.ax = ax + last[at], path.ay = ay + last[at + 1];
        wrap(path.ax, path.ay);
        path.appear =
            arrives ? std::clamp((double(threshold) - previous) / (double(count) - previous), 0.0, 1.0) : 0.0;
        if (!arrives) {  // how far it has moved from its stable position, for the points entering near it
          double sx = ax + patch.xy[at], sy = ay + patch.xy[at + 1];
          wrap(sx, sy);
          drift.add(sx, sy, last[at] - patch.xy[at], last[at + 1] - patch.xy[at + 1]);
        }
        if (kind < run.stage) {  // earlier kinds are final for this keyframe
          KDM_CHECK(patch.frames.size() > g && !patch.frames[g].empty());
          path.bx = ax + patch.frames[g][at], path.by = ay + patch.frames[g][at + 1];
          wrap(path.bx, path.by);
          fixed.insert(fixed.end(), {path.bx / run.w, path.by / run.h});
          fixed_paths.push_back(path);
          continue;
        }
        // Free points start where the last keyframe left them, pulled back towards their stable spots (or,
        // parting only, at their mean).
        double x = ax + last[at] + kPull * (patch.xy[at] - last[at]);
        double y = ay + last[at + 1] + kPull * (patch.xy[at + 1] - last[at + 1]);
        if (part_only) {
          KDM_CHECK(patch.frames.size() > g && !patch.frames[g].empty());
          x = ax + patch.frames[g][at], y = ay + patch.frames[g][at + 1];
        }
        wrap(x, y);
        if (arrives && g > 0) arrivals.push_back(out.refs.size());
        out.refs.push_back(refs[i]);
        out.kinds.push_back(kind);
        out.levels.push_back(j);
        out.ids.push_back((std::uint64_t(kind) << 32) |
                          std::uint64_t(refs[i].patch - levels[j].of(static_cast<PatchKind>(kind)).data()));
        out.arrives.push_back(arrives && g > 0);
        out.paths.push_back(path);
        start.insert(start.end(), {x, y});
      }
    }

  // Where a free point may be: offsets within what the file holds, interiors off their tile's edges.
  const double max_offset = kMaxOffset / std::sqrt(double(count));
  auto confine_point = [&](double& x, double& y, std::size_t i) {
    if (i >= out.refs.size()) return;  // a fixed point
    const PatchPointRef& ref = out.refs[i];
    const double* stable = &ref.patch->xy[2 * ref.index];
    double rel[2];
    relative(ref, stable, run.w, run.h, x, y, rel);
    keep_in_bounds(static_cast<PatchKind>(out.kinds[i]), kEdgeMargin * spacing, widths[out.levels[i]].corner,
                   rel);
    for (int a = 0; a < 2; ++a) rel[a] = std::clamp(rel[a], stable[a] - max_offset, stable[a] + max_offset);
    x = ref.anchor_x + rel[0], y = ref.anchor_y + rel[1];
    wrap(x, y);
  };
  // ... and, at keyframe g, no farther than kMaxMove from where it was at g - 1.
  auto limit_move = [&](const GlidePath& p, double& x, double& y) {
    if (g == 0) return;
    double dx = x - p.ax, dy = y - p.ay;
    dx -= run.w * std::round(dx / run.w), dy -= run.h * std::round(dy / run.h);
    const double m = std::hypot(dx, dy), cap = kMaxMove * spacing;
    if (m <= cap) return;
    x = p.ax + dx * cap / m, y = p.ay + dy * cap / m;
    wrap(x, y);
  };
  auto confine_end = [&](std::vector<double>& xy, std::size_t i) {
    confine_point(xy[2 * i], xy[2 * i + 1], i);
    limit_move(out.paths[i], xy[2 * i], xy[2 * i + 1]);
    confine_point(xy[2 * i], xy[2 * i + 1], i);
  };

  // Obstacles for the entering points of the run's own patches: what they meet in other tiles (each copy
  // on the torus gets its patch's), shown near the start of the way only (later, the runs that move those
  // points keep them apart).
  std::vector<GlidePath> obstacles;
  {
    std::map<std::pair<const Patch*, std::pair<double, double>>, char> copies;
    for (std::size_t i : arrivals)
      if (out.kinds[i] == run.stage)
        copies[{out.refs[i].patch, {out.refs[i].anchor_x, out.refs[i].anchor_y}}] = 1;
    std::map<const Patch*, std::vector<double>> near;
    for (const auto& [copy, unused_flag] : copies) {
      const auto kind = static_cast<PatchKind>(run.stage);
      auto [it, fresh] = near.emplace(copy.first, std::vector<double>{});
      if (fresh)
        it->second = entry_obstacles(levels, widths[top], top, kind,
                                     std::size_t(copy.first - levels[top].of(kind).data()), shape, g,
                                     2 * hex_spacing(previous));
      for (std::size_t k = 0; k < it->second.size(); k += 2) {
        GlidePath o;
        o.ax = o.bx = copy.second.first + it->second[k], o.ay = o.by = copy.second.second + it->second[k + 1];
        wrap(o.ax, o.ay), wrap(o.bx, o.by);
        o.vanish = kObstacleFraction, o.obstacle = true;
        obstacles.push_back(o);
      }
    }
  }
  // New points enter where the nested set puts them, moved with their neighbours and kept off them; that
  // spot is also their position at the last keyframe (their entry), so they glide in from it. Parting
  // only, their entries are set already (the mean).
  if (!part_only) {
    for (std::size_t i : arrivals) {
      double dx, dy;
      drift.at(start[2 * i], start[2 * i + 1], dx, dy);
      start[2 * i] += dx, start[2 * i + 1] += dy;
      wrap(start[2 * i], start[2 * i + 1]);
    }
    std::vector<double> others = fixed;
    for (std::size_t i = 0; i < out.refs.size(); ++i)
      if (!out.arrives[i]) others.insert(others.end(), {start[2 * i] / run.w, start[2 * i + 1] / run.h});
    for (const GlidePath& o : obstacles) others.insert(others.end(), {o.ax / run.w, o.ay / run.h});
    separate_points(
        start, arrivals, others, run.w, run.h, kMinDistance * hex_spacing(previous),
        [&](std::vector<double>& xy, std::size_t i) { confine_point(xy[2 * i], xy[2 * i + 1], i); });
    for (std::size_t i : arrivals) out.paths[i].ax = start[2 * i], out.paths[i].ay = start[2 * i + 1];
  }

  // The descent: T = 0 on the run's torus, earlier kinds fixed at this keyframe.
  SamplerOptions o;
  o.extent[0] = run.w, o.extent[1] = run.h;
  o.temperature = 0;
  o.burn_in_sweeps = sweeps_at(sweeps, count);  // descent; no MH sweeps follow at T = 0
  o.sweeps = 0;
  o.step = kStep;
  o.peak_density = kPeakDensity;
  o.numerics = Numerics::kOriginal;
  o.threads = threads;
  o.seed = seed;
  o.fixed_points = std::move(fixed);
  // Late arrivals (shown after late_from of the way here) are left out of the descent: the points around
  // them make their room in the next interval, while they are shown, not before (docs/design.md §3).
  std::vector<std::size_t> in_descent;
  for (std::size_t i = 0; i < out.refs.size(); ++i)
    if (!(late_from > 0 && out.arrives[i] && out.paths[i].appear > late_from)) {
      in_descent.push_back(i);
      o.initial_points.insert(o.initial_points.end(), {start[2 * i] / run.w, start[2 * i + 1] / run.h});
    }
  std::vector<double> end = start;
  if (!part_only && !in_descent.empty()) {
    const SampleResult relaxed = sample(o);
    for (std::size_t k = 0; k < in_descent.size(); ++k) {
      end[2 * in_descent[k]] = relaxed.points[2 * k] * run.w;
      end[2 * in_descent[k] + 1] = relaxed.points[2 * k + 1] * run.h;
    }
  }
  std::vector<std::size_t> moving(out.refs.size());
  for (std::size_t i = 0; i < moving.size(); ++i) moving[i] = i, confine_end(end, i);
  separate_points(end, moving, o.fixed_points, run.w, run.h, kMinDistance * spacing, confine_end);
  for (std::size_t i = 0; i < moving.size(); ++i)
    out.paths[i].bx = end[2 * i], out.paths[i].by = end[2 * i + 1];
  if (g == 0) return out;

  // Between the keyframes: paths kept apart, moving this keyframe's positions and the entry points.
  std::vector<GlidePath> paths = out.paths;
  for (std::size_t i = 0; i < paths.size(); ++i) paths[i].move_b = true, paths[i].move_a = out.arrives[i];
  paths.insert(paths.end(), fixed_paths.begin(), fixed_paths.end());
  paths.insert(paths.end(), obstacles.begin(), obstacles.end());
  auto radius = [&](double t) {
    return kPathDistance * hex_spacing(previous + t * (double(count) - previous));
  };
  separate_paths(
      paths, run.w, run.h, radius, radius(0),
      [&](GlidePath& p, std::size_t i) {
        if (i >= out.refs.size()) return;
        if (p.move_a) confine_point(p.ax, p.ay, i);
        confine_point(p.bx, p.by, i);
        limit_move(p, p.bx, p.by), confine_point(p.bx, p.by, i);
      },
      24);
  std::copy(paths.begin(), paths.begin() + std::ptrdiff_t(out.paths.size()), out.paths.begin());
  return out;
}

}  // namespace

std::vector<std::uint32_t> make_keyframe_nominal(const std::vector<std::uint32_t>& nominal,
                                                 std::uint32_t per_level) {
  std::vector<std::uint32_t> counts;
  if (per_level == 0 || nominal.empty()) return counts;
  counts.push_back(nominal[0]);
  for (std::size_t k = 1; k < nominal.size(); ++k)
    for (std::uint32_t i = 1; i <= per_level; ++i) {
      const double ratio = double(nominal[k]) / nominal[k - 1];
      const auto c = i == per_level ? nominal[k]
                                    : static_cast<std::uint32_t>(std::lround(
                                          nominal[k - 1] * std::pow(ratio, double(i) / per_level)));
      if (c > counts.back()) counts.push_back(c);
    }
  return counts;
}

void relax_keyframe(std::vector<LevelPatches>& levels, const std::vector<BakeRun>& runs,
                    const std::vector<PatchWidths>& widths, const TilesetShape& shape, std::size_t g,
                    int sweeps, std::uint64_t seed, int threads, Consensus by_consensus, double late_from) {
  const std::uint32_t count = shape.keyframe_nominal[g];
  struct Sum {
    std::vector<double> b, a;
    std::vector<int> nb, na;
  };
  for (int stage = 0; stage < 4; ++stage) {
    const bool consensus = by_consensus.covers(count, stage);
    // The stage's own runs, and with consensus the later stages' tori relaxed as this stage too, so that
    // a shared patch moves by the mean of its moves in every context it meets.
    std::vector<BakeRun> plan;
    std::vector<std::uint64_t> salts;
    std::vector<std::size_t> own;  // the stage's own runs in the plan
    for (std::size_t r = 0; r < runs.size(); ++r) {
      if (runs[r].stage != stage && !(consensus && runs[r].stage > stage)) continue;
      plan.push_back(runs[r]);
      plan.back().stage = stage;
      salts.push_back(runs[r].stage == stage ? r : r + 1024 * (stage + 1));
      if (runs[r].stage == stage) own.push_back(plan.size() - 1);
    }
    std::map<Patch*, Sum> sums;
    std::map<Patch*, std::size_t> first_run;  // the one run and copy a patch moves with, if only one
    // Each copy of a patch of the stage's kind adds its moves (a tile's interior can appear twice on a
    // torus; its levels move together since every copy counts the same), or only the first copy seen.
    auto add_moves = [&](const BakeRun& run, std::size_t r, const FrameRun& result, bool every_copy) {
      std::map<std::uint64_t, std::pair<std::int64_t, std::int64_t>> copy_of;
      for (std::size_t i = 0; i < result.refs.size(); ++i) {
        if (result.kinds[i] != stage) continue;
        const PatchPointRef& ref = result.refs[i];
        auto& patch = const_cast<Patch&>(*ref.patch);  // levels is ours to write; gather hands out const
        if (!every_copy) {
          const std::int64_t ax = std::llround(ref.anchor_x), ay = std::llround(ref.anchor_y);
          const std::pair<std::int64_t, std::int64_t> anchor{(ax % run.w + run.w) % run.w,
                                                             (ay % run.h + run.h) % run.h};
          if (copy_of.emplace(result.ids[i], anchor).first->second != anchor) continue;  // the other copy
          if (first_run.emplace(&patch, r).first->second != r) continue;                 // an earlier run's
        }
        Sum& sum = sums[&patch];
        if (sum.b.empty()) {
          sum.b.assign(patch.xy.size(), 0.0), sum.a.assign(patch.xy.size(), 0.0);
          sum.nb.assign(patch.size(), 0), sum.na.assign(patch.size(), 0);
        }
        const double* stable = &patch.xy[2 * ref.index];
        const GlidePath& path = result.paths[i];
        double rel[2];
        relative(ref, stable, run.w, run.h, path.bx, path.by, rel);
        sum.b[2 * ref.index] += rel[0], sum.b[2 * ref.index + 1] += rel[1], ++sum.nb[ref.index];
        if (result.arrives[i]) {  // where it enters: its position at keyframe g - 1
          relative(ref, stable, run.w, run.h, path.ax, path.ay, rel);
          sum.a[2 * ref.index] += rel[0], sum.a[2 * ref.index + 1] += rel[1], ++sum.na[ref.index];
        }
      }
    };
    // The stage is done: its patches take their mean moves.
    auto commit = [&](bool from_last) {
      for (auto& [patch, sum] : sums) {
        if (patch->frames.size() <= g) patch->frames.resize(g + 1);
        if (from_last)
          patch->frames[g] = g > 0 && !patch->frames[g - 1].empty() ? patch->frames[g - 1] : patch->xy;
        for (std::size_t k = 0; k < patch->size(); ++k) {
          if (sum.nb[k])
            for (int c = 0; c < 2; ++c) patch->frames[g][2 * k + c] = sum.b[2 * k + c] / sum.nb[k];
          if (sum.na[k]) {
            if (patch->frames[g - 1].empty()) patch->frames[g - 1] = patch->xy;
            for (int c = 0; c < 2; ++c) patch->frames[g - 1][2 * k + c] = sum.a[2 * k + c] / sum.na[k];
          }
        }
      }
      sums.clear(), first_run.clear();
    };
    auto run_seed = [&](std::size_t r) {
      return mix64(seed ^ mix64(0x474c4944ull + 4096ull * g + salts[r]));
    };
    for_each_run(
        plan, threads,
        [&](std::size_t r, int run_threads) {
          return relax_run(levels, plan[r], widths, shape, g, sweeps, run_seed(r), run_threads, late_from);
        },
        [&](std::size_t r, FrameRun& result) { add_moves(plan[r], r, result, consensus); });
    commit(true);
    if (!consensus) continue;
    // Means of moves that each kept the points apart need not keep them apart: part them on the stage's
    // own tori (a patch meets the same earlier kinds on every torus, and no other patch of its kind).
    // Every run reads the means (commit writes after the last), so the result is the same for any thread
    // count.
    std::vector<BakeRun> own_runs;
    for (std::size_t r : own) own_runs.push_back(plan[r]);
    for_each_run(
        own_runs, threads,
        [&](std::size_t r, int run_threads) {
          return relax_run(levels, own_runs[r], widths, shape, g, sweeps, run_seed(own[r]), run_threads,
                           late_from, true);
        },
        [&](std::size_t r, FrameRun& result) { add_moves(own_runs[r], r, result, false); });
    commit(false);
  }
}

}  // namespace kdm::gen
