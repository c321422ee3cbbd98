// Separating the glide track's paths; see glide_paths.h.
#include "bake/glide_paths.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace kdm::gen {
namespace {

double wrapped(double d, int period) {
  return d - period * std::round(d / period);
}

/// The path's point at fraction t (as a path that stays there).
GlidePath at_fraction(const GlidePath& p, double t, int w, int h) {
  GlidePath s = p;
  s.ax = s.bx = p.ax + t * wrapped(p.bx - p.ax, w);
  s.ay = s.by = p.ay + t * wrapped(p.by - p.ay, h);
  return s;
}

}  // namespace

void separate_points(std::vector<double>& xy, const std::vector<std::size_t>& moving,
                     const std::vector<double>& fixed, int w, int h, double r,
                     const std::function<void(std::vector<double>&, std::size_t)>& confine) {
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
      confine(xy, i);
      xy[2 * i] -= w * std::floor(xy[2 * i] / w), xy[2 * i + 1] -= h * std::floor(xy[2 * i + 1] / h);
      if (xy[2 * i] >= w) xy[2 * i] = 0;
      if (xy[2 * i + 1] >= h) xy[2 * i + 1] = 0;
    }
    if (!moved) break;
  }
}

double closest_approach(const GlidePath& p, const GlidePath& q, int w, int h, double& t) {
  // Relative position at fraction s: d0 + s (d1 - d0), with each path's own move unwrapped.
  const double d0x = wrapped(p.ax - q.ax, w), d0y = wrapped(p.ay - q.ay, h);
  const double vx = wrapped(p.bx - p.ax, w) - wrapped(q.bx - q.ax, w);
  const double vy = wrapped(p.by - p.ay, h) - wrapped(q.by - q.ay, h);
  const double from = std::max(p.appear, q.appear), to = std::min(p.vanish, q.vanish), vv = vx * vx + vy * vy;
  if (from > to) return t = from, std::numeric_limits<double>::infinity();
  t = vv > 0 ? std::clamp(-(d0x * vx + d0y * vy) / vv, from, to) : to;
  return std::hypot(d0x + t * vx, d0y + t * vy);
}

std::size_t separate_paths(std::vector<GlidePath>& paths, int w, int h,
                           const std::function<double(double)>& radius, double max_radius,
                           const std::function<void(GlidePath&, std::size_t)>& confine, int passes) {
  const int nx = std::max(1, static_cast<int>(w / max_radius)),
            ny = std::max(1, static_cast<int>(h / max_radius));
  const double cw = double(w) / nx, ch = double(h) / ny;
  std::size_t left = 0;
  for (int pass = 0; pass < passes; ++pass) {
    // Each path in every cell its bounding box (widened by the radius) touches.
    std::vector<std::vector<std::size_t>> cells(std::size_t(nx) * ny);
    auto span = [&](const GlidePath& p, int& x0, int& x1, int& y0, int& y1, double pad) {
      const double bx = p.ax + wrapped(p.bx - p.ax, w), by = p.ay + wrapped(p.by - p.ay, h);
      x0 = static_cast<int>(std::floor((std::min(p.ax, bx) - pad) / cw));
      x1 = static_cast<int>(std::floor((std::max(p.ax, bx) + pad) / cw));
      y0 = static_cast<int>(std::floor((std::min(p.ay, by) - pad) / ch));
      y1 = static_cast<int>(std::floor((std::max(p.ay, by) + pad) / ch));
      x1 = std::min(x1, x0 + nx - 1), y1 = std::min(y1, y0 + ny - 1);
    };
    for (std::size_t i = 0; i < paths.size(); ++i) {
      int x0, x1, y0, y1;
      span(paths[i], x0, x1, y0, y1, 0);
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x)
          cells[std::size_t((y % ny + ny) % ny) * nx + (x % nx + nx) % nx].push_back(i);
    }
    left = 0;
    std::vector<std::size_t> seen;
    for (std::size_t i = 0; i < paths.size(); ++i) {
      if (!paths[i].move_a && !paths[i].move_b) continue;
      int x0, x1, y0, y1;
      span(paths[i], x0, x1, y0, y1, max_radius);
      seen.clear();
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x)
          for (std::size_t j : cells[std::size_t((y % ny + ny) % ny) * nx + (x % nx + nx) % nx])
            if (j != i) seen.push_back(j);
      std::sort(seen.begin(), seen.end());
      seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
      for (std::size_t j : seen) {
        GlidePath &p = paths[i], &q = paths[j];
        if ((q.move_a || q.move_b) && j < i) continue;  // that pair was handled from j
        if (q.obstacle && !p.move_a) continue;
        double t;
        const double d = closest_approach(p, q, w, h, t);
        // With both entry ends fixed, the later ends move the pair apart at fraction t by t times their
        // move: a pair already closer where both appear (t0) is asked for no more than it can give soon
        // after, not for moves of (r - d) / t near t = 0.
        double r = radius(t);
        if (!p.move_a && !q.move_a) {
          const double t0 = std::max(p.appear, q.appear);
          const GlidePath ps = at_fraction(p, t0, w, h), qs = at_fraction(q, t0, w, h);
          r = std::min(r, std::hypot(wrapped(ps.ax - qs.ax, w), wrapped(ps.ay - qs.ay, h)) + 2 * t0 * r);
        }
        if (d >= r) continue;
        ++left;
        // The direction apart at t (any direction if they coincide there), and how much each movable end
        // takes: the smallest moves that widen the gap at t by exactly r - d.
        double ux = wrapped(p.ax - q.ax, w) + t * (wrapped(p.bx - p.ax, w) - wrapped(q.bx - q.ax, w));
        double uy = wrapped(p.ay - q.ay, h) + t * (wrapped(p.by - p.ay, h) - wrapped(q.by - q.ay, h));
        if (d > 0) {
          ux /= d, uy /= d;
        } else {
          ux = 1, uy = 0;
        }
        const double ca = 1 - t, cb = t;
        const double gain = (p.move_a ? ca * ca : 0) + (p.move_b ? cb * cb : 0) + (q.move_a ? ca * ca : 0) +
                            (q.move_b ? cb * cb : 0);
        if (!(gain > 1e-12)) continue;
        const double k = std::min(1.02 * (r - d) / gain, r / std::max(ca, cb));  // no end moves more than r
        auto push = [&](GlidePath& s, double sign) {
          if (s.move_a) s.ax += sign * k * ca * ux, s.ay += sign * k * ca * uy;
          if (s.move_b) s.bx += sign * k * cb * ux, s.by += sign * k * cb * uy;
        };
        push(p, 1);
        push(q, -1);
        for (GlidePath* s : {&p, &q}) {
          s->ax -= w * std::floor(s->ax / w), s->ay -= h * std::floor(s->ay / h);
          s->bx -= w * std::floor(s->bx / w), s->by -= h * std::floor(s->by / h);
          if (s->ax >= w) s->ax = 0;
          if (s->ay >= h) s->ay = 0;
          if (s->bx >= w) s->bx = 0;
          if (s->by >= h) s->by = 0;
        }
        confine(p, i);
        confine(q, j);
      }
    }
    if (!left) break;
  }
  return left;
}

}  // namespace kdm::gen
