// The hand-over between depths; see handover.h.
#include "bake/handover.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "bake/glider_field.h"
#include "bake/min_cost_assignment.h"
#include "bake/progressive_order.h"
#include "kdm/generator/sampler.h"
#include "kdm/runtime/check.h"

namespace kdm::gen {
namespace {

// Distances in d_hex at N_top. Two glides closer than kGlideSeparation are a close pair; a point appears
// once every glide is kClearance from it, where the order allows.
constexpr double kGlideSeparation = 0.35;
constexpr double kClearance = 0.5;
// Square-grid spacings 1/√N_top. Glides past kLongGlide cost kLongGlideWeight times more per spacing²
// beyond it: a long glide is slow (TilesetShape::handover_end) and crosses settled points, so its
// neighbours are better moved a little each. Swaps that part two glides keep both within kMaxGlide.
constexpr double kLongGlide = 0.6;
constexpr double kLongGlideWeight = 10;
constexpr double kMaxGlide = 1.2;
// Passes of untangle over the tiles (each sees its neighbours' moves of the pass before).
constexpr int kPasses = 2;
// What untangle leaves closer than kRepairBelow (d_hex at N_top), mostly a long glide coming back into
// its tile past a neighbour tile's glide, repair moves apart as far as a swap within kMaxRepairGlide
// spacings allows, in kRepairPasses passes.
constexpr double kRepairBelow = 0.2;
constexpr double kMaxRepairGlide = 1.5;
constexpr int kRepairPasses = 3;

/// Positions (tile units, x y pairs) of ranks [0, n) of `tile` at keyframe g, as the file holds them.
std::vector<double> keyframe_positions(const TilesetData& set, const Tile& tile, std::size_t g,
                                       std::uint32_t n) {
  std::size_t at = 0;
  for (std::size_t h = 0; h < g; ++h) at += 2 * set.offsets_at_keyframe(tile, h);
  KDM_CHECK(n <= set.offsets_at_keyframe(tile, g));
  const double unit = set.glide_unit(g);
  std::vector<double> xy(2 * std::size_t(n));
  for (std::uint32_t r = 0; r < n; ++r) {
    xy[2 * r] = tile.points[r].unit_x() + tile.glide[at + 2 * r] * unit;
    xy[2 * r + 1] = tile.points[r].unit_y() + tile.glide[at + 2 * r + 1] * unit;
  }
  return xy;
}

/// The cost of a glide of squared length d2 (tile units), with long glides (past `long_glide`) dearer.
double glide_cost(double d2, double long_glide) {
  const double over = std::max(0.0, std::sqrt(d2) - long_glide);
  return d2 + kLongGlideWeight * over * over;
}

/// Least total glide_cost from each row to a distinct column (x y pairs), each row's candidates the
/// columns within `reach`, widened until every row finds one.
std::vector<std::uint32_t> match(const std::vector<double>& rows, const std::vector<double>& columns,
                                 double reach, double long_glide, std::size_t t) {
  const auto n_rows = std::uint32_t(rows.size() / 2), n_columns = std::uint32_t(columns.size() / 2);
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double v : columns) lo = std::min(lo, v), hi = std::max(hi, v);
  std::vector<std::uint32_t> row_column;
  for (int attempt = 0; attempt < 8; ++attempt, reach *= 1.5) {
    const auto cells = std::max<std::int64_t>(1, std::int64_t(std::ceil((hi - lo) / reach)));
    const auto cell_of = [&](double v) {
      return std::clamp<std::int64_t>(std::int64_t(std::floor((v - lo) / reach)), 0, cells - 1);
    };
    std::vector<std::vector<std::uint32_t>> grid(std::size_t(cells * cells));
    for (std::uint32_t c = 0; c < n_columns; ++c)
      grid[std::size_t(cell_of(columns[2 * c + 1]) * cells + cell_of(columns[2 * c]))].push_back(c);
    std::vector<AssignmentEdge> edges;
    const double scale = 1.0 / (reach * reach);  // costs of order 1
    for (std::uint32_t r = 0; r < n_rows; ++r) {
      const std::int64_t cx = cell_of(rows[2 * r]), cy = cell_of(rows[2 * r + 1]);
      for (std::int64_t y = std::max<std::int64_t>(0, cy - 1); y <= std::min(cells - 1, cy + 1); ++y)
        for (std::int64_t x = std::max<std::int64_t>(0, cx - 1); x <= std::min(cells - 1, cx + 1); ++x)
          for (std::uint32_t c : grid[std::size_t(y * cells + x)]) {
            const double ex = columns[2 * c] - rows[2 * r], ey = columns[2 * c + 1] - rows[2 * r + 1];
            const double d2 = ex * ex + ey * ey;
            if (d2 <= reach * reach) edges.push_back({r, c, glide_cost(d2, long_glide) * scale});
          }
    }
    if (min_cost_assignment(n_rows, n_columns, edges, row_column)) return row_column;
  }
  throw std::runtime_error("hand-over: tile " + std::to_string(t) + "'s points find too few sub-points");
}

/// One tile's sub-points and which of them each of its points glides onto.
struct Matched {
  std::vector<double> start;          ///< per rank: the top keyframe's position (x y pairs, tile units)
  std::vector<double> columns;        ///< the sub-points at the hand-over keyframe (x y pairs, tile units)
  std::vector<std::uint32_t> packed;  ///< the same, packed as TileHandover's
  std::vector<std::uint32_t> column;  ///< per rank: its sub-point
};

Matched match_tile(const TilesetData& set, std::size_t t) {
  const Subdivision sub = set.subdivision();
  const std::uint32_t m = sub.m;
  const std::size_t h = set.handover_keyframe();
  const double top = set.level_nominal.back();
  const Tile& tile = set.tiles[t];
  Matched out;
  out.start =
      keyframe_positions(set, tile, set.keyframe_nominal.size() - 1, std::uint32_t(tile.points.size()));
  for (std::uint32_t k = 0; k < m; ++k)
    for (std::uint32_t i = 0; i < m; ++i) {
      const Tile& child = set.tiles[set.subtile_index(t, i, k)];
      const std::uint32_t present = set.points_at_keyframe(child, h);
      const std::vector<double> xy = keyframe_positions(set, child, h, present);
      for (std::uint32_t q = 0; q < present; ++q) {
        out.columns.insert(out.columns.end(), {(i + xy[2 * q]) / m, (k + xy[2 * q + 1]) / m});
        out.packed.push_back((k * m + i) << 16 | q);
      }
    }
  if (out.columns.size() < out.start.size()) {  // the passes that keep points apart removed too many
    const std::string k = std::to_string(set.keyframe_nominal[h]), s = std::to_string(set.handover_slack);
    // (start and columns hold x, y pairs)
    throw InvalidArgument(
        "hand-over: tile " + std::to_string(t) + " holds " + std::to_string(out.start.size() / 2) +
        " points at its top level, its " + std::to_string(m * m) + " subtiles only " +
        std::to_string(out.columns.size() / 2) + " together at the hand-over keyframe (nominally " + k +
        " points per subtile): a larger handover_slack (now " + s + ") hands them over later, holding more");
  }
  out.column = match(out.start, out.columns, 2.5 / std::sqrt(top), kLongGlide / std::sqrt(top), t);
  return out;
}

/// Rank r's glide onto column c.
Glide glide_to(const TilesetData& set, const Matched& m, std::uint32_t r, std::uint32_t c) {
  Glide g{m.start[2 * r], m.start[2 * r + 1], m.columns[2 * c], m.columns[2 * c + 1], 0};
  // As the runtime's tables (QueryTables::handover_end): the length in square-grid spacings 1/√N_top.
  g.end =
      set.handover_end(std::hypot(g.bx - g.ax, g.by - g.ay) * std::sqrt(double(set.level_nominal.back())));
  return g;
}

double length(const Glide& g) {
  return std::hypot(g.bx - g.ax, g.by - g.ay);
}

/// Tile t's points set up to swap sub-points: the glides that can pass near them (a GliderField), its
/// sub-points by cells of 2 spacings, and the rank that takes each.
class TileSwaps {
 public:
  TileSwaps(const TilesetData& set, std::vector<Matched>& matched, std::vector<std::vector<Glide>>& glides,
            std::size_t t, double distance)
      : set_(set),
        m_(matched[t]),
        own_(glides[t]),
        field_(set, glides, t, distance, set.level_nominal.back()),
        n_(static_cast<std::uint32_t>(own_.size())),
        spacing_(1 / std::sqrt(double(set.level_nominal.back()))),
        cells_(static_cast<std::int64_t>(std::ceil(1.5 / (2 * spacing_)))),
        near_(std::size_t(cells_ * cells_)),
        owner_(m_.packed.size(), n_) {
    for (std::uint32_t c = 0; c < m_.packed.size(); ++c)
      near_[std::size_t(cell_of(m_.columns[2 * c + 1]) * cells_ + cell_of(m_.columns[2 * c]))].push_back(c);
    for (std::uint32_t r = 0; r < n_; ++r) owner_[m_.column[r]] = r;
  }

  /// The tile's ranks, [0, ranks()), and rank r's glide.
  std::uint32_t ranks() const { return n_; }
  const Glide& glide(std::uint32_t r) const { return own_[r]; }
  /// The glides that can pass near the tile's, as they stand.
  const GliderField& field() const { return field_; }

  /// For each sub-point c near rank r's start but its own: visit(c, mine, other, theirs) with r's glide
  /// onto c, the rank `other` that takes c (ranks() if none) and its glide onto r's sub-point, where neither
  /// glide is longer than `longest` spacings or than the one it replaces.
  template <class Visit>
  void for_swaps(std::uint32_t r, double longest, Visit&& visit) const {
    const double max_length = longest * spacing_;
    const std::int64_t cx = cell_of(m_.start[2 * r]), cy = cell_of(m_.start[2 * r + 1]);
    for (std::int64_t y = std::max<std::int64_t>(0, cy - 1); y <= std::min(cells_ - 1, cy + 1); ++y)
      for (std::int64_t x = std::max<std::int64_t>(0, cx - 1); x <= std::min(cells_ - 1, cx + 1); ++x)
        for (std::uint32_t c : near_[std::size_t(y * cells_ + x)]) {
          if (c == m_.column[r]) continue;
          const Glide mine = glide_to(set_, m_, r, c);
          if (length(mine) > std::max(max_length, length(own_[r]))) continue;
          const std::uint32_t other = owner_[c];
          Glide theirs;
          if (other < n_) {
            theirs = glide_to(set_, m_, other, m_.column[r]);
            if (length(theirs) > std::max(max_length, length(own_[other]))) continue;
          }
          visit(c, mine, other, theirs);
        }
  }

  /// Rank r takes sub-point c with glide `mine`; c's rank, if any, takes r's with `theirs`.
  void swap(std::uint32_t r, std::uint32_t c, const Glide& mine, const Glide& theirs) {
    const std::uint32_t old = m_.column[r], other = owner_[c];
    m_.column[r] = c, owner_[c] = r, own_[r] = mine;
    field_.replace(r, mine);
    owner_[old] = other;
    if (other < n_) m_.column[other] = old, own_[other] = theirs, field_.replace(other, theirs);
  }

 private:
  std::int64_t cell_of(double v) const {
    return std::clamp<std::int64_t>(static_cast<std::int64_t>(std::floor((v + 0.25) / (2 * spacing_))), 0,
                                    cells_ - 1);
  }

  const TilesetData& set_;
  Matched& m_;
  std::vector<Glide>& own_;
  GliderField field_;
  std::uint32_t n_;
  double spacing_;
  std::int64_t cells_;
  std::vector<std::vector<std::uint32_t>> near_;
  std::vector<std::uint32_t> owner_;
};

/// The squared length a swap adds.
double added_length(const TileSwaps& swaps, std::uint32_t r, const Glide& mine, std::uint32_t other,
                    const Glide& theirs) {
  double added = length(mine) * length(mine) - length(swaps.glide(r)) * length(swaps.glide(r));
  if (other < swaps.ranks())
    added += length(theirs) * length(theirs) - length(swaps.glide(other)) * length(swaps.glide(other));
  return added;
}

/// Parts tile t's glides that come close to another (its own at another pace, or a neighbour tile's):
/// each such point swaps sub-points with a nearby point of its tile, or takes a sub-point no point has,
/// where that leaves both clear (some cannot: where a glide crosses its tile's edge, or meets a point
/// that stays).
void untangle(const TilesetData& set, std::vector<Matched>& matched, std::vector<std::vector<Glide>>& glides,
              std::size_t t) {
  const double top = set.level_nominal.back();
  TileSwaps swaps(set, matched, glides, t, kGlideSeparation * std::sqrt(2 / (std::sqrt(3.0) * top)));
  const GliderField& field = swaps.field();
  for (std::uint32_t r = 0; r < swaps.ranks(); ++r) {
    if (!field.meets(swaps.glide(r), r, r)) continue;
    // The best move: least added squared length among those that leave every glide it changes clear.
    double best = std::numeric_limits<double>::infinity();
    std::uint32_t best_column = 0;
    Glide best_r, best_other;
    swaps.for_swaps(
        r, kMaxGlide, [&](std::uint32_t c, const Glide& mine, std::uint32_t other, const Glide& theirs) {
          const double added = added_length(swaps, r, mine, other, theirs);
          if (added >= best) return;
          if (field.meets(mine, r, other < swaps.ranks() ? other : r)) return;
          if (other < swaps.ranks() && (field.meets(theirs, r, other) || field.meet(mine, theirs))) return;
          best = added, best_column = c, best_r = mine, best_other = theirs;
        });
    if (best < std::numeric_limits<double>::infinity()) swaps.swap(r, best_column, best_r, best_other);
  }
}

/// Moves apart tile t's glides that still come within kRepairBelow of another (its own or a neighbour
/// tile's): each such point takes the swap with a nearby point of its tile, or the free sub-point, that
/// leaves the glides it changes farthest from every other, where that is farther than before.
void repair(const TilesetData& set, std::vector<Matched>& matched, std::vector<std::vector<Glide>>& glides,
            std::size_t t) {
  const double d_hex = std::sqrt(2 / (std::sqrt(3.0) * set.level_nominal.back()));
  TileSwaps swaps(set, matched, glides, t, kGlideSeparation * d_hex);
  const GliderField& field = swaps.field();
  for (std::uint32_t r = 0; r < swaps.ranks(); ++r) {
    const double now = field.nearest(swaps.glide(r), r, r);
    if (now >= kRepairBelow * d_hex) continue;
    double best = now, best_added = 0;
    std::uint32_t best_column = 0;
    bool found = false;
    Glide best_r, best_other;
    swaps.for_swaps(
        r, kMaxRepairGlide,
        [&](std::uint32_t c, const Glide& mine, std::uint32_t other, const Glide& theirs) {
          double before = now, after = field.nearest(mine, r, other < swaps.ranks() ? other : r);
          if (other < swaps.ranks()) {
            before = std::min(before, field.nearest(swaps.glide(other), other, other));
            after = std::min({after, field.nearest(theirs, r, other), field.approach(mine, theirs)});
          }
          const double added = added_length(swaps, r, mine, other, theirs);
          if (after <= before || after < best || (after == best && added >= best_added)) return;
          best = after, best_added = added, best_column = c, best_r = mine, best_other = theirs, found = true;
        });
    if (found) swaps.swap(r, best_column, best_r, best_other);
  }
}

/// The order tile t's leftover sub-points appear in: a void-and-cluster order among the taken ones, then
/// each slot (thresholds evenly over (N_top, m² K_h]) takes the first in that order whose place every
/// glide that can pass near it has cleared.
std::vector<std::uint32_t> appearing_order(const TilesetData& set, const std::vector<Matched>& matched,
                                           const std::vector<std::vector<Glide>>& glides, std::size_t t) {
  const Matched& m = matched[t];
  const double top = set.level_nominal.back();
  std::vector<char> taken(m.packed.size(), 0);
  for (std::uint32_t c : m.column) taken[c] = 1;
  RankingInput ranking;
  std::vector<double> spots;
  std::vector<std::uint32_t> leftover;
  for (std::size_t c = 0; c < m.packed.size(); ++c) {
    const double x = m.columns[2 * c], y = m.columns[2 * c + 1];
    std::vector<double>& into = taken[c] ? ranking.fixed : ranking.candidates;
    into.insert(into.end(), {x - std::floor(x), y - std::floor(y)});  // on the unit torus
    if (taken[c]) continue;
    spots.insert(spots.end(), {x, y});
    leftover.push_back(m.packed[c]);
  }
  ranking.filter_width = 1.5 / std::sqrt(top);
  const std::vector<std::uint32_t> order = progressive_order(ranking);
  const double d_hex = std::sqrt(2 / (std::sqrt(3.0) * top));
  const GliderField field(set, glides, t, kClearance * d_hex, top);
  const std::vector<double> clear = field.clear_counts(spots, kClearance * d_hex);
  const std::size_t listed = order.size();
  std::vector<char> placed(listed, 0);
  std::vector<std::uint32_t> out;
  for (std::size_t a = 0; a < listed; ++a) {
    const double threshold = top + (double(a) + 0.5) / double(listed) * (set.appearing_end() - top);
    std::size_t pick = listed;
    for (std::size_t i = 0; i < listed && pick == listed; ++i)
      if (!placed[order[i]] && clear[order[i]] <= threshold) pick = order[i];
    if (pick == listed)  // none is clear yet: the one that clears first
      for (std::size_t i = 0; i < listed; ++i)
        if (!placed[order[i]] && (pick == listed || clear[order[i]] < clear[pick])) pick = order[i];
    placed[pick] = 1;
    out.push_back(leftover[pick]);
  }
  return out;
}

}  // namespace

std::vector<TileHandover> plan_handover(const TilesetData& set) {
  KDM_CHECK(set.subdivision().m >= 2 && set.keyframe_nominal.size() >= 2);
  std::vector<Matched> matched;
  std::vector<std::vector<Glide>> glides(set.tiles.size());
  for (std::size_t t = 0; t < set.tiles.size(); ++t) {
    matched.push_back(match_tile(set, t));
    for (std::uint32_t r = 0; r < matched[t].column.size(); ++r)
      glides[t].push_back(glide_to(set, matched[t], r, matched[t].column[r]));
  }
  // Tiles in turn, each against its neighbours as they stand: a few passes.
  for (int pass = 0; pass < kPasses; ++pass)
    for (std::size_t t = 0; t < set.tiles.size(); ++t) untangle(set, matched, glides, t);
  for (int pass = 0; pass < kRepairPasses; ++pass)
    for (std::size_t t = 0; t < set.tiles.size(); ++t) repair(set, matched, glides, t);
  std::vector<TileHandover> out(set.tiles.size());
  for (std::size_t t = 0; t < set.tiles.size(); ++t) {
    for (std::uint32_t c : matched[t].column) out[t].target.push_back(matched[t].packed[c]);
    out[t].appearing = appearing_order(set, matched, glides, t);
  }
  return out;
}

}  // namespace kdm::gen
