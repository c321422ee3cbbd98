// Smooth queries past a tile set's top level: the hand-over between depths (descent.h; docs/design.md
// §3, "Unbounded zoom", states the rules this file follows).
//
// Every choice about a point is made from canonical quantities (its tile path, its rank, the density at
// its stable position or at its sub-point's), so partitions of a region stay exact; and a tile and its
// subtile make the one choice they share, whether a sub-point q is the subtile's, with the same
// expression: ρ(x_q) · area[d + 1] > K_h, x_q computed as the subtile computes its own points.
#include "descent.h"

#include "glide_count.h"
#include "read_ahead.h"
#include "subtile_loops.h"

#include <algorithm>
#include <cmath>

namespace kdm::detail {

DescentQuery::DescentQuery(const Tileset& tileset, const QueryParams& q, const ImageSampler& s)
    : set(&tileset.data()),
      tables(&TilesetInternals::tables(tileset)),
      keyframes(keyframe_table(tileset)),
      params(&q),
      sampler(&s) {
  const double m = tables->subtiles;
  side[0] = q.tile_size, area[0] = q.tile_size * q.tile_size * q.scale;
  for (std::uint32_t d = 1; d <= kMaxQueryDepth; ++d)
    side[d] = side[d - 1] / m, area[d] = area[d - 1] / (m * m);
  // Positions past depth 0 are summed relative to the origin's tile, so their precision follows their
  // distance from the origin, not from the world's.
  const double ox = std::floor(q.origin_x / q.tile_size), oy = std::floor(q.origin_y / q.tile_size);
  if (std::fabs(ox) < 9e15 && std::fabs(oy) < 9e15) {
    origin_tile_x = static_cast<std::int64_t>(ox), origin_tile_y = static_cast<std::int64_t>(oy);
    origin_frac_x = std::fma(-ox, q.tile_size, q.origin_x),
    origin_frac_y = std::fma(-oy, q.tile_size, q.origin_y);
  } else {
    origin_frac_x = q.origin_x, origin_frac_y = q.origin_y;
  }
  reach = tables->descent_reach;
  top = set->keyframe_nominal.back(), kh = set->keyframe_nominal[tables->handover_keyframe];
  appearing_end = set->appearing_end();
}

double DescentQuery::density_at(double x, double y) const {
  const QueryDensity& d = params->density;
  switch (d.kind) {
    case QueryDensity::Kind::kConstant:
      return density_or_zero(d.constant);
    case QueryDensity::Kind::kImage:
      return sampler->at(x, y);
    case QueryDensity::Kind::kCallback:
      break;
  }
  return callback_value(d, x, y);
}

void DescentQuery::density_bounds(double x0, double y0, double x1, double y1, double& lo, double& hi) const {
  detail::density_bounds(params->density, x0, y0, x1, y1, lo, hi);
}

namespace {

constexpr std::uint32_t kDone = kDescentDone;
using Node = DescentNode;

/// One depth-0 tile's descent: a stack of the tiles from it down to the one being emitted.
class Descent {
 public:
  Descent(const DescentQuery& q, QueryPoint* out, std::size_t capacity, std::size_t& written,
          std::uint64_t& budget, ReadAhead* ahead)
      : q_(q),
        set_(*q.set),
        t_(*q.tables),
        m_(t_.subtiles),
        out_(out),
        capacity_(capacity),
        n_(written),
        budget_(budget),
        ahead_(ahead),
        together_(q.params->glide_together && q.params->density.kind != QueryDensity::Kind::kConstant) {}

  bool run(std::int64_t tx, std::int64_t ty, std::size_t index, DescentPlace& at) {
    Node& root = stack_[0];
    root.type = index, root.gx = tx, root.gy = ty;
    root.wx = double(tx) * q_.side[0], root.wy = double(ty) * q_.side[0];
    root.rx = double(tx - q_.origin_tile_x) * q_.side[0] - q_.origin_frac_x;
    root.ry = double(ty - q_.origin_tile_y) * q_.side[0] - q_.origin_frac_y;
    q_.density_bounds(root.wx, root.wy, root.wx + q_.side[0], root.wy + q_.side[0], root.rho_min,
                      root.rho_max);
    for (std::uint32_t k = 0; k < at.depth; ++k) {  // back down the path a full buffer stopped on
      const auto j = static_cast<std::uint32_t>(at.path >> (16 * k) & 0xFFFF);
      stack_[k].points_done = true, stack_[k].next_child = j + 1;
      stack_[k + 1] = child(stack_[k], j);
    }
    int top = static_cast<int>(at.depth);
    std::uint32_t seq = at.rank;
    for (;;) {
      Node& n = stack_[top];
      if (!n.points_done) {
        const std::uint32_t stopped = emit(top, seq);
        if (stopped != kDone) {
          at = DescentPlace{std::uint32_t(top), 0, stopped};
          for (int k = 0; k < top; ++k) at.path |= std::uint64_t(stack_[k].next_child - 1) << (16 * k);
          return false;
        }
        n.points_done = true, seq = 0;
      }
      bool descended = false;
      if (descends(n))
        while (!descended && n.next_child < m_ * m_) {
          const Node c = child(n, n.next_child++);
          if (wanted(c)) stack_[++top] = c, descended = true;
        }
      if (descended) continue;
      if (top == 0) return true;
      --top;
    }
  }

 private:
  /// Whether a tile's subtiles can emit anything: some sub-point's expected count can exceed K_h.
  bool descends(const Node& n) const {
    return n.depth < kMaxQueryDepth && n.rho_max * q_.area[n.depth + 1] > q_.kh;
  }
  /// Whether the tile's points can glide past its top keyframe (it has a hand-over there).
  bool hands_over(const Node& n) const { return n.depth < kMaxQueryDepth; }

  Node child(const Node& p, std::uint32_t j) const {
    Node c;
    const std::uint32_t cx = j % m_, cy = j / m_, d = p.depth + 1;
    c.type = t_.child_type[p.type * m_ * m_ + j], c.depth = d;
    c.gx = p.gx * m_ + cx, c.gy = p.gy * m_ + cy;
    c.wx = double(c.gx) * q_.side[d], c.wy = double(c.gy) * q_.side[d];
    c.rx = p.rx + double(cx) * q_.side[d], c.ry = p.ry + double(cy) * q_.side[d];
    q_.density_bounds(c.wx, c.wy, c.wx + q_.side[d], c.wy + q_.side[d], c.rho_min, c.rho_max);
    return c;
  }

  /// Whether a subtile can emit a point into the region: it (with its farthest glide) meets the region
  /// and some of its points can be emitted (every one needs an expected count above K_h).
  bool wanted(const Node& c) const {
    const QueryParams& p = *q_.params;
    const double s = q_.side[c.depth], r = q_.reach * s;
    return c.wx - r < p.x1 && c.wx + s + r > p.x0 && c.wy - r < p.y1 && c.wy + s + r > p.y0 &&
           c.rho_max * q_.area[c.depth] > q_.kh;
  }

  /// A sub-point of tile `n`: its subtile's coordinates and type, its stable position and the expected
  /// count of its subtile there.
  struct SubPoint {
    std::uint32_t cx, cy, rank, depth;
    std::size_t type;
    double x, y, expected;
  };
  SubPoint sub_point(const Node& n, std::uint32_t cx, std::uint32_t cy, std::uint32_t rank) {
    const std::uint32_t d = n.depth + 1;
    SubPoint s{cx, cy, rank, d, t_.child_type[n.type * m_ * m_ + cy * m_ + cx], 0, 0, 0};
    const TilePoint& p = set_.tiles[s.type].points[rank];
    // As the subtile computes its own points' positions (run, emit): the same bits.
    const double wx = double(n.gx * m_ + cx) * q_.side[d], wy = double(n.gy * m_ + cy) * q_.side[d];
    s.x = wx + p.unit_x() * q_.side[d], s.y = wy + p.unit_y() * q_.side[d];
    s.expected = read(s.x, s.y) * q_.area[d];
    return s;
  }
  /// Where sub-point s lies when its subtile's count at it is `count` (at least K_h), in its parent's unit
  /// coordinates: as the subtile places it once it owns it (gliding together too, as visit does).
  void glided(const SubPoint& s, double count, double& ux, double& uy) {
    const TilePoint& p = set_.tiles[s.type].points[s.rank];
    const std::int8_t* glide = set_.tiles[s.type].glide.data();
    const std::uint32_t* start = t_.glide_start[s.type].data();
    const GlideBracket g(q_.keyframes, placing_count(std::max(count, q_.kh), s.x, s.y, s.depth));
    const std::int8_t *o0 = glide + 2 * (std::size_t(start[g.g0]) + s.rank),
                      *o1 = glide + 2 * (std::size_t(start[g.g1]) + s.rank);
    const double dx = double(o0[0]) * g.w0 + double(o1[0]) * g.w1,
                 dy = double(o0[1]) * g.w0 + double(o1[1]) * g.w1;
    ux = (s.cx + p.unit_x() + dx * (1.0 / 65536.0)) / m_,
    uy = (s.cy + p.unit_y() + dy * (1.0 / 65536.0)) / m_;
  }
  /// The count a point of expected count `count` at stable world position (x, y) in a tile at depth `depth`
  /// glides by: its own, or with a varying density and glide_together, glide_count.h's.
  double placing_count(double count, double x, double y, std::uint32_t depth) {
    if (!together_) return count;
    return glide_count(count, x, y, q_.side[depth], q_.area[depth],
                       [&](double u, double v) { return read(u, v); });
  }
  /// Where sub-point s lies at its subtile's keyframe h, in its parent's unit coordinates.
  void keyframe_one(const SubPoint& s, double& ux, double& uy) const {
    const TilePoint& p = set_.tiles[s.type].points[s.rank];
    const std::int8_t* o = set_.tiles[s.type].glide.data() +
                           2 * (std::size_t(t_.glide_start[s.type][t_.handover_keyframe]) + s.rank);
    const double unit = t_.glide_scale[t_.handover_keyframe] * (1.0 / 65536.0);
    ux = (s.cx + p.unit_x() + o[0] * unit) / m_, uy = (s.cy + p.unit_y() + o[1] * unit) / m_;
  }

  /// Whose a point is and the count that places it. Rank `rank` of stack_[k], with `expected` the tile's
  /// count at its stable position: a rank the tile inherits (one of its parent's sub-points) is its own
  /// once taken over: past K_h there and, unless it appears on its own, its parent's point gliding onto
  /// it its parent's own and past the end of its hand-over (m² K_h). Such a point is placed by the smaller
  /// of its count and its parent point's over m², so that it stands at its keyframe-h position when taken
  /// over, however unequal the two counts; every count is proportional to the scale, so no point ever
  /// jumps. Other ranks are the tile's own, placed by their count (whether it is emitted is the caller's).
  struct Share {
    bool own;
    double count;
  };
  Share share(int k, std::uint32_t rank, double expected) {
    if (k == 0 || rank >= t_.points_at_keyframe[stack_[k].type][t_.handover_keyframe])
      return {true, expected};
    const Node& p = stack_[k - 1];
    const std::uint32_t from =
        t_.inherited[p.type][t_.inherited_start[p.type * (m_ * m_ + 1) + p.next_child - 1] + rank];
    if (QueryTables::appearing(from)) return {expected > q_.kh, expected};
    // The parent's count at its point, as emit computes it there; a constant density's needs no position
    // (the same value, without a load from the parent's points at a rank far from the last one).
    double here;
    if (q_.params->density.kind == QueryDensity::Kind::kConstant) {
      here = density_or_zero(q_.params->density.constant) * q_.area[p.depth];
    } else {
      const TilePoint& point = set_.tiles[p.type].points[from];
      const double side = q_.side[p.depth];
      here = read(p.wx + point.unit_x() * side, p.wy + point.unit_y() * side) * q_.area[p.depth];
    }
    const Share parent = share(k - 1, from, here);
    // Past the tile's latest hand-over end every point has ended its own: no lookup of it.
    const bool ended =
        parent.count > t_.handover_end_max[p.type] || parent.count > t_.handover_end[p.type][from];
    return {parent.own && expected > q_.kh && ended, std::min(expected, parent.count / (double(m_) * m_))};
  }

  /// The id of rank `rank` of stack_[k]: a sub-point a point glided onto keeps that point's id.
  PointId id_of(int k, std::uint32_t rank) const {
    while (k > 0 && rank < t_.points_at_keyframe[stack_[k].type][t_.handover_keyframe]) {
      const Node& p = stack_[k - 1];
      const std::uint32_t from =
          t_.inherited[p.type][t_.inherited_start[p.type * (m_ * m_ + 1) + p.next_child - 1] + rank];
      if (QueryTables::appearing(from)) break;
      rank = from, --k;
    }
    return PointId{stack_[k].gx, stack_[k].gy, rank, std::uint32_t(k)};
  }

  /// The density at (x, y). With a batch callback, read ahead when it can be (ReadAhead); in a dry run a
  /// value not yet read is asked for and the candidate stops there: its later reads give 0 unasked.
  double read(double x, double y) { return ahead_ ? read_through_ahead(x, y) : q_.density_at(x, y); }
  [[gnu::noinline]] double read_through_ahead(double x, double y) {
    double value;
    if (ahead_->find(x, y, value)) return value;
    if (!dry_) return q_.density_at(x, y);
    if (!missed_ && (missed_ = true, !ahead_->want(x, y)))
      overflow_item_ = std::min(overflow_item_, dry_item_);
    return 0;
  }

  /// Writes a point at world (x, y), (rx, ry) from the origin, unless it lies outside the region or where
  /// the density is 0; false when the buffer is full.
  bool write(double x, double y, double rx, double ry, const PointId& id) {
    const QueryParams& p = *q_.params;
    if (x < p.x0 || x >= p.x1 || y < p.y0 || y >= p.y1) return true;
    if (p.density.kind != QueryDensity::Kind::kConstant && !(read(x, y) > 0)) return true;
    if (dry_) return true;
    if (n_ == capacity_) return false;
    out_[n_++] = QueryPoint{rx, ry, id};
    return true;
  }
  /// The same for a position in tile n's unit coordinates.
  bool write_unit(const Node& n, double ux, double uy, const PointId& id) {
    const double s = q_.side[n.depth];
    const double x = n.wx + ux * s, y = n.wy + uy * s;
    return n.depth == 0 ? write(x, y, x - q_.params->origin_x, y - q_.params->origin_y, id)
                        : write(x, y, n.rx + ux * s, n.ry + uy * s, id);
  }

  /// What emit's loop over a tile's ranks uses, fixed for the tile, and the window a culled tile's ranks
  /// must lie in (it widens as the ranks pass keyframes).
  struct RankLoop {
    const Node* n;
    const Tile* tile;
    const float* thresholds;
    const std::uint32_t* start;
    const std::uint32_t* present;
    double side, area, constant_count;
    std::uint32_t seq, inherited;
    bool constant, culled;
    GlideBracket constant_bracket;
    SubtileCull around;
    std::uint32_t segment = 0;
    double lo_x = 0, hi_x = 0, lo_y = 0, hi_y = 0;
  };

  /// Rank r of stack_[k], in emit's loop over the ranks that may hand over or be inherited: written if
  /// emitted; false when the buffer is full.
  [[gnu::always_inline]] bool visit(int k, RankLoop& L, std::uint32_t r) {
    const Node& n = *L.n;
    const Tile& tile = *L.tile;
    const double side = L.side, area = L.area;
    const std::uint32_t inherited = L.inherited, top_keyframe = q_.keyframes.n - 1;
    const TilePoint& p = tile.points[r];
    if (L.culled) {
      if (r == L.seq || (L.segment < q_.keyframes.n && L.present[L.segment] <= r)) {
        while (L.segment < q_.keyframes.n && L.present[L.segment] <= r) ++L.segment;
        const double rank_reach = std::max(t_.glide_reach_from[L.segment ? L.segment - 1 : 0],
                                           hands_over(n) ? t_.handover_reach : 0);
        L.lo_x = L.around.x0 - rank_reach * 65536.0, L.hi_x = L.around.x1 + rank_reach * 65536.0;
        L.lo_y = L.around.y0 - rank_reach * 65536.0, L.hi_y = L.around.y1 + rank_reach * 65536.0;
      }
      if (!(p.x + 0.5 >= L.lo_x && p.x + 0.5 < L.hi_x && p.y + 0.5 >= L.lo_y && p.y + 0.5 < L.hi_y))
        return true;
    }
    const double xs = n.wx + p.unit_x() * side, ys = n.wy + p.unit_y() * side;
    const double count_here = L.constant ? L.constant_count : read(xs, ys) * area;
    const Share mine = r < inherited ? share(k, r, count_here) : Share{true, count_here};
    if (r < inherited ? !mine.own : !TilesetShape::emits(L.thresholds[r], mine.count)) return true;
    const double expected = mine.count;
    if (hands_over(n) && expected > q_.top) {
      const std::uint32_t v = tile.handover[r], code = v % 25;
      const SubPoint s = sub_point(n, TilesetShape::subtile_of(p.x, m_) + code % 5 - 2,
                                   TilesetShape::subtile_of(p.y, m_) + code / 5 - 2, v / 25);
      const double end = t_.handover_end[n.type][r];
      if (s.expected > q_.kh && expected > end) return true;  // its subtile took it over
      // On the straight line from its top-keyframe position to where its subtile will place the sub-point,
      // a fraction f of the way, linear in the scale: 0 where its own count a · N_top reaches N_top, 1
      // where both its own count passes the hand-over's end and the sub-point's b · K_h passes K_h (a and
      // b are proportional to the scale), which is where its subtile takes it over and places it by the
      // smaller of b · K_h and its count over m² (share).
      const double a = expected / q_.top, b = s.expected / q_.kh;
      const double f = (a - 1) / (std::max(b > 0 ? a / b : HUGE_VAL, end / q_.top) - 1);
      const std::int8_t* o = tile.glide.data() + 2 * (std::size_t(L.start[top_keyframe]) + r);
      const double unit = t_.glide_scale[top_keyframe] * (1.0 / 65536.0);
      const double ax = p.unit_x() + o[0] * unit, ay = p.unit_y() + o[1] * unit;
      double bx, by;
      glided(s, std::min(s.expected, expected / (double(m_) * m_)), bx, by);
      return write_unit(n, ax + f * (bx - ax), ay + f * (by - ay), id_of(k, r));
    }
    // A varying density's points glide as query.cpp's do, at every depth (glide_together: glide_count.h);
    // a handed-over point's sub-point is placed by the same count (glided), so it does not jump.
    const double placed = L.constant ? expected : placing_count(expected, xs, ys, n.depth);
    const GlideBracket g =
        L.constant && r >= inherited ? L.constant_bracket : GlideBracket(q_.keyframes, placed);
    const std::int8_t* o0 = tile.glide.data() + 2 * (std::size_t(L.start[g.g0]) + r);
    const std::int8_t* o1 = tile.glide.data() + 2 * (std::size_t(L.start[g.g1]) + r);
    const double dx = double(o0[0]) * g.w0 + double(o1[0]) * g.w1,
                 dy = double(o0[1]) * g.w0 + double(o1[1]) * g.w1;
    if (n.depth == 0) {  // the expression of query.cpp's emit_tile, bit for bit
      const double unit = side * (1.0 / 65536.0), x = xs + dx * unit, y = ys + dy * unit;
      return write(x, y, x - q_.params->origin_x, y - q_.params->origin_y, id_of(k, r));
    }
    return write_unit(n, p.unit_x() + dx * (1.0 / 65536.0), p.unit_y() + dy * (1.0 / 65536.0), id_of(k, r));
  }

  /// Which point of its parent each rank of stack_[k] (k > 0) is (QueryTables::inherited), by rank.
  const std::uint32_t* inherited_row(int k) const {
    const Node& p = stack_[k - 1];
    return t_.inherited[p.type].data() + t_.inherited_start[p.type * (m_ * m_ + 1) + p.next_child - 1];
  }
  static constexpr std::uint32_t kPrefetch = 16;
  /// Starts loading what share reads of point `from` of the parent of stack_[k].
  void prefetch_parent(int k, std::uint32_t from) const {
    if (QueryTables::appearing(from)) return;
    const std::size_t type = stack_[k - 1].type;
    __builtin_prefetch(set_.tiles[type].points.data() + from);
    __builtin_prefetch(t_.handover_end[type].data() + from);
  }
  /// The count a constant density gives the parent of stack_[k] (k > 0), as share computes it there.
  double parent_count(int k) const {
    return density_or_zero(q_.params->density.constant) * q_.area[stack_[k - 1].depth];
  }
  /// Whether a constant density at `count` in subtile stack_[k] (k > 0) makes each of its inherited ranks
  /// its own: its parent's count is past the end of every point's hand-over, and its own past K_h.
  bool handed_over_whole(int k, double count) const {
    return k > 0 && parent_count(k) > t_.handover_end_max[stack_[k - 1].type] && count > q_.kh;
  }
  /// A constant density's inherited ranks of subtile stack_[k] from L.seq to `end`, where
  /// handed_over_whole: each is placed by one of two counts known here (share's, without its lookups of
  /// the parent's points and ends) and keeps its parent point's id. Ranks inherited through more than
  /// one depth go through visit. kDone, or the rank where the buffer or the budget ran out.
  std::uint32_t emit_inherited(int k, const RankLoop& L, std::uint32_t end) {
    const Node& n = *L.n;
    const Node& p = stack_[k - 1];
    const double here = parent_count(k);
    const std::uint32_t* from_of = inherited_row(k);
    const std::uint32_t chained = p.depth > 0 ? t_.points_at_keyframe[p.type][t_.handover_keyframe] : 0;
    const GlideBracket taken(q_.keyframes, std::min(L.constant_count, here / (double(m_) * m_)));
    const Tile& tile = *L.tile;
    RankLoop general = L;
    general.culled = false;  // visit is called out of order here; culling only saves work
    for (std::uint32_t r = L.seq; r < end; ++r) {
      if (budget_ == 0) return r;
      --budget_;
      const std::uint32_t from = from_of[r];
      const bool appearing = QueryTables::appearing(from);
      if (!appearing && from < chained) {
        if (!visit(k, general, r)) return r;
        continue;
      }
      const GlideBracket& g = appearing ? L.constant_bracket : taken;
      const std::int8_t* o0 = tile.glide.data() + 2 * (std::size_t(L.start[g.g0]) + r);
      const std::int8_t* o1 = tile.glide.data() + 2 * (std::size_t(L.start[g.g1]) + r);
      const double dx = double(o0[0]) * g.w0 + double(o1[0]) * g.w1,
                   dy = double(o0[1]) * g.w0 + double(o1[1]) * g.w1;
      const PointId id = appearing ? PointId{n.gx, n.gy, r, n.depth} : PointId{p.gx, p.gy, from, p.depth};
      const TilePoint& point = tile.points[r];
      if (!write_unit(n, point.unit_x() + dx * (1.0 / 65536.0), point.unit_y() + dy * (1.0 / 65536.0), id))
        return r;
    }
    return kDone;
  }

  /// Reads ahead the values that items [from, …) of a loop will read, by dry runs of `pass(from, to)`,
  /// which visits them (ReadAhead), setting dry_item_ to the item it is at; `reads` bounds the values an
  /// item reads. Returns the end of the items read for. Most items read far fewer (culled, not emitted,
  /// taken over): a block that left the table less than half full makes the next one twice as long, and
  /// one that fills it ends before the first item the table refused, and makes the next half as long.
  template <class Pass>
  std::uint32_t read_ahead(std::uint32_t from, std::uint32_t end, std::uint32_t reads, Pass pass) {
    const std::uint32_t block =
        std::max<std::uint32_t>(1, std::uint32_t(ReadAhead::kCapacity) * ahead_widen_ / reads);
    std::uint32_t to = end - from > block ? from + block : end;
    const std::uint32_t asked = to;
    ahead_->clear();
    dry_ = true;
    do {
      overflow_item_ = to;
      pass(from, to);
      ahead_->read();
      if (overflow_item_ < to) to = std::max(overflow_item_, from + 1);
    } while (ahead_->take_added() > 0);
    dry_ = false;
    if (to < asked)
      ahead_widen_ = std::max<std::uint32_t>(1, ahead_widen_ / 2);
    else if (2 * ahead_->size() < ReadAhead::kCapacity && to - from == block && ahead_widen_ < 64)
      ahead_widen_ *= 2;
    return to;
  }

  /// Emits stack_[k]'s points from `seq` on (ranks, then its appearing sub-points at index point count
  /// + a): kDone, or where the buffer or the budget ran out.
  std::uint32_t emit(int k, std::uint32_t seq) {
    const Node& n = stack_[k];
    const Tile& tile = set_.tiles[n.type];
    const float* thresholds = t_.thresholds[n.type].data();
    const auto count = static_cast<std::uint32_t>(tile.points.size());
    const double side = q_.side[n.depth], area = q_.area[n.depth], bound = n.rho_max * area;
    std::uint32_t candidates = static_cast<std::uint32_t>(
        std::lower_bound(thresholds, thresholds + count, bound,
                         [](float t, double l) { return TilesetShape::emits(t, l); }) -
        thresholds);
    // A subtile's first points come from its parent, which emits them until the subtile takes them over.
    const std::uint32_t inherited = n.depth > 0 ? t_.points_at_keyframe[n.type][t_.handover_keyframe] : 0;
    // Every point has a sub-point: where the density's lower bound puts the tile's own points past the end
    // of their hand-over and every sub-point past K_h, its subtiles hold all but the inherited ones.
    const bool handed_over = n.depth < kMaxQueryDepth && n.rho_min * area > t_.handover_end_max[n.type] &&
                             n.rho_min * q_.area[n.depth + 1] > q_.kh;
    if (handed_over) candidates = std::min(candidates, inherited);
    const std::uint32_t* start = t_.glide_start[n.type].data();
    // A constant density: one count and one bracket for the tile's own points (the same values the
    // per-point expressions give).
    const bool constant = q_.params->density.kind == QueryDensity::Kind::kConstant;
    const double constant_count = constant ? density_or_zero(q_.params->density.constant) * area : 0;
    const GlideBracket constant_bracket =
        constant ? GlideBracket(q_.keyframes, constant_count) : GlideBracket();
    // A subtile whose own points neither hand over nor meet a varying density: its own ranks are emitted
    // by a loop of their own (emit_own), the same expressions without the other cases' tests, and without
    // the region's where the subtile lies inside it.
    const QueryParams& params = *q_.params;
    const double reach = std::max(t_.glide_reach[constant_bracket.g0], t_.glide_reach[constant_bracket.g1]);
    const double margin = (reach + 1e-9) * side;  // the farthest those points glide, and a hair for rounding
    const bool direct = constant && n.depth > 0 && !(hands_over(n) && constant_count > q_.top);
    // The same for a varying density whose bound keeps every own point below N_top (emit_varying).
    const bool varying = !constant && n.depth > 0 && !(hands_over(n) && bound > q_.top);
    const double margin_all = (t_.glide_reach_from[0] + 1e-9) * side;  // any keyframe's farthest glide
    const bool inside = direct ? n.wx - margin >= params.x0 && n.wx + side + margin < params.x1 &&
                                     n.wy - margin >= params.y0 && n.wy + side + margin < params.y1
                               : n.wx - margin_all >= params.x0 && n.wx + side + margin_all < params.x1 &&
                                     n.wy - margin_all >= params.y0 && n.wy + side + margin_all < params.y1;
    const std::uint32_t general_end = direct || varying ? std::min(candidates, inherited) : candidates;
    // Outside the region widened by the farthest a point glides (from the keyframe before the one it is
    // present at: it is emitted only past that count) or hands over, a point is passed over before its
    // density is looked up: an ancestor of a small deep region holds thousands.
    const double far = (q_.reach + 1e-9) * side;
    const bool culled = general_end > seq && !(n.wx - far >= params.x0 && n.wx + side + far < params.x1 &&
                                               n.wy - far >= params.y0 && n.wy + side + far < params.y1);
    const SubtileCull around = culled ? subtile_cull(q_, n) : SubtileCull{};
    RankLoop loop{&n,       &tile,  thresholds,       start, t_.points_at_keyframe[n.type].data(),
                  side,     area,   constant_count,   seq,   inherited,
                  constant, culled, constant_bracket, around};
    std::uint32_t first = seq;  // the first rank left to the general loop
    if (direct && seq < general_end && handed_over_whole(k, constant_count)) {
      const std::uint32_t stopped = emit_inherited(k, loop, general_end);
      if (stopped != kDone) return stopped;
      first = general_end;
    }
    std::uint32_t read_to = first;  // the ranks whose values are read ahead (a batch callback's)
    // An inherited rank reads its parent point's position and hand-over end, at ranks of the parent far
    // apart: fetched kPrefetch ranks ahead, so the loop does not wait for each.
    const std::uint32_t* from_of = k > 0 ? inherited_row(k) : nullptr;
    const std::uint32_t prefetch_end = k > 0 ? std::min(general_end, inherited) : 0;
    for (std::uint32_t r = first; r < general_end; ++r) {
      if (budget_ == 0) return r;
      --budget_;
      if (r + kPrefetch < prefetch_end) prefetch_parent(k, from_of[r + kPrefetch]);
      // A rank reads at most its count, its k ancestors', its sub-point's, its glide count's probes and its
      // glided position's.
      if (ahead_ && r == read_to)
        read_to = read_ahead(r, general_end,
                             std::uint32_t(k) + 3 + (q_.params->glide_together ? GlideLattice::kCorners : 0),
                             [&](std::uint32_t from, std::uint32_t to) {
                               RankLoop dry = loop;
                               for (std::uint32_t i = from; i < to; ++i)
                                 dry_item_ = i, missed_ = false, visit(k, dry, i);
                             });
      if (!visit(k, loop, r)) return r;
    }
    if ((direct || varying) && candidates > inherited) {
      const std::uint32_t from = std::max(seq, inherited);
      DescentSink sink{out_, capacity_, n_, budget_};
      std::uint32_t stopped;
      if (inside) {
        stopped = direct ? emit_own<false, false>(q_, n, sink, from, candidates, constant_bracket, reach, {})
                         : emit_varying_any<false, false>(q_, n, sink, from, candidates, {});
      } else {
        const SubtileCull c = subtile_cull(q_, n);
        if (direct)
          stopped = c.listed
                        ? emit_own<true, true>(q_, n, sink, from, candidates, constant_bracket, reach, c)
                        : emit_own<true, false>(q_, n, sink, from, candidates, constant_bracket, reach, c);
        else
          stopped = c.listed ? emit_varying_any<true, true>(q_, n, sink, from, candidates, c)
                             : emit_varying_any<true, false>(q_, n, sink, from, candidates, c);
      }
      if (stopped != kDone) return stopped;
    }
    // The sub-points no point glides onto appear at evenly spread thresholds over (N_top, m² K_h].
    if (!hands_over(n) || !(bound > q_.top) || handed_over) return kDone;
    const auto listed = static_cast<std::uint32_t>(tile.appearing.size());
    const auto appear = [&](std::uint32_t a) {  // false when the buffer is full
      const std::uint32_t w = tile.appearing[a], j = w >> 16;
      const SubPoint s = sub_point(n, j % m_, j / m_, w & 0xFFFF);
      if (s.expected > q_.kh) return true;  // its subtile took it over (share: it appears on its own)
      const double threshold = q_.top + (a + 0.5) / listed * (q_.appearing_end - q_.top);
      if (!(read(s.x, s.y) * area > threshold)) return true;
      // At its keyframe h, where its subtile places it once it owns it: gliding together, by the count
      // that lifts it there (glided), so that it does not jump when taken over.
      double ux, uy;
      if (together_)
        glided(s, q_.kh, ux, uy);
      else
        keyframe_one(s, ux, uy);
      return write_unit(n, ux, uy, PointId{n.gx * m_ + s.cx, n.gy * m_ + s.cy, s.rank, n.depth + 1});
    };
    read_to = seq > count ? seq - count : 0;
    for (std::uint32_t a = read_to; a < listed; ++a) {
      if (budget_ == 0) return count + a;
      --budget_;
      if (ahead_ && a == read_to)  // two values, at the sub-point and where it appears, and its glide count's
        read_to = read_ahead(a, listed, 2 + (together_ ? GlideLattice::kCorners : 0),
                             [&](std::uint32_t from, std::uint32_t to) {
                               for (std::uint32_t i = from; i < to; ++i)
                                 dry_item_ = i, missed_ = false, appear(i);
                             });
      if (!appear(a)) return count + a;
    }
    return kDone;
  }

  const DescentQuery& q_;
  const TilesetData& set_;
  const QueryTables& t_;
  const std::uint32_t m_;
  QueryPoint* out_;
  std::size_t capacity_;
  std::size_t& n_;
  std::uint64_t& budget_;
  ReadAhead* const ahead_;  // set for a batch callback
  const bool together_;     // points glide together (glide_count.h)
  bool dry_ = false;        // a run that only finds the values to read ahead
  bool missed_ = false;     // the candidate a dry run is at stopped at a value not yet read
  std::uint32_t dry_item_ = 0, overflow_item_ = 0;  // the item a dry run is at; the first the table refused
  std::uint32_t ahead_widen_ = 1;  // a block's items, in units of the table's room over an item's reads
  Node stack_[kMaxQueryDepth + 1];
};

}  // namespace

bool emit_descending(const DescentQuery& q, std::int64_t tx, std::int64_t ty, std::size_t index,
                     QueryPoint* out, std::size_t capacity, std::size_t& written, std::uint64_t& budget,
                     DescentPlace& at) {
  const QueryDensity& d = q.params->density;
  if (d.kind == QueryDensity::Kind::kCallback && d.batch_callback) {
    ReadAhead ahead(d);
    return Descent(q, out, capacity, written, budget, &ahead).run(tx, ty, index, at);
  }
  return Descent(q, out, capacity, written, budget, nullptr).run(tx, ty, index, at);
}

}  // namespace kdm::detail
