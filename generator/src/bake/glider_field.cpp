// The hand-over's paths around a tile; see glider_field.h.
#include "bake/glider_field.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "kdm/runtime/check.h"

namespace kdm::gen {
namespace {

/// Where g is at `count` (tile units).
void position(const Glide& g, double top, double count, double& x, double& y) {
  const double f = std::clamp((count - top) / (g.end - top), 0.0, 1.0);
  x = g.ax + f * (g.bx - g.ax), y = g.ay + f * (g.by - g.ay);
}

/// Corner colour of tile u at (x, y) ∈ {0, 1}² (tile_index digits, base C: sw, se, ne, nw).
std::uint32_t corner(std::size_t u, std::uint32_t C, int x, int y) {
  const int digit = x ? (y ? 1 : 2) : (y ? 0 : 3);  // from the last: nw, ne, se, sw
  for (int i = 0; i < digit; ++i) u /= C;
  return static_cast<std::uint32_t>(u % C);
}

}  // namespace

GliderField::GliderField(const TilesetData& set, const std::vector<std::vector<Glide>>& glides, std::size_t t,
                         double distance, double top)
    : distance_(distance), top_(top) {
  own_ = static_cast<std::uint32_t>(glides[t].size());
  glides_ = glides[t];
  for (int oy = -1; oy <= 1; ++oy)
    for (int ox = -1; ox <= 1; ++ox)
      for (std::size_t u = 0; u < set.tiles.size() && (ox || oy); ++u) {
        bool fits = true;
        for (int y = 0; y <= 1; ++y)
          for (int x = 0; x <= 1; ++x) {
            const int wx = ox + x, wy = oy + y;
            if (wx >= 0 && wx <= 1 && wy >= 0 && wy <= 1 &&
                corner(u, set.colours, x, y) != corner(t, set.colours, wx, wy))
              fits = false;
          }
        if (!fits) continue;
        for (Glide g : glides[u]) {
          g.ax += ox, g.bx += ox, g.ay += oy, g.by += oy;
          if (std::max(g.ax, g.bx) < -distance || std::min(g.ax, g.bx) > 1 + distance ||
              std::max(g.ay, g.by) < -distance || std::min(g.ay, g.by) > 1 + distance)
            continue;
          glides_.push_back(g);
        }
      }
  cell_ = 4 / std::sqrt(top);  // a few spacings: a cell holds a few dozen paths
  cells_ = static_cast<std::int64_t>(std::ceil(2.0 / cell_));
  grid_.assign(std::size_t(cells_ * cells_), {});
  stamp_.assign(glides_.size(), 0);
  for (std::uint32_t i = 0; i < glides_.size(); ++i) add(i);
}

template <class Visit>
void GliderField::for_cells(const Glide& g, double margin, Visit&& visit) const {
  const auto cell_of = [&](double v) {  // the grid spans [−0.5, 1.5)², edge cells take what lies beyond
    return std::clamp<std::int64_t>(static_cast<std::int64_t>(std::floor((v + 0.5) / cell_)), 0, cells_ - 1);
  };
  const std::int64_t x0 = cell_of(std::min(g.ax, g.bx) - margin), x1 = cell_of(std::max(g.ax, g.bx) + margin);
  const std::int64_t y0 = cell_of(std::min(g.ay, g.by) - margin), y1 = cell_of(std::max(g.ay, g.by) + margin);
  for (std::int64_t y = y0; y <= y1; ++y)
    for (std::int64_t x = x0; x <= x1; ++x) visit(std::size_t(y * cells_ + x));
}

void GliderField::add(std::uint32_t i) {
  for_cells(glides_[i], distance_, [&](std::size_t c) { grid_[c].push_back(i); });
}

void GliderField::remove(std::uint32_t i) {
  for_cells(glides_[i], distance_, [&](std::size_t c) {
    std::vector<std::uint32_t>& in = grid_[c];
    in.erase(std::find(in.begin(), in.end(), i));
  });
}

void GliderField::replace(std::uint32_t r, const Glide& g) {
  KDM_CHECK(r < own_);
  remove(r);
  glides_[r] = g;
  add(r);
}

double GliderField::approach(const Glide& a, const Glide& b) const {
  // Both move linearly in the count until the first arrives, then one does until the other arrives: on
  // each piece the difference is linear, so its least length is a projection.
  const double ends[3] = {top_, std::min(a.end, b.end), std::max(a.end, b.end)};
  double least = std::numeric_limits<double>::infinity();
  for (int piece = 0; piece < 2; ++piece) {
    if (!(ends[piece + 1] > ends[piece])) continue;
    double ax, ay, bx, by, cx, cy, dx, dy;
    position(a, top_, ends[piece], ax, ay);
    position(b, top_, ends[piece], bx, by);
    position(a, top_, ends[piece + 1], cx, cy);
    position(b, top_, ends[piece + 1], dx, dy);
    const double x0 = ax - bx, y0 = ay - by, vx = (cx - dx) - x0, vy = (cy - dy) - y0;
    const double v2 = vx * vx + vy * vy;
    const double s = v2 > 0 ? std::clamp(-(x0 * vx + y0 * vy) / v2, 0.0, 1.0) : 0.0;
    least = std::min(least, std::hypot(x0 + s * vx, y0 + s * vy));
  }
  return least;
}

template <class Visit>
void GliderField::for_glides_near(const Glide& g, std::uint32_t skip_a, std::uint32_t skip_b,
                                  Visit&& visit) const {
  ++query_;
  bool done = false;
  for_cells(g, 0, [&](std::size_t c) {
    for (std::uint32_t i : grid_[c]) {
      if (done || stamp_[i] == query_ || i == skip_a || i == skip_b) continue;
      stamp_[i] = query_;
      done = visit(glides_[i]);
    }
  });
}

double GliderField::nearest(const Glide& g, std::uint32_t skip_a, std::uint32_t skip_b) const {
  double least = distance_;
  for_glides_near(g, skip_a, skip_b, [&](const Glide& other) {
    least = std::min(least, approach(g, other));
    return false;
  });
  return least;
}

bool GliderField::meets(const Glide& g, std::uint32_t skip_a, std::uint32_t skip_b) const {
  bool close = false;
  for_glides_near(g, skip_a, skip_b, [&](const Glide& other) { return close = meet(g, other); });
  return close;
}

std::vector<double> GliderField::clear_counts(const std::vector<double>& spots, double clearance) const {
  const std::size_t n = spots.size() / 2;
  std::vector<double> clear(n, top_);
  for (std::size_t s = 0; s < n; ++s) {
    const Glide here{spots[2 * s], spots[2 * s + 1], spots[2 * s], spots[2 * s + 1], top_};
    ++query_;
    for_cells(here, clearance, [&](std::size_t c) {
      for (std::uint32_t i : grid_[c]) {
        if (stamp_[i] == query_) continue;
        stamp_[i] = query_;
        // |a + f·d − s|² < clearance² for f in (f1, f2): clear once f passes f2, unless it ends that close.
        const Glide& g = glides_[i];
        const double px = g.ax - spots[2 * s], py = g.ay - spots[2 * s + 1], dx = g.bx - g.ax,
                     dy = g.by - g.ay;
        const double qa = dx * dx + dy * dy, qb = px * dx + py * dy,
                     qc = px * px + py * py - clearance * clearance;
        const double disc = qb * qb - qa * qc;
        if (qa <= 0 || disc <= 0) continue;
        const double f1 = (-qb - std::sqrt(disc)) / qa, f2 = (-qb + std::sqrt(disc)) / qa;
        if (f2 <= 0 || f1 >= 1 || f2 >= 1) continue;
        clear[s] = std::max(clear[s], top_ + f2 * (g.end - top_));
      }
    });
  }
  return clear;
}

}  // namespace kdm::gen
