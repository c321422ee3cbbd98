// Empty circles of the Delaunay triangulation (empty_circles.h). The triangulation is Qhull's (Barber,
// Dobkin & Huhdanpaa, "The Quickhull algorithm for convex hulls", ACM TOMS 1996): the lower hull of the
// points lifted onto a paraboloid. A torus is triangulated with copies of the points near its sides, and
// each triangle is counted once, in the copy whose circumcentre lies in the unit square. The copies reach
// as far as the widest such circle, so that every circle is judged against every point it could hold.
#include "kdm/analysis/empty_circles.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <numeric>
#include <queue>
#include <string>
#include <tuple>
#include <utility>

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

#include "empty_circles_copies.h"
#include "kdm/analysis/common.h"
#include "parallel.h"

namespace kdm::analysis {
namespace {

struct Circle {
  double x = 0, y = 0, r = 0;
};

/// The circumcircle of a triangle; r = +inf for a degenerate (flat) one.
Circle circumcircle(const double* a, const double* b, const double* c) {
  const double bx = b[0] - a[0], by = b[1] - a[1], cx = c[0] - a[0], cy = c[1] - a[1];
  const double d = 2 * (bx * cy - by * cx);
  const double b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
  if (!(std::fabs(d) > 1e-12 * (b2 + c2))) return {a[0], a[1], HUGE_VAL};
  const double ux = (cy * b2 - by * c2) / d, uy = (bx * c2 - cx * b2) / d;
  return {a[0] + ux, a[1] + uy, std::hypot(ux, uy)};
}

/// How far a point is moved for the triangulation at most (below), in the square's units.
constexpr double kMoveBound = 0x1p-21;

/// A Delaunay triangle's circle, measured on the points as given where that is within a few moves of the
/// circle of the moved points, else on the moved ones (empty of them, so within a move of an empty
/// circle of the points as given). Two points closer than a move (10^6 uniform points hold some) can swap
/// sides in the triangulation, and the given points' circle of such a sliver is no empty circle at all: in
/// one set it was 5 d_hex where the largest is 2.
Circle delaunay_circle(const std::vector<double>& xy, const std::vector<double>& moved, int i, int j, int k) {
  // Corners in order of position, not as the triangulation lists them (which depends on what else was
  // triangulated): the same triangle gives the same bits however the set was copied.
  int v[3] = {i, j, k};
  std::sort(v, v + 3, [&](int a, int b) {
    return std::tie(xy[2 * a], xy[2 * a + 1]) < std::tie(xy[2 * b], xy[2 * b + 1]);
  });
  std::tie(i, j, k) = std::tie(v[0], v[1], v[2]);
  const Circle given = circumcircle(&xy[2 * i], &xy[2 * j], &xy[2 * k]);
  const Circle m = circumcircle(&moved[2 * i], &moved[2 * j], &moved[2 * k]);
  // Flat as given (a row of a grid, one point a hair from the next across the torus's seam): the moved
  // circle, or none if that is flat too (a box's hull).
  if (!std::isfinite(given.r)) return m;
  return std::fabs(given.r - m.r) <= 8 * kMoveBound ? given : m;
}

/// Calls visit(i, j, k, moved) with the point indices of every Delaunay triangle of `xy` (interleaved x
/// y) and the moved points it was triangulated on (delaunay_circle measures it).
/// `original` (optional): the point each one is a copy of, so that copies move as their originals do.
template <class Visit>
void delaunay(std::vector<double>& xy, Visit&& visit, const std::vector<std::size_t>* original = nullptr) {
  const int n = static_cast<int>(xy.size() / 2);
  // Points that span no area have no triangulation: Qhull fails on them after pages of its internals.
  bool flat = true;
  for (int i = 1, far = 0; i < n && flat; ++i) {  // far: the point farthest from the first yet
    const double fx = xy[2 * far] - xy[0], fy = xy[2 * far + 1] - xy[1];
    const double dx = xy[2 * i] - xy[0], dy = xy[2 * i + 1] - xy[1];
    flat = std::fabs(fx * dy - fy * dx) <= 1e-12 * (fx * fx + fy * fy + dx * dx + dy * dy);
    if (dx * dx + dy * dy > fx * fx + fy * fy) far = i;
  }
  if (flat)
    throw DegenerateSet(
        "the points are degenerate (all coincident or on one line): they have no Delaunay "
        "triangulation");
  // Points in degenerate position (a lattice, a line wrapped on a torus) made Qhull merge facets for
  // minutes (n³). It triangulates them moved by at most kMoveBound instead, each by a hash of its index
  // (the same every run; a torus copy as its original, so that every translate of a triangle is
  // triangulated alike): in general position, a Delaunay triangulation of the points themselves where ties
  // allowed several.
  std::vector<double> moved(xy);
  for (std::size_t i = 0; i < moved.size(); ++i) {
    const std::size_t point = original ? (*original)[i / 2] : i / 2;
    std::uint64_t h = (2 * point + i % 2 + 1) * 0x9E3779B97F4A7C15ull;
    h = (h ^ (h >> 31)) * 0xBF58476D1CE4E5B9ull, h ^= h >> 29;
    moved[i] += (double(h >> 11) * 0x1p-53 - 0.5) * 2 * kMoveBound;
  }
  // Qhull's own report of any other failure goes to a scratch file: the error below says it in one line.
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> sink(std::tmpfile(), std::fclose);
  std::FILE* err = sink ? sink.get() : stderr;
  qhT qh_qh;
  qhT* qh = &qh_qh;
  qh_zero(qh, err);
  char flags[] = "qhull d Qbb Qc Qz Q12 Qt";
  const int failed = qh_new_qhull(qh, 2, n, moved.data(), False, flags, nullptr, err);
  if (!failed) {
    facetT* facet;
    FORALLfacets {
      if (facet->upperdelaunay) continue;
      int id[3], m = 0;
      vertexT *vertex, **vertexp;
      FOREACHvertex_(facet->vertices) {
        if (m < 3) id[m] = qh_pointid(qh, vertex->point);
        ++m;
      }
      if (m == 3) visit(id[0], id[1], id[2], moved);
    }
  }
  qh_freeqhull(qh, !qh_ALL);
  int curlong = 0, totlong = 0;
  qh_memfreeshort(qh, &curlong, &totlong);
  if (failed)
    throw InvalidInput("the Delaunay triangulation failed (Qhull error " + std::to_string(failed) + ")");
}

/// One set's judged circles: their radii in local d_hex and the counts empty_circles pools.
struct SetCircles {
  std::vector<double> radii;
  double largest = -1, largest_x = 0, largest_y = 0;  ///< the largest radius and its centre, normalised
  std::size_t over_085 = 0, over_100 = 0, over_085_near_edge = 0, near_edge_judged = 0;
};

/// The circumcircles of the Delaunay triangles of a torus set's n points and copies of them (`xy`: the points
/// first, then the copies; `original`: the point each stands for) that count: each in the copy that holds
/// its lowest-numbered point itself (a rule of indices and whole shifts, so no rounding counts a triangle
/// twice or never). A circle that lies where every copy of every point is present is empty of every point:
/// a Delaunay triangle of the torus. A torus of n points has 2n of them (Euler).
std::vector<Circle> counted_circles(std::vector<double>& xy, const std::vector<std::size_t>& original,
                                    std::size_t n) {
  std::vector<Circle> circles;
  delaunay(
      xy,
      [&](int i, int j, int k, const std::vector<double>& moved) {
        const int v[3] = {i, j, k};
        // Lowest-numbered point first, and of two copies of it (a few points) the one lowest in x, then y:
        // one translate of the triangle has the point itself there.
        const int* first = std::min_element(v, v + 3, [&](int a, int b) {
          return std::tie(original[a], xy[2 * a], xy[2 * a + 1]) <
                 std::tie(original[b], xy[2 * b], xy[2 * b + 1]);
        });
        if (std::size_t(*first) >= n) return;  // another copy's
        const Circle c = delaunay_circle(xy, moved, i, j, k);
        if (std::isfinite(c.r)) circles.push_back(c);  // else flat
      },
      &original);
  return circles;
}

/// The circumcircles of a torus set's Delaunay triangles, each once, with the set's copies within a margin
/// m of the square (or of the lx × ly rectangle, `coords` in its lengths): fewer than 2n circles, or one
/// past the copies, mean the margin was too narrow for some (a wide hole, or few points). It then grows
/// and the set is triangulated again, up to m = 2·max(lx, ly): no empty circle of a torus is wider than
/// half its diagonal, so none reaches farther than the diagonal past its lowest point.
std::vector<Circle> torus_circles_by_margin(const std::vector<double>& coords, double spacing, double lx = 1,
                                            double ly = 1) {
  const std::size_t n = coords.size() / 2;
  const double cap = 2 * std::max(lx, ly);
  for (double m = std::min(cap, 4 * spacing);;) {
    std::vector<double> xy = coords;
    std::vector<std::size_t> original;  // the point each copy stands for
    for (std::size_t i = 0; i < n; ++i) original.push_back(i);
    const int shifts_x = static_cast<int>(std::ceil(m / lx)), shifts_y = static_cast<int>(std::ceil(m / ly));
    for (std::size_t i = 0; i < n; ++i)
      for (int sx = -shifts_x; sx <= shifts_x; ++sx)
        for (int sy = -shifts_y; sy <= shifts_y; ++sy) {
          const double x = coords[2 * i] + sx * lx, y = coords[2 * i + 1] + sy * ly;
          if ((sx || sy) && x > -m && x < lx + m && y > -m && y < ly + m)
            xy.insert(xy.end(), {x, y}), original.push_back(i);
        }
    const std::vector<Circle> circles = counted_circles(xy, original, n);
    double reach = 0;  // how far the circles reach past the square
    for (const Circle& c : circles)
      reach = std::max({reach, c.r - c.x, c.x + c.r - lx, c.r - c.y, c.y + c.r - ly});
    if ((reach <= m && circles.size() == 2 * n) || m >= cap) return circles;
    m = std::min(cap, std::max(2 * m, 1.01 * reach));
  }
}

/// Where a torus set's copies are needed: cells about a spacing wide over the square and around it, those
/// that a Delaunay circle through a point of the square may cover. An empty circle centred in a cell d
/// cells (centre to centre) from the nearest one holding a point is at most d + √2 cells wide. A margin as
/// wide as the widest hole all round copied a steep ramp's dense side 25 times (10^5 points of ramp:1e9:
/// 2.5 million points, 29 s and 1.6 GB); this copies it only beside the wide holes (0.16 million).
/// A rectangle lx × ly (`coords` in its lengths) has gx × gy cells, not quite square: lengths are then
/// in units of the shorter cell side h (a cell is ax × ay of them), and reaches in whole cells are counted
/// as if every cell were h wide, which can only copy more. The square's cells are exactly as they were.
class CopyRegion {
 public:
  CopyRegion(const std::vector<double>& coords, double spacing, double lx = 1, double ly = 1)
      : lx_(lx), ly_(ly) {
    gx_ = std::clamp(static_cast<int>(lx / spacing), 1, 1024);
    gy_ = std::clamp(static_cast<int>(ly / spacing), 1, 1024);
    const bool square = lx == 1 && ly == 1;
    const double cx_side = lx / gx_, cy_side = ly / gy_, h = std::min(cx_side, cy_side);
    const double ax = square ? 1.0 : cx_side / h, ay = square ? 1.0 : cy_side / h;
    const std::size_t n = coords.size() / 2;
    // For each cell, the cell holding a point nearest it (or nearly: Danielsson's propagation of nearest
    // sites, in order of distance), as an offset in cells on the torus. Any cell holding a point bounds
    // the circles centred in a cell, the nearest best.
    std::vector<std::array<int, 2>> site(std::size_t(gx_) * gy_, {kNone, kNone});
    auto length2 = [&](const std::array<int, 2>& o) {
      return double(o[0]) * ax * (double(o[0]) * ax) + double(o[1]) * ay * (double(o[1]) * ay);
    };
    using Entry = std::pair<double, std::size_t>;  // squared offset, cell
    std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t c = std::size_t(cell_y(coords[2 * i + 1])) * gx_ + cell_x(coords[2 * i]);
      if (site[c][0] == kNone) site[c] = {0, 0}, queue.push({0.0, c});
    }
    while (!queue.empty()) {
      const auto [d2, q] = queue.top();
      queue.pop();
      if (d2 > length2(site[q])) continue;  // improved since
      const int cx = int(q % gx_), cy = int(q / gx_);
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const std::size_t c = std::size_t((cy + dy + gy_) % gy_) * gx_ + (cx + dx + gx_) % gx_;
          const std::array<int, 2> o = {site[q][0] - dx, site[q][1] - dy};
          if (site[c][0] == kNone || length2(o) < length2(site[c])) site[c] = o, queue.push({length2(o), c});
        }
    }
    // The widest circle centred in a cell, in cells: a point lies within the cells' centres' distance and
    // two half diagonals; no empty circle of a torus is wider than half its diagonal. The slack covers the
    // moves.
    const double diagonal = square ? std::sqrt(2.0) : std::hypot(ax, ay);
    const double widest_torus = square ? std::sqrt(0.5) * gx_ : 0.5 * std::hypot(lx, ly) / h;
    std::vector<double> widest(site.size());
    for (std::size_t c = 0; c < site.size(); ++c)
      widest[c] = std::min(std::sqrt(length2(site[c])) + diagonal, widest_torus) + kSlack;
    const int far = static_cast<int>(std::ceil(*std::max_element(widest.begin(), widest.end())));
    // Cells up to `far` outside the square may centre a circle through a point in it, which may reach
    // `far` cells further.
    margin_ = 2 * far + 1;
    side_x_ = gx_ + 2 * margin_, side_y_ = gy_ + 2 * margin_;
    // reach: how many cells around a cell a circle centred in it or near may cover; spread from each
    // cell that may centre a circle through the square to its neighbours, one less each step.
    std::vector<int> reach(std::size_t(side_x_) * side_y_, -1);
    for (int j = -margin_; j < gy_ + margin_; ++j)
      for (int i = -margin_; i < gx_ + margin_; ++i) {
        const double w = widest[std::size_t(wrap(j, gy_)) * gx_ + wrap(i, gx_)];
        const double dx = (i < 0 ? -i - 1 : std::max(0, i - gx_)) * ax,
                     dy = (j < 0 ? -j - 1 : std::max(0, j - gy_)) * ay;
        if (dx * dx + dy * dy <= w * w) reach[index(i, j)] = static_cast<int>(std::ceil(w));
      }
    for (int pass = 0; pass < 2; ++pass) {  // Rosenfeld and Pfaltz's two raster passes
      const int step = pass ? -1 : 1;
      for (int jj = 0; jj < side_y_; ++jj)
        for (int ii = 0; ii < side_x_; ++ii) {
          const int i = pass ? side_x_ - 1 - ii : ii, j = pass ? side_y_ - 1 - jj : jj;
          int& r = reach[std::size_t(j) * side_x_ + i];
          const int before[4][2] = {{-step, 0}, {-step, -step}, {0, -step}, {step, -step}};
          for (const auto& b : before) {
            const int bi = i + b[0], bj = j + b[1];
            if (bi >= 0 && bi < side_x_ && bj >= 0 && bj < side_y_)
              r = std::max(r, reach[std::size_t(bj) * side_x_ + bi] - 1);
          }
        }
    }
    // Cells left out, summed (their count in any rectangle of cells: contains()).
    left_out_.assign(std::size_t(side_x_ + 1) * (side_y_ + 1), 0);
    for (int j = 0; j < side_y_; ++j)
      for (int i = 0; i < side_x_; ++i) {
        const bool inside = i >= margin_ && i < margin_ + gx_ && j >= margin_ && j < margin_ + gy_;
        const std::size_t at = std::size_t(j + 1) * (side_x_ + 1) + (i + 1);
        left_out_[at] = (!inside && reach[std::size_t(j) * side_x_ + i] < 0) + left_out_[at - 1] +
                        left_out_[at - side_x_ - 1] - left_out_[at - side_x_ - 2];
      }
  }

  /// The points, then their copies in the region: `original` says which point each is.
  void copies(const std::vector<double>& coords, std::vector<double>& xy,
              std::vector<std::size_t>& original) const {
    const std::size_t n = coords.size() / 2;
    xy = coords;
    original.resize(n);
    std::iota(original.begin(), original.end(), std::size_t(0));
    const int shifts_x = (margin_ + gx_ - 1) / gx_, shifts_y = (margin_ + gy_ - 1) / gy_;
    for (std::size_t i = 0; i < n; ++i) {
      const int cx = cell_x(coords[2 * i]), cy = cell_y(coords[2 * i + 1]);
      for (int sx = -shifts_x; sx <= shifts_x; ++sx)
        for (int sy = -shifts_y; sy <= shifts_y; ++sy)
          if ((sx || sy) && !left_out(cx + sx * gx_, cy + sy * gy_, cx + sx * gx_, cy + sy * gy_))
            xy.insert(xy.end(), {coords[2 * i] + sx * lx_, coords[2 * i + 1] + sy * ly_}),
                original.push_back(i);
    }
  }

  /// Whether every cell a circle covers, widened by the slack, holds its copies.
  bool contains(const Circle& c) const {
    const double x0 = (c.x - c.r) / lx_ * gx_ - kSlack, x1 = (c.x + c.r) / lx_ * gx_ + kSlack;
    const double y0 = (c.y - c.r) / ly_ * gy_ - kSlack, y1 = (c.y + c.r) / ly_ * gy_ + kSlack;
    if (!(x0 >= -margin_ && y0 >= -margin_ && x1 < gx_ + margin_ && y1 < gy_ + margin_)) return false;
    return !left_out(int(std::floor(x0)), int(std::floor(y0)), int(std::floor(x1)), int(std::floor(y1)));
  }

 private:
  int cell_x(double v) const { return std::min(gx_ - 1, std::max(0, static_cast<int>(v / lx_ * gx_))); }
  int cell_y(double v) const { return std::min(gy_ - 1, std::max(0, static_cast<int>(v / ly_ * gy_))); }
  static int wrap(int i, int g) { return ((i % g) + g) % g; }
  std::size_t index(int i, int j) const { return std::size_t(j + margin_) * side_x_ + (i + margin_); }
  /// Whether a cell in [i0, i1] × [j0, j1] (cells of the plane, 0 to g − 1 the square's) is left out.
  bool left_out(int i0, int j0, int i1, int j1) const {
    if (i0 < -margin_ || j0 < -margin_ || i1 >= gx_ + margin_ || j1 >= gy_ + margin_) return true;
    auto at = [&](int i, int j) {
      return left_out_[std::size_t(j + margin_) * (side_x_ + 1) + (i + margin_)];
    };
    return at(i1 + 1, j1 + 1) - at(i0, j1 + 1) - at(i1 + 1, j0) + at(i0, j0) > 0;
  }

  static constexpr int kNone = std::numeric_limits<int>::min();
  /// Cells of slack (0.01 of a cell, at most 1024 cells to the side: 10^-5, ten moves and more) for the
  /// moves of the points and the rounding of a point to its cell.
  static constexpr double kSlack = 0.01;
  double lx_ = 1, ly_ = 1;
  int gx_ = 1, gy_ = 1, margin_ = 0, side_x_ = 1, side_y_ = 1;
  std::vector<std::int64_t> left_out_;  // (side_x + 1)(side_y + 1) prefix sums of the cells without copies
};

/// The circumcircles of a torus set's Delaunay triangles, each once, triangulated with the copies of
/// CopyRegion; none if a circle does not lie where the copies are present or they are fewer than 2n (a
/// flat triangle).
std::vector<Circle> torus_circles_around_holes(const std::vector<double>& coords, double spacing,
                                               double lx = 1, double ly = 1) {
  const std::size_t n = coords.size() / 2;
  const CopyRegion region(coords, spacing, lx, ly);
  std::vector<double> xy;
  std::vector<std::size_t> original;
  region.copies(coords, xy, original);
  std::vector<Circle> circles = counted_circles(xy, original, n);
  const auto inside = [&](const Circle& c) { return region.contains(c); };
  if (circles.size() != 2 * n || !std::all_of(circles.begin(), circles.end(), inside)) circles.clear();
  return circles;
}

/// The circumcircles of a torus set's Delaunay triangles, each once: with the copies around its holes, or
/// failing that with a margin; both give the same circles. A rectangle's `coords` are in its lengths
/// (`sides`, common.h).
std::vector<Circle> torus_circles(const std::vector<double>& coords, double spacing, const Sides& sides) {
  std::vector<Circle> circles = torus_circles_around_holes(coords, spacing, sides[0], sides[1]);
  return circles.empty() ? torus_circles_by_margin(coords, spacing, sides[0], sides[1]) : circles;
}

/// The box set's circumcircles: those centred at least `border` spacings inside the square (the lx × ly
/// rectangle, `xy` in its lengths).
std::vector<Circle> box_circles(std::vector<double> xy, double spacing, double border, double lx = 1,
                                double ly = 1) {
  std::vector<Circle> circles;
  const double m = border * spacing;
  delaunay(xy, [&](int i, int j, int k, const std::vector<double>& moved) {
    const Circle c = delaunay_circle(xy, moved, i, j, k);
    if (std::isfinite(c.r) && c.x >= m && c.x <= lx - m && c.y >= m && c.y <= ly - m) circles.push_back(c);
  });
  return circles;
}

/// The set's points with every coincident one after the first left out, in their order (the same vector
/// when there are none). Coincident points have the empty circles of their position once; triangulated
/// each, their zero-width triangles fail the torus's count of 2n circles, which then triangulated 25
/// copies of the square (4,096 points and 2,000 duplicates: 3.9 s, against 0.03 s without them).
std::vector<double> distinct_positions(const std::vector<double>& coords) {
  const std::size_t n = coords.size() / 2;
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return std::tie(coords[2 * a], coords[2 * a + 1], a) < std::tie(coords[2 * b], coords[2 * b + 1], b);
  });
  std::vector<char> repeat(n, 0);
  bool any = false;
  for (std::size_t k = 1; k < n; ++k) {
    const std::size_t a = order[k - 1], b = order[k];
    if (coords[2 * a] == coords[2 * b] && coords[2 * a + 1] == coords[2 * b + 1]) repeat[b] = 1, any = true;
  }
  if (!any) return coords;
  std::vector<double> out;
  for (std::size_t i = 0; i < n; ++i)
    if (!repeat[i]) out.insert(out.end(), {coords[2 * i], coords[2 * i + 1]});
  return out;
}

SetCircles judge_set(const tools::PointSet& set, const EmptyCircleOptions& o, double mean_rho,
                     double max_rho) {
  SetCircles out;
  const double spacing = hex_spacing(set.size());  // of all the points, coincident ones too
  const double edge_band = o.tile_size > 0 ? spacing : 0;
  const double lx = o.sides[0], ly = o.sides[1];
  const bool square = lx == 1 && ly == 1;
  std::vector<double> xy = distinct_positions(set.coords);
  if (!square)  // triangulated in the rectangle's own lengths: a Delaunay triangulation is no affine map's
    for (std::size_t i = 0; i < xy.size(); i += 2) xy[i] *= lx, xy[i + 1] *= ly;
  for (const Circle& c :
       o.torus ? torus_circles(xy, spacing, o.sides) : box_circles(xy, spacing, o.border, lx, ly)) {
    double local = spacing;
    double u = square ? c.x : c.x / lx, v = square ? c.y : c.y / ly;  // normalised, as the density reads
    if (o.torus) {  // a triangle across the seam is counted once, its centre perhaps past the edge
      u -= std::floor(u), v -= std::floor(v);
    }
    if (o.density) {
      const double rho = o.density(std::clamp(u, 0.0, 1.0), std::clamp(v, 0.0, 1.0));
      if (!(rho > 0) || rho < o.min_relative_density * max_rho) continue;
      local = spacing * std::sqrt(mean_rho / rho);
    }
    const double r = c.r / local;
    out.radii.push_back(r);
    if (r > out.largest) out.largest = r, out.largest_x = u, out.largest_y = v;
    bool near_edge = false;
    if (edge_band > 0) {
      auto gap = [&](double v) {
        const double t = v / o.tile_size;
        return std::fabs(t - std::round(t)) * o.tile_size;
      };
      near_edge = std::min(gap(c.x), gap(c.y)) < edge_band;
      out.near_edge_judged += near_edge;
    }
    if (r > 0.85) out.over_085 += 1, out.over_085_near_edge += near_edge;
    if (r > 1.0) out.over_100 += 1;
  }
  return out;
}

}  // namespace

namespace detail {

std::vector<double> torus_circumradii(const std::vector<double>& coords, TorusCopies copies, double lx,
                                      double ly) {
  const double spacing = hex_spacing(coords.size() / 2);
  std::vector<double> radii;
  for (const Circle& c : copies == TorusCopies::kAroundHoles
                             ? torus_circles_around_holes(coords, spacing, lx, ly)
                             : torus_circles_by_margin(coords, spacing, lx, ly))
    radii.push_back(c.r);
  return radii;
}

}  // namespace detail

EmptyCircles empty_circles(const std::vector<tools::PointSet>& sets, const EmptyCircleOptions& o) {
  if (sets.empty()) throw InvalidInput("no point sets");
  const std::pair<double, double> scale =
      o.density ? density_scale(o.density) : std::pair<double, double>(1, 1);
  const double mean_rho = scale.first, max_rho = scale.second;
  if (o.density && !(mean_rho > 0)) throw InvalidInput("the target density is zero everywhere");
  if (!(o.sides[0] > 0 && o.sides[1] > 0 && std::isfinite(o.sides[0]) && std::isfinite(o.sides[1])))
    throw InvalidInput("the domain's sides must be positive finite numbers");
  if (o.tile_size > 0 && !unit_sides(o.sides))
    throw InvalidInput("tile edges are those of square tiles of the unit square, not of a rectangle");
  EmptyCircles out;
  for (const tools::PointSet& set : sets) {
    if (set.dim != 2) throw InvalidInput("empty circles are 2D only");
    validate_points(set.coords, 2);
    if (set.size() < 3) throw InvalidInput("empty circles need at least 3 points per set");
    out.points += set.size();
  }
  // Sets are triangulated in parallel and pooled in their order, so nothing depends on the thread count.
  std::vector<SetCircles> per_set(sets.size());
  std::vector<std::string> failure(sets.size());
  std::vector<char> degenerate(sets.size(), 0);
  detail::parallel_for(std::ptrdiff_t(sets.size()), o.threads, [&](std::ptrdiff_t s, int) {
    try {
      per_set[s] = judge_set(sets[s], o, mean_rho, max_rho);
    } catch (const DegenerateSet& e) {
      failure[s] = e.what(), degenerate[s] = 1;
    } catch (const InvalidInput& e) {
      failure[s] = e.what();
    }
  });
  for (std::size_t s = 0; s < sets.size(); ++s) {
    if (degenerate[s]) throw DegenerateSet(failure[s]);
    if (!failure[s].empty()) throw InvalidInput(failure[s]);
  }
  std::vector<double> radii;
  std::size_t near_edge_judged = 0;
  double largest = -1;
  for (std::size_t k = 0; k < per_set.size(); ++k) {
    const SetCircles& c = per_set[k];
    if (c.largest > largest)
      largest = c.largest, out.largest_set = k, out.largest_x = c.largest_x, out.largest_y = c.largest_y;
    radii.insert(radii.end(), c.radii.begin(), c.radii.end());
    out.over_085 += c.over_085, out.over_100 += c.over_100, out.over_085_near_edge += c.over_085_near_edge;
    near_edge_judged += c.near_edge_judged;
  }
  out.triangles = radii.size();
  if (!radii.empty()) {
    out.largest = *std::max_element(radii.begin(), radii.end());
    const std::size_t rank =
        std::min(radii.size() - 1, static_cast<std::size_t>(std::ceil(0.999 * radii.size())) - 1);
    std::nth_element(radii.begin(), radii.begin() + std::ptrdiff_t(rank), radii.end());
    out.p999 = radii[rank];
    out.near_edge_share = double(near_edge_judged) / double(radii.size());
  }
  return out;
}

}  // namespace kdm::analysis
