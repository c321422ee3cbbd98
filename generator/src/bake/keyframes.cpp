// Keyframes of the gliding track; see keyframes.h.
#include "bake/keyframes.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "bake/run_stages.h"
#include "kdm/generator/sampler.h"
#include "kdm/runtime/check.h"
#include "sampler/rng.h"

namespace kdm::gen {
namespace {

/// No two points of a keyframe closer than this fraction of its hexagonal spacing (separate()).
constexpr double kMinDistance = 0.45;

/// Each keyframe starts the points this fraction of the way back to their stable positions. Relaxed from
/// where the last keyframe left them, points drift without bound (a random walk over the keyframes:
/// measured on a 3-level set, the 99th percentile of the offsets grows to 3.4 point spacings at 512 points
/// per tile, a third of a tile side on the shipped set), and a point whose emission is decided at its
/// stable position then shows far from it: dots outside a sharp edge of a density image. Pulled back by a
/// quarter, offsets stay within about a spacing (99th percentile 0.9–1.0), the keyframes and the densities
/// between them measure as well or better (δavg .85–.88 and .81–.83), and points move no more per step.
constexpr double kPull = 0.25;

/// A run's points at one keyframe: where each free point (patches of the run's kind and later) came from,
/// its start and where the descent left it, in torus coordinates.
struct FrameRun {
  std::vector<PatchPointRef> refs;
  std::vector<int> kinds;
  std::vector<std::uint64_t> ids;  ///< (kind, patch index): the same patch of every level
  std::vector<double> start, end;
  std::vector<double> base;   ///< where each starts, relative to its patch's anchor (before `shift`)
  std::vector<double> shift;  ///< how far a new point's start was moved from its stable position
  std::vector<char> arrives;  ///< new at this keyframe: its start is its position at the last keyframe
};

/// The level whose nominal range holds keyframe count K: the first with N_L >= K.
std::uint32_t level_of_count(const TilesetData& table, std::uint32_t count) {
  std::uint32_t level = 0;
  while (level + 1 < table.level_nominal.size() && table.level_nominal[level] < count) ++level;
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

/// Pushes apart the moving points (indices into xy) that lie closer than `r` to any other point, moving or
/// fixed (`fixed`: normalized coordinates). With γ = 1 the energy's pull towards a gap next to a point is as
/// strong as the push of overlapping kernels, so the descent can settle a point right beside a fixed one.
void separate(std::vector<double>& xy, const std::vector<std::size_t>& moving,
              const std::vector<double>& fixed, int w, int h, double r) {
  std::vector<double> still;
  for (std::size_t i = 0; i < fixed.size(); i += 2)
    still.insert(still.end(), {fixed[i] * w, fixed[i + 1] * h});
  std::vector<char> is_moving(xy.size() / 2, 0);
  for (std::size_t i : moving) is_moving[i] = 1;
  for (std::size_t i = 0; i < is_moving.size(); ++i)
    if (!is_moving[i]) still.insert(still.end(), {xy[2 * i], xy[2 * i + 1]});
  const int nx = std::max(1, static_cast<int>(w / r)), ny = std::max(1, static_cast<int>(h / r));
  auto cell_of = [&](double x, double y) {
    const int cx = std::min(nx - 1, static_cast<int>(x / w * nx)),
              cy = std::min(ny - 1, static_cast<int>(y / h * ny));
    return std::pair<int, int>{cx, cy};
  };
  std::vector<std::vector<std::size_t>> still_cells(std::size_t(nx) * ny);
  for (std::size_t k = 0; k < still.size(); k += 2) {
    const auto [cx, cy] = cell_of(still[k], still[k + 1]);
    still_cells[std::size_t(cy) * nx + cx].push_back(k);
  }
  for (int pass = 0; pass < 4; ++pass) {
    std::vector<std::vector<std::size_t>> cells(std::size_t(nx) * ny);
    for (std::size_t i : moving) {
      const auto [cx, cy] = cell_of(xy[2 * i], xy[2 * i + 1]);
      cells[std::size_t(cy) * nx + cx].push_back(i);
    }
    bool moved = false;
    for (std::size_t i : moving) {
      const auto [cx, cy] = cell_of(xy[2 * i], xy[2 * i + 1]);
      for (int j = -1; j <= 1; ++j)
        for (int k = -1; k <= 1; ++k) {
          const std::size_t c = std::size_t((cy + j + ny) % ny) * nx + (cx + k + nx) % nx;
          auto push = [&](double ox, double oy, std::size_t other, bool other_moves) {
            double ex = xy[2 * i] - ox, ey = xy[2 * i + 1] - oy;
            ex -= w * std::round(ex / w), ey -= h * std::round(ey / h);
            const double d = std::hypot(ex, ey);
            if (d >= r) return;
            if (d == 0) ex = 1, ey = 0;  // coincident: any direction
            const double norm = d > 0 ? d : 1.0, gap = (r - d) * (other_moves ? 0.5 : 1.0);
            xy[2 * i] += gap * ex / norm, xy[2 * i + 1] += gap * ey / norm;
            if (other_moves) xy[2 * other] -= gap * ex / norm, xy[2 * other + 1] -= gap * ey / norm;
            moved = true;
          };
          for (std::size_t s : still_cells[c]) push(still[s], still[s + 1], 0, false);
          for (std::size_t o : cells[c])
            if (o > i) push(xy[2 * o], xy[2 * o + 1], o, true);
        }
    }
    for (std::size_t i : moving) {
      xy[2 * i] -= w * std::floor(xy[2 * i] / w), xy[2 * i + 1] -= h * std::floor(xy[2 * i + 1] / h);
      if (xy[2 * i] >= w) xy[2 * i] = 0;
      if (xy[2 * i + 1] >= h) xy[2 * i + 1] = 0;
    }
    if (!moved) break;
  }
}

FrameRun relax_run(const std::vector<LevelPatches>& levels, const BakeRun& run, const TilesetData& table,
                   std::size_t g, int sweeps, std::uint64_t seed, int threads) {
  const Colouring col = Colouring::torus(table.colours, run.w, run.h, run.grid);
  const std::uint32_t count = table.keyframe_nominal[g];
  const std::uint32_t previous = g ? table.keyframe_nominal[g - 1] : 0;
  const std::uint32_t top = level_of_count(table, count);
  FrameRun out;
  std::vector<double> fixed;
  std::vector<double> unused;
  std::vector<std::uint16_t> keys;
  std::vector<PatchPointRef> refs;
  DriftField drift(run.w, run.h, 1.0 / std::sqrt(std::max<double>(1, previous)));
  std::vector<std::size_t> arrivals;  // free points new at this keyframe (their start is their stable spot)
  auto wrap = [&](double& x, double& y) {
    x -= run.w * std::floor(x / run.w), y -= run.h * std::floor(y / run.h);
    if (x >= run.w) x = 0;  // rounding of a tiny negative value
    if (y >= run.h) y = 0;
  };
  for (std::uint32_t j = 0; j <= top; ++j)
    for (int kind = 0; kind < 4; ++kind) {
      std::array<bool, 4> kinds{};
      kinds[kind] = true;
      unused.clear(), keys.clear(), refs.clear();
      gather(levels[j], col, kinds, 0, 0, run.w, run.h, unused, &keys, &refs);
      for (std::size_t i = 0; i < refs.size(); ++i) {
        const float threshold = table.emission_threshold(j, keys[i]);
        if (!TilesetData::emits(threshold, count)) continue;
        const bool arrives = !TilesetData::emits(threshold, previous);
        const Patch& patch = *refs[i].patch;
        const std::size_t at = 2 * refs[i].index;
        // Earlier kinds are final for this keyframe; the rest start where the last keyframe left them.
        const std::vector<double>* from = &patch.xy;
        if (kind < run.stage) {
          KDM_CHECK(patch.frames.size() > g && !patch.frames[g].empty());
          from = &patch.frames[g];
        } else if (g > 0 && patch.frames.size() > g - 1 && !patch.frames[g - 1].empty()) {
          from = &patch.frames[g - 1];
        }
        double bx = (*from)[at], by = (*from)[at + 1];  // relative to the patch's anchor
        if (kind >= run.stage) bx += kPull * (patch.xy[at] - bx), by += kPull * (patch.xy[at + 1] - by);
        double x = refs[i].anchor_x + bx, y = refs[i].anchor_y + by;
        wrap(x, y);
        if (!arrives) {
          double sx = refs[i].anchor_x + patch.xy[at], sy = refs[i].anchor_y + patch.xy[at + 1];
          wrap(sx, sy);
          drift.add(sx, sy, bx - patch.xy[at], by - patch.xy[at + 1]);
        }
        if (kind < run.stage) {
          fixed.insert(fixed.end(), {x / run.w, y / run.h});
        } else {
          if (arrives && g > 0) arrivals.push_back(out.refs.size());
          out.refs.push_back(refs[i]);
          out.kinds.push_back(kind);
          out.ids.push_back((std::uint64_t(kind) << 32) |
                            std::uint64_t(refs[i].patch - levels[j].of(static_cast<PatchKind>(kind)).data()));
          out.start.insert(out.start.end(), {x, y});
          out.base.insert(out.base.end(), {bx, by});
        }
      }
    }
  // New points enter where the nested set puts them, moved with their neighbours and kept off them; that
  // spot is also their position at the last keyframe, so they glide in from it.
  out.shift.assign(out.start.size(), 0.0);
  out.arrives.assign(out.refs.size(), 0);
  const std::vector<double> stable = out.start;
  for (std::size_t i : arrivals) {
    double dx, dy;
    drift.at(out.start[2 * i], out.start[2 * i + 1], dx, dy);
    out.start[2 * i] += dx, out.start[2 * i + 1] += dy;
    wrap(out.start[2 * i], out.start[2 * i + 1]);
    out.arrives[i] = 1;
  }
  {
    std::vector<double> others = fixed;
    for (std::size_t i = 0; i < out.refs.size(); ++i)
      if (!out.arrives[i])
        others.insert(others.end(), {out.start[2 * i] / run.w, out.start[2 * i + 1] / run.h});
    separate(out.start, arrivals, others, run.w, run.h,
             kMinDistance * std::sqrt(2.0 / (std::sqrt(3.0) * std::max<double>(1, previous))));
  }
  for (std::size_t i : arrivals) {
    double dx = out.start[2 * i] - stable[2 * i], dy = out.start[2 * i + 1] - stable[2 * i + 1];
    out.shift[2 * i] = dx - run.w * std::round(dx / run.w),
                  out.shift[2 * i + 1] = dy - run.h * std::round(dy / run.h);
  }
  out.end = out.start;
  SamplerOptions o;
  o.extent[0] = run.w, o.extent[1] = run.h;
  o.temperature = 0;
  o.burn_in_sweeps = sweeps;  // descent; no MH sweeps follow at T = 0
  o.sweeps = 0;
  o.numerics = Numerics::kOriginal;
  o.threads = threads;
  o.seed = seed;
  o.fixed_points = std::move(fixed);
  for (std::size_t i = 0; i < out.start.size(); i += 2)
    o.initial_points.insert(o.initial_points.end(), {out.start[i] / run.w, out.start[i + 1] / run.h});
  const SampleResult relaxed = sample(o);
  for (std::size_t i = 0; i < out.end.size(); i += 2)
    out.end[i] = relaxed.points[i] * run.w, out.end[i + 1] = relaxed.points[i + 1] * run.h;
  std::vector<std::size_t> moving(out.refs.size());
  for (std::size_t i = 0; i < moving.size(); ++i) moving[i] = i;
  separate(out.end, moving, o.fixed_points, run.w, run.h,
           kMinDistance * std::sqrt(2.0 / (std::sqrt(3.0) * count)));
  return out;
}

}  // namespace

std::vector<std::uint32_t> keyframe_counts(const std::vector<std::uint32_t>& nominal,
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
                    const TilesetData& table, std::size_t g, int sweeps, std::uint64_t seed, int threads) {
  for_each_run(
      runs, threads,
      [&](std::size_t r, int run_threads) {
        return relax_run(levels, runs[r], table, g, sweeps,
                         mix64(seed ^ mix64(0x474c4944ull + 4096ull * g + r)), run_threads);
      },
      [&](std::size_t r, FrameRun& result) {
        const BakeRun& run = runs[r];
        // Each patch of the run's kind not relaxed yet at g takes the moves of one copy on the torus: the
        // copy of the first point seen of that patch (of any level: a tile's interior can appear twice on
        // the torus, and its levels must move together).
        std::map<std::uint64_t, std::pair<std::int64_t, std::int64_t>> copy_of;
        std::map<const Patch*, bool> mine;
        for (std::size_t i = 0; i < result.refs.size(); ++i) {
          if (result.kinds[i] != run.stage) continue;
          const PatchPointRef& ref = result.refs[i];
          auto& patch = const_cast<Patch&>(*ref.patch);  // levels is ours to write; gather hands out const
          const std::int64_t ax = std::llround(ref.anchor_x), ay = std::llround(ref.anchor_y);
          const std::pair<std::int64_t, std::int64_t> anchor{(ax % run.w + run.w) % run.w,
                                                             (ay % run.h + run.h) % run.h};
          if (copy_of.emplace(result.ids[i], anchor).first->second != anchor) continue;  // the other copy
          const auto [it, first] = mine.emplace(&patch, false);
          if (first) {
            it->second = patch.frames.size() <= g || patch.frames[g].empty();  // else an earlier run's
            if (it->second) {
              if (patch.frames.size() <= g) patch.frames.resize(g + 1);
              patch.frames[g] = g > 0 && !patch.frames[g - 1].empty() ? patch.frames[g - 1] : patch.xy;
            }
          }
          if (!it->second) continue;
          // The move, unwrapped across the torus seam, added to the point's own coordinates.
          double dx = result.end[2 * i] - result.start[2 * i],
                 dy = result.end[2 * i + 1] - result.start[2 * i + 1];
          dx -= run.w * std::round(dx / run.w), dy -= run.h * std::round(dy / run.h);
          const double x = result.base[2 * i] + result.shift[2 * i],
                       y = result.base[2 * i + 1] + result.shift[2 * i + 1];
          patch.frames[g][2 * ref.index] = x + dx;
          patch.frames[g][2 * ref.index + 1] = y + dy;
          if (result.arrives[i]) {  // where it enters: its position at keyframe g - 1
            if (patch.frames[g - 1].empty()) patch.frames[g - 1] = patch.xy;
            patch.frames[g - 1][2 * ref.index] = x;
            patch.frames[g - 1][2 * ref.index + 1] = y;
          }
        }
      });
}

}  // namespace kdm::gen
