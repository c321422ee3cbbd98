// The hand-over between depths; see handover.h.
#include "bake/handover.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>

#include "bake/min_cost_assignment.h"
#include "bake/progressive_order.h"
#include "kdm/runtime/check.h"

namespace kdm::gen {
namespace {

// Worlds here are 2×2 tori of parent tiles (Colouring::around_tile); sub-steps count 1/m of a parent.
constexpr std::int64_t kParents = 2;

std::int64_t floor_div(std::int64_t a, std::int64_t b) {
  return a >= 0 ? a / b : -((-a + b - 1) / b);
}
std::int64_t wrap(std::int64_t v, std::int64_t period) {
  return ((v % period) + period) % period;
}
/// v wrapped into [−period/2, period/2).
std::int64_t centred(std::int64_t v, std::int64_t period) {
  return wrap(v + period / 2, period) - period / 2;
}
double centred(double v, double period) {
  return v - period * std::floor(v / period + 0.5);
}

/// A point of some patch, by identity: the patch, its index there and the patch's anchor (sub-steps for
/// sub-points, relative to a reference the caller chooses).
struct PointKey {
  const Patch* patch = nullptr;
  std::uint32_t index = 0;
  std::int64_t ax = 0, ay = 0;
  bool operator<(const PointKey& o) const {
    return std::tie(patch, index, ax, ay) < std::tie(o.patch, o.index, o.ax, o.ay);
  }
};

/// Which class of parent zone decides a sub-point: a corner (anchor: the vertex), a horizontal or vertical
/// edge (anchor: its west / south vertex) or an interior (anchor: the tile), in parent units mod 2.
struct ZoneId {
  int kind = 3;  // PatchKind order: corner, horizontal edge, vertical edge, interior
  std::int64_t x = 0, y = 0;
  bool operator<(const ZoneId& o) const { return std::tie(kind, x, y) < std::tie(o.kind, o.x, o.y); }
  bool operator==(const ZoneId& o) const { return kind == o.kind && x == o.x && y == o.y; }
};

struct SubPoint {
  PointKey key;           ///< anchor in sub-steps on the world's torus
  double sx = 0, sy = 0;  ///< stable position, sub-steps
  double x = 0, y = 0;    ///< position at keyframe 1, sub-steps
  ZoneId zone;            ///< the class that decides it
};

PatchKind kind_of(const LevelPatches& level, const Patch* p, std::size_t& index) {
  for (int k = 0; k < 4; ++k) {
    const std::vector<Patch>& v = level.of(static_cast<PatchKind>(k));
    if (!v.empty() && p >= v.data() && p < v.data() + v.size()) {
      index = static_cast<std::size_t>(p - v.data());
      return static_cast<PatchKind>(k);
    }
  }
  return PatchKind::kInterior;  // not reached for a patch of this level
}

/// The sub world of a 2×2 torus of parent tiles: sub-vertex colours by the subdivision rule.
class SubWorld {
 public:
  SubWorld(const std::vector<LevelPatches>& levels, const TilesetData& set, const Subdivision& sub,
           const Colouring& parents)
      : levels_(levels), set_(set), sub_(sub), parents_(parents) {
    const std::int64_t period = kParents * sub.m;
    std::vector<std::uint32_t> grid(std::size_t(period * period));
    for (std::int64_t J = 0; J < period; ++J)
      for (std::int64_t I = 0; I < period; ++I) {
        const std::int64_t P = I / sub.m, Q = J / sub.m;
        grid[std::size_t(J * period + I)] =
            sub.vertex_colour(parents.at(P, Q), parents.at(P + 1, Q), parents.at(P + 1, Q + 1),
                              parents.at(P, Q + 1), std::uint32_t(I % sub.m), std::uint32_t(J % sub.m));
      }
    sub_colouring_ = Colouring::torus(set.colours, int(period), int(period), std::move(grid));
  }

  const Colouring& colouring() const { return sub_colouring_; }

  /// The parent zone class of a sub-vertex (torus sub-steps).
  ZoneId zone_of_vertex(std::int64_t I, std::int64_t J) const {
    const std::int64_t m = sub_.m, period = kParents * m;
    I = wrap(I, period), J = wrap(J, period);
    const std::int64_t P = I / m, Q = J / m, i = I % m, j = J % m;
    const std::int64_t vx = wrap(i * 2 > m ? P + 1 : P, kParents), vy = wrap(j * 2 > m ? Q + 1 : Q, kParents);
    switch (sub_.zone_of(std::uint32_t(i), std::uint32_t(j))) {
      case Subdivision::Zone::kCorner:
        return {0, vx, vy};
      case Subdivision::Zone::kHorizontalEdge:
        return {1, P, vy};
      case Subdivision::Zone::kVerticalEdge:
        return {2, vx, Q};
      case Subdivision::Zone::kInterior:
        break;
    }
    return {3, P, Q};
  }

  /// Every sub-point present at keyframe 1 whose stable position lies in [x0, x1) × [y0, y1) (sub-steps).
  std::vector<SubPoint> points(double x0, double y0, double x1, double y1) const {
    std::vector<SubPoint> out;
    for (std::size_t k = 0; k < levels_.size(); ++k) {
      if (k > 0 && set_.level_nominal[k - 1] >= set_.keyframe_nominal[1]) break;
      std::vector<double> xy;
      std::vector<std::uint16_t> keys;
      std::vector<PatchPointRef> refs;
      gather(levels_[k], sub_colouring_, {true, true, true, true}, x0, y0, x1, y1, xy, &keys, &refs);
      for (std::size_t n = 0; n < refs.size(); ++n) {
        if (!TilesetShape::emits(set_.emission_threshold(std::uint32_t(k), keys[n]),
                                 set_.keyframe_nominal[1]))
          continue;
        const PatchPointRef& ref = refs[n];
        const auto ax = static_cast<std::int64_t>(std::llround(ref.anchor_x + x0));
        const auto ay = static_cast<std::int64_t>(std::llround(ref.anchor_y + y0));
        KDM_CHECK(ref.patch->frames.size() > 1 && !ref.patch->frames[1].empty());
        SubPoint p;
        p.key = {ref.patch, ref.index, ax, ay};
        p.sx = xy[2 * n] + x0, p.sy = xy[2 * n + 1] + y0;
        p.x = double(ax) + ref.patch->frames[1][2 * ref.index];
        p.y = double(ay) + ref.patch->frames[1][2 * ref.index + 1];
        std::size_t patch_index = 0;
        const PatchKind kind = kind_of(levels_[k], ref.patch, patch_index);
        p.zone = class_of(kind, ax, ay, p.sx, p.sy);
        out.push_back(p);
      }
    }
    return out;
  }

 private:
  /// The narrowest zone class holding every sub-vertex the patch (kind, anchor) depends on.
  ZoneId class_of(PatchKind kind, std::int64_t ax, std::int64_t ay, double sx, double sy) const {
    // The sub-vertices the patch depends on: its vertex, its edge's ends or its subtile's corners.
    std::array<ZoneId, 4> depends;
    int n = 0;
    const std::int64_t wide = kind == PatchKind::kHorizontalEdge || kind == PatchKind::kInterior;
    const std::int64_t tall = kind == PatchKind::kVerticalEdge || kind == PatchKind::kInterior;
    for (std::int64_t dy = 0; dy <= tall; ++dy)
      for (std::int64_t dx = 0; dx <= wide; ++dx)
        depends[std::size_t(n++)] = zone_of_vertex(ax + dx, ay + dy);
    const auto zones = [&] { return std::vector<ZoneId>(depends.begin(), depends.begin() + n); }();
    const ZoneId interior{3, wrap(floor_div(std::int64_t(std::floor(sx)), sub_.m), kParents),
                          wrap(floor_div(std::int64_t(std::floor(sy)), sub_.m), kParents)};
    if (std::all_of(zones.begin(), zones.end(),
                    [&](const ZoneId& z) { return z.kind == 0 && z == zones[0]; }))
      return zones[0];
    const ZoneId* edge = nullptr;
    for (const ZoneId& z : zones) {
      if (z.kind == 3) return interior;
      if (z.kind == 0) continue;
      if (edge && !(*edge == z)) return interior;
      edge = &z;
    }
    if (!edge) return interior;  // corners of two different vertices
    const ZoneId a{0, edge->x, edge->y},
        b{0, wrap(edge->x + (edge->kind == 1), kParents), wrap(edge->y + (edge->kind == 2), kParents)};
    for (const ZoneId& z : zones)
      if (z.kind == 0 && !(z == a) && !(z == b)) return interior;
    return *edge;
  }

  const std::vector<LevelPatches>& levels_;
  const TilesetData& set_;
  Subdivision sub_;
  Colouring parents_;
  Colouring sub_colouring_;
};

/// A point to match: position (parent units, on the 2×2 torus) and the parent tile showing it.
struct Spot {
  double x = 0, y = 0;
  int square = 0;
};

/// Least total squared distance, each row to a column of its square within `reach` (parent units),
/// widening the reach until every row finds one.
std::vector<std::uint32_t> match(const std::vector<Spot>& rows, const std::vector<Spot>& columns,
                                 double reach, const std::string& what) {
  std::vector<std::uint32_t> row_column;
  if (rows.empty()) return row_column;
  for (int attempt = 0; attempt < 6; ++attempt, reach *= 1.5) {
    const auto cells = std::max<std::int64_t>(1, std::int64_t(kParents / reach));
    const double cell = double(kParents) / double(cells);
    std::vector<std::vector<std::uint32_t>> grid(std::size_t(cells * cells));
    const auto cell_of = [&](double v) { return wrap(std::int64_t(std::floor(v / cell)), cells); };
    for (std::uint32_t c = 0; c < columns.size(); ++c)
      grid[std::size_t(cell_of(columns[c].y) * cells + cell_of(columns[c].x))].push_back(c);
    std::vector<AssignmentEdge> edges;
    const double scale = 1.0 / (reach * reach);  // costs of order 1
    for (std::uint32_t r = 0; r < rows.size(); ++r) {
      const std::int64_t cx = cell_of(rows[r].x), cy = cell_of(rows[r].y);
      std::set<std::int64_t> seen;  // small tori: a neighbour cell may repeat
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dx = -1; dx <= 1; ++dx) {
          const std::int64_t at = wrap(cy + dy, cells) * cells + wrap(cx + dx, cells);
          if (!seen.insert(at).second) continue;
          for (std::uint32_t c : grid[std::size_t(at)]) {
            if (columns[c].square != rows[r].square) continue;
            const double ex = centred(columns[c].x - rows[r].x, double(kParents));
            const double ey = centred(columns[c].y - rows[r].y, double(kParents));
            const double d2 = ex * ex + ey * ey;
            if (d2 <= reach * reach) edges.push_back({r, c, d2 * scale});
          }
        }
    }
    if (min_cost_assignment(std::uint32_t(rows.size()), std::uint32_t(columns.size()), edges, row_column))
      return row_column;
  }
  throw std::runtime_error("hand-over: " + what + " finds too few sub-points (" +
                           std::to_string(rows.size()) + " points, " + std::to_string(columns.size()) +
                           " sub-points)");
}

int square_of(double x, double y) {  // parent units on the 2×2 torus
  return int(wrap(std::int64_t(std::floor(x)), kParents) +
             kParents * wrap(std::int64_t(std::floor(y)), kParents));
}

/// Which matching a parent point joins, by where its stable position lies and what its patch depends on:
/// a corner group (a point of the vertex's corner patch within the top level's corner half-width of it),
/// an edge group (a point of either end's corner patch or of the edge's own patch within the top level's
/// edge half-width of its line), else the interior of the tile that shows it. Points near a tile edge thus
/// move the same way in every tile that shows them; those farther in (coarse levels' wide patches) are
/// matched with their tile's interior, whose neighbourhood they share in every tile anyway. Anchors are
/// the group's vertex (corner), west or south vertex (edge) or tile corner (interior), parent units.
ZoneId group_of(PatchKind kind, std::int64_t ax, std::int64_t ay, double rx, double ry, PatchWidths top) {
  switch (kind) {
    case PatchKind::kCorner:
      if (std::max(std::fabs(rx), std::fabs(ry)) < top.corner) return {0, ax, ay};
      if (std::fabs(ry) < top.edge) return {1, rx > 0 ? ax : ax - 1, ay};
      if (std::fabs(rx) < top.edge) return {2, ax, ry > 0 ? ay : ay - 1};
      break;
    case PatchKind::kHorizontalEdge:
      if (std::fabs(ry) < top.edge) return {1, ax, ay};
      break;
    case PatchKind::kVerticalEdge:
      if (std::fabs(rx) < top.edge) return {2, ax, ay};
      break;
    case PatchKind::kInterior:
      break;
  }
  return {3, std::int64_t(std::floor(double(ax) + rx)), std::int64_t(std::floor(double(ay) + ry))};
}

/// A parent point to match: which (patch, index; anchor unused) and where (top keyframe, parent tile).
struct Row {
  PointKey key;
  Spot spot;
};

/// The matching of one patch class: sub-points (anchors relative to the class's anchor vertex) and the
/// parent points (patch, index; anchor unused) they went to, both ways.
struct Claims {
  std::map<PointKey, PointKey> by_sub, by_row;
  bool holds(const PointKey& sub_point) const { return by_sub.count(sub_point) > 0; }
};

/// Where relative anchors are centred for a class kind (sub-steps from its anchor vertex): the vertex for
/// corners, the edge's middle for edges, the tile's middle for interiors.
std::int64_t centre_x(int kind, std::int64_t m) {
  return kind == 1 || kind == 3 ? m / 2 : 0;
}
std::int64_t centre_y(int kind, std::int64_t m) {
  return kind == 2 || kind == 3 ? m / 2 : 0;
}

/// Finds the patch `p` among the levels' patches: its kind and index there.
void locate(const std::vector<LevelPatches>& levels, const Patch* p, PatchKind& kind, std::size_t& index) {
  for (const LevelPatches& level : levels)
    for (int k = 0; k < 4; ++k) {
      const std::vector<Patch>& v = level.of(static_cast<PatchKind>(k));
      if (!v.empty() && p >= v.data() && p < v.data() + v.size()) {
        kind = static_cast<PatchKind>(k);
        index = static_cast<std::size_t>(p - v.data());
        return;
      }
    }
  KDM_CHECK(false);
}

class Planner {
 public:
  Planner(const std::vector<LevelPatches>& levels, const TilesetData& set, const Subdivision& sub,
          PatchWidths top_widths)
      : levels_(levels), set_(set), sub_(sub), C_(set.colours), top_widths_(top_widths) {
    reach_ = 2.5 / std::sqrt(double(set.level_nominal.back()));
    top_ = set.keyframe_nominal.size() - 1;
  }

  void plan_corners() {
    corner_.resize(C_);
    for (std::uint32_t c = 0; c < C_; ++c) {
      const SubWorld world(levels_, set_, sub_, Colouring::around_tile(C_, tile(c, 0, 0, 0)));
      std::vector<SubPoint> columns;
      for (const SubPoint& p : world.points(0, 0, kParents * sub_.m, kParents * sub_.m))
        if (p.zone == ZoneId{0, 0, 0}) columns.push_back(p);
      std::vector<Row> rows;
      for (const LevelPatches& level : levels_)
        add_rows(level.corners[c], PatchKind::kCorner, 0, 0, {0, 0, 0}, rows);
      corner_[c] = run(rows, 0, 0, 0, columns, "corner " + std::to_string(c));
    }
  }

  void plan_edges() {
    for (int kind = 1; kind <= 2; ++kind) {
      edge_[kind - 1].resize(std::size_t(C_) * C_);
      for (std::uint32_t a = 0; a < C_; ++a)
        for (std::uint32_t b = 0; b < C_; ++b) {
          // An edge from vertex (0, 0) east (kind 1: the tile's south edge) or north (kind 2: its west edge).
          const std::size_t t = kind == 1 ? tile(a, b, 0, 0) : tile(a, 0, 0, b);
          const SubWorld world(levels_, set_, sub_, Colouring::around_tile(C_, t));
          const std::int64_t ex = kind == 1, ey = kind == 2;
          std::vector<SubPoint> columns;
          for (const SubPoint& p : world.points(0, 0, kParents * sub_.m, kParents * sub_.m)) {
            if (p.zone == ZoneId{kind, 0, 0}) {
              columns.push_back(p);
            } else if (p.zone.kind == 0 &&
                       ((p.zone.x == 0 && p.zone.y == 0) || (p.zone.x == ex && p.zone.y == ey))) {
              const bool at_start = p.zone.x == 0 && p.zone.y == 0;
              const std::uint32_t colour = at_start ? a : b;
              if (corner_[colour].holds(relative(p.key, 0, p.zone.x, p.zone.y))) continue;
              if (sector(p, p.zone.x, p.zone.y) == ZoneId{kind, 0, 0}) columns.push_back(p);
            }
          }
          std::vector<Row> rows;
          const ZoneId group{kind, 0, 0};
          for (const LevelPatches& level : levels_) {
            const auto edge_kind = static_cast<PatchKind>(kind);
            add_rows(level.of(edge_kind)[a * C_ + b], edge_kind, 0, 0, group, rows);
            add_rows(level.corners[a], PatchKind::kCorner, 0, 0, group, rows);
            add_rows(level.corners[b], PatchKind::kCorner, ex, ey, group, rows);
          }
          edge_[kind - 1][a * C_ + b] = run(rows, kind, 0, 0, columns, "edge " + std::to_string(a * C_ + b));
        }
    }
  }

  /// The interior of tile t, then its tables.
  TileHandover plan_tile(std::size_t t, const std::vector<std::vector<PatchPointRef>>& ranked) {
    const Colouring parents = Colouring::around_tile(C_, t);
    const SubWorld world(levels_, set_, sub_, parents);
    std::vector<SubPoint> columns, all = world.points(0, 0, sub_.m, sub_.m);
    for (const SubPoint& p : all)
      if (!claimed(p, parents)) columns.push_back(p);
    std::vector<Row> rows;
    std::vector<ZoneId> groups;
    for (const PatchPointRef& ref : ranked[t]) {
      const auto ax = std::int64_t(std::llround(ref.anchor_x)), ay = std::int64_t(std::llround(ref.anchor_y));
      std::size_t index = 0;
      PatchKind kind = PatchKind::kInterior;
      locate(levels_, ref.patch, kind, index);
      const double rx = ref.patch->xy[2 * ref.index], ry = ref.patch->xy[2 * ref.index + 1];
      groups.push_back(group_of(kind, ax, ay, rx, ry, top_widths_));
      if (groups.back().kind == 3) rows.push_back(row(*ref.patch, ref.index, ax, ay));
    }
    const Claims interior = run(rows, 3, 0, 0, columns, "interior " + std::to_string(t));

    TileHandover out;
    std::set<PointKey> taken;  // absolute anchors
    for (std::size_t r = 0; r < ranked[t].size(); ++r) {
      const PatchPointRef& ref = ranked[t][r];
      const ZoneId g = groups[r];
      const auto colour = [&](std::int64_t x, std::int64_t y) { return parents.at(x, y); };
      const Claims& claims =
          g.kind == 0 ? corner_[colour(g.x, g.y)]
          : g.kind == 3
              ? interior
              : edge_[g.kind - 1][colour(g.x, g.y) * C_ + colour(g.x + (g.kind == 1), g.y + (g.kind == 2))];
      const auto found = claims.by_row.find({ref.patch, ref.index, 0, 0});
      KDM_CHECK(found != claims.by_row.end());
      const std::int64_t gx = g.kind == 3 ? 0 : g.x, gy = g.kind == 3 ? 0 : g.y;
      const PointKey sub_point{found->second.patch, found->second.index, found->second.ax + gx * sub_.m,
                               found->second.ay + gy * sub_.m};
      taken.insert(sub_point);
      out.target.push_back(pack(sub_point, parents));
    }
    std::vector<double> fixed, leftovers;
    std::vector<std::uint32_t> leftover_packed;
    const auto unit = [&](double v) { return v / sub_.m - std::floor(v / sub_.m); };  // on the unit torus
    for (const SubPoint& p : all) {
      if (taken.count(p.key)) {
        fixed.insert(fixed.end(), {unit(p.x), unit(p.y)});
      } else {
        leftovers.insert(leftovers.end(), {unit(p.x), unit(p.y)});
        leftover_packed.push_back(pack(p.key, parents));
      }
    }
    KDM_CHECK(taken.size() == out.target.size());
    RankingInput order;
    order.candidates = leftovers;
    order.fixed = fixed;
    order.filter_width = 1.5 / std::sqrt(double(set_.level_nominal.back()));
    for (std::uint32_t i : progressive_order(order)) out.appearing.push_back(leftover_packed[i]);
    return out;
  }

  /// Rank lookups for every tile: (patch, index, anchor relative to the tile) -> rank.
  void index_ranks(const std::vector<std::vector<PatchPointRef>>& ranked) {
    rank_of_.resize(ranked.size());
    for (std::size_t t = 0; t < ranked.size(); ++t)
      for (std::uint32_t r = 0; r < ranked[t].size(); ++r) {
        const PatchPointRef& ref = ranked[t][r];
        rank_of_[t][{ref.patch, ref.index, std::llround(ref.anchor_x), std::llround(ref.anchor_y)}] = r;
      }
  }

 private:
  std::size_t tile(std::uint32_t sw, std::uint32_t se, std::uint32_t ne, std::uint32_t nw) const {
    return set_.tile_index(sw, se, ne, nw);
  }

  /// Key k with its anchor relative to vertex (vx, vy), for a class of kind `kind` (so that the class's
  /// sub-points all lie within half the torus of its centre).
  PointKey relative(const PointKey& k, int kind, std::int64_t vx, std::int64_t vy) const {
    const std::int64_t period = kParents * sub_.m, cx = centre_x(kind, sub_.m), cy = centre_y(kind, sub_.m);
    return {k.patch, k.index, centred(k.ax - vx * sub_.m - cx, period) + cx,
            centred(k.ay - vy * sub_.m - cy, period) + cy};
  }

  /// The edge whose sector around vertex (vx, vy) holds p: east or west (kind 1), north or south (kind 2),
  /// by its stable position; the edge's anchor is its west / south vertex.
  ZoneId sector(const SubPoint& p, std::int64_t vx, std::int64_t vy) const {
    const double dx = centred(p.sx / sub_.m - double(vx), double(kParents));
    const double dy = centred(p.sy / sub_.m - double(vy), double(kParents));
    if (std::fabs(dy) < std::fabs(dx)) return {1, wrap(dx > 0 ? vx : vx - 1, kParents), vy};
    return {2, vx, wrap(dy > 0 ? vy : vy - 1, kParents)};
  }

  bool claimed(const SubPoint& p, const Colouring& parents) const {
    const auto edge_claims = [&](const ZoneId& e) -> const Claims& {
      const std::uint32_t a = parents.at(e.x, e.y), b = parents.at(e.x + (e.kind == 1), e.y + (e.kind == 2));
      return edge_[e.kind - 1][a * C_ + b];
    };
    if (p.zone.kind == 3) return false;
    if (p.zone.kind == 0) {
      if (corner_[parents.at(p.zone.x, p.zone.y)].holds(relative(p.key, 0, p.zone.x, p.zone.y))) return true;
      const ZoneId e = sector(p, p.zone.x, p.zone.y);
      return edge_claims(e).holds(relative(p.key, e.kind, e.x, e.y));
    }
    return edge_claims(p.zone).holds(relative(p.key, p.zone.kind, p.zone.x, p.zone.y));
  }

  /// Matches the points of every level's patch (kind, index) anchored at parent vertex (vx, vy) to
  /// `columns` (sub-points on the same world); returns the claims keyed relative to that vertex.
  /// Point i of `patch` (anchored at parent vertex (ax, ay)) as a row.
  Row row(const Patch& patch, std::uint32_t i, std::int64_t ax, std::int64_t ay) const {
    const auto& frame = patch.frames[top_];
    KDM_CHECK(frame.size() == 2 * patch.size());
    return {{&patch, i, 0, 0},
            {double(ax) + frame[2 * i], double(ay) + frame[2 * i + 1],
             square_of(double(ax) + patch.xy[2 * i], double(ay) + patch.xy[2 * i + 1])}};
  }

  /// Appends the points of `patch` (of kind `kind`, anchored at (ax, ay)) that join `group`.
  void add_rows(const Patch& patch, PatchKind kind, std::int64_t ax, std::int64_t ay, const ZoneId& group,
                std::vector<Row>& rows) const {
    for (std::uint32_t i = 0; i < patch.size(); ++i)
      if (group_of(kind, ax, ay, patch.xy[2 * i], patch.xy[2 * i + 1], top_widths_) == group)
        rows.push_back(row(patch, i, ax, ay));
  }

  /// Matches `rows` to `columns` (sub-points on the same world); returns the claims keyed relative to
  /// the class's vertex (vx, vy) (class kind `kind`: 0 corner, 1, 2 edges, 3 interior).
  Claims run(const std::vector<Row>& rows, int kind, std::int64_t vx, std::int64_t vy,
             const std::vector<SubPoint>& columns, const std::string& what) const {
    std::vector<Spot> spots, cols;
    for (const Row& r : rows) spots.push_back(r.spot);
    for (const SubPoint& p : columns)
      cols.push_back({p.x / sub_.m, p.y / sub_.m, square_of(p.sx / sub_.m, p.sy / sub_.m)});
    const std::vector<std::uint32_t> row_column = match(spots, cols, reach_, what);
    Claims claims;
    for (std::size_t r = 0; r < row_column.size(); ++r) {
      const PointKey sub_point = relative(columns[row_column[r]].key, kind, vx, vy);
      claims.by_sub[sub_point] = rows[r].key;
      claims.by_row[rows[r].key] = sub_point;
    }
    return claims;
  }

  /// (j << 16) | q of a sub-point of tile (0, 0) of `parents` (anchor absolute, sub-steps).
  std::uint32_t pack(const PointKey& key, const Colouring& parents) const {
    const double sx = double(key.ax) + key.patch->xy[2 * key.index];
    const double sy = double(key.ay) + key.patch->xy[2 * key.index + 1];
    const auto si = std::int64_t(std::floor(sx)), sj = std::int64_t(std::floor(sy));
    KDM_CHECK(si >= 0 && si < sub_.m && sj >= 0 && sj < sub_.m);
    std::uint32_t corner[4];
    const std::int64_t I[4] = {si, si + 1, si + 1, si}, J[4] = {sj, sj, sj + 1, sj + 1};
    for (int v = 0; v < 4; ++v)
      corner[v] = sub_.vertex_colour(parents.at(0, 0), parents.at(1, 0), parents.at(1, 1), parents.at(0, 1),
                                     std::uint32_t(I[v]), std::uint32_t(J[v]));
    const std::size_t type = tile(corner[0], corner[1], corner[2], corner[3]);
    const auto found = rank_of_[type].find({key.patch, key.index, key.ax - si, key.ay - sj});
    KDM_CHECK(found != rank_of_[type].end());
    KDM_CHECK(found->second < 65536 && sj * sub_.m + si < 65536);
    return std::uint32_t(sj * sub_.m + si) << 16 | found->second;
  }

  const std::vector<LevelPatches>& levels_;
  const TilesetData& set_;
  Subdivision sub_;
  std::uint32_t C_;
  PatchWidths top_widths_;
  double reach_ = 0;
  std::size_t top_ = 0;
  std::vector<Claims> corner_;
  std::vector<Claims> edge_[2];
  std::vector<std::map<PointKey, std::uint32_t>> rank_of_;
};

}  // namespace

std::vector<TileHandover> plan_handover(const std::vector<LevelPatches>& levels, const TilesetData& set,
                                        const std::vector<std::vector<PatchPointRef>>& ranked,
                                        const Subdivision& sub, PatchWidths top_widths) {
  KDM_CHECK(sub.m >= 2 && 2 * sub.zone + 1 < sub.m && sub.colours == set.colours);
  KDM_CHECK(set.keyframe_nominal.size() >= 2 && ranked.size() == set.tiles.size());
  Planner planner(levels, set, sub, top_widths);
  planner.index_ranks(ranked);
  planner.plan_corners();
  planner.plan_edges();
  std::vector<TileHandover> out;
  for (std::size_t t = 0; t < set.tiles.size(); ++t) out.push_back(planner.plan_tile(t, ranked));
  return out;
}

}  // namespace kdm::gen
