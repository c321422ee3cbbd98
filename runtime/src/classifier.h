// Internal: a class query's classifier (kdm/runtime/class_query.h), which classes the points the
// emission loop writes without their densities at hand: from their tiles' and cells' bounds where those
// settle the class, else from the classes' densities at their stable positions.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "class_densities.h"
#include "descent.h"
#include "image_runs.h"
#include "query_tables.h"

namespace kdm::detail {

/// Finds emitted points' classes from their tiles' thresholds and, for varying densities, the cumulative
/// densities at their stable positions.
class Classifier {
 public:
  Classifier(const Tileset& tileset, const ClassQueryParams& p, const ClassDensities& densities,
             const QueryParams& q)
      : tileset_(tileset),
        set_(tileset.data()),
        tables_(detail::TilesetInternals::tables(tileset)),
        p_(p),
        densities_(densities),
        S_(q.tile_size),
        scale_(q.scale) {}

  /// detail::ConstantClasses::class_of_id over a Classifier (`user`): one point's class.
  static std::uint8_t class_of_id(void* user, const PointId& id) {
    std::uint8_t c = 0;
    (*static_cast<Classifier*>(user))([&](std::size_t) -> const PointId& { return id; }, &c, 1);
    return c;
  }

  /// detail::VaryingClasses::class_ranks over a Classifier (`user`): ranks [first, first + count) of
  /// depth-0 tile (tx, ty).
  static void class_ranks(void* user, std::int64_t tx, std::int64_t ty, std::uint32_t first,
                          std::uint32_t count, std::uint8_t* out) {
    auto& c = *static_cast<Classifier*>(user);
    if (count == 1 && c.classify_one(tx, ty, first, *out)) return;
    c.classify_run(PointId{tx, ty, first}, count, out);
  }

  /// detail::VaryingClasses::class_points over a Classifier (`user`).
  static void class_points(void* user, std::int64_t tx, std::int64_t ty, const std::uint32_t* ranks,
                           std::size_t n, const double* x, const double* y, std::uint8_t* out) {
    static_cast<Classifier*>(user)->classify_points(tx, ty, ranks, n, x, y, out);
  }

  /// detail::VaryingClasses::class_records over a Classifier (`user`).
  static void class_records(void* user, const QueryPoint* p, std::size_t n, std::uint8_t* out) {
    auto& c = *static_cast<Classifier*>(user);
    if (!c.densities_.batch) {
      c([&](std::size_t i) -> const PointId& { return p[i].id; }, out, n);
      return;
    }
    c.classify_records(p, n, out);
  }

  /// Classes ids(0) … ids(count - 1) into classes[0..count).
  template <class Ids>
  void operator()(Ids ids, std::uint8_t* classes, std::size_t count) {
    if (densities_.all_constant)
      classify_constant(ids, classes, count);
    else
      classify_varying(ids, classes, count);
  }

 private:
  /// Constant densities: thresholds grow with the rank, so class k holds the ranks from first_rank_[k - 1]
  /// on, and a tile's points come in rank order, so the class only steps forward along them. Everything
  /// the loop reads is local: the byte stores into `classes` could alias any member.
  template <class Ids>
  void classify_constant(Ids ids, std::uint8_t* classes, std::size_t count) {
    const std::uint32_t last = p_.class_count - 1;
    std::uint32_t first_rank[kMaxQueryClasses];
    std::copy(first_rank_, first_rank_ + kMaxQueryClasses, first_rank);
    PointId tile = tile_;
    std::uint32_t cls = class_, previous = rank_;
    for (std::size_t i = 0; i < count; ++i) {
      const PointId& id = ids(i);
      if (id.tile_x != tile.tile_x || id.tile_y != tile.tile_y || id.depth != tile.depth) {
        enter(id);
        tile = id, cls = 0, previous = 0;
        std::copy(first_rank_, first_rank_ + kMaxQueryClasses, first_rank);
      }
      if (float t; appearing_threshold(id.rank, t)) {
        classes[i] = class_at(id, t);
        continue;
      }
      if (id.rank < previous) cls = 0;
      previous = id.rank;
      while (cls < last && id.rank >= first_rank[cls]) ++cls;
      classes[i] = static_cast<std::uint8_t>(cls);
    }
    class_ = cls, rank_ = previous;
  }

  template <class Ids>
  void classify_varying(Ids ids, std::uint8_t* classes, std::size_t count) {
    // The sure ranges follow one another in rank order, and a tile's points come in rank order: the range
    // a rank may lie in only steps forward (back to the first where the ranks fall, past the top level).
    std::uint32_t k = class_, previous = rank_;
    for (std::size_t i = 0; i < count; ++i) {
      const PointId& id = ids(i);
      if (id.tile_x != tile_.tile_x || id.tile_y != tile_.tile_y || id.depth != tile_.depth) enter(id), k = 0;
      if (float t; appearing_threshold(id.rank, t)) {
        classes[i] = class_at(id, t);
        continue;
      }
      if (id.rank < previous) k = 0;
      previous = id.rank;
      if (id.rank >= thresholds_size_) {  // not a point of its tile (never for a valid set): the last class
        classes[i] = static_cast<std::uint8_t>(p_.class_count - 1);
        continue;
      }
      // Ranks whose class the tile's bounds settle need no density read.
      while (id.rank >= sure_to_[k]) ++k;  // the last class's range has no end
      if (id.rank >= sure_from_[k]) {
        classes[i] = static_cast<std::uint8_t>(k);
        continue;
      }
      classes[i] = read_class(id);
    }
    class_ = k, rank_ = previous;
  }

  /// Varying densities, one rank of the current tile at or past the last one classified (a candidate the
  /// loop settled by its cell's bounds): its class into `out`; false for any other point.
  bool classify_one(std::int64_t tx, std::int64_t ty, std::uint32_t rank, std::uint8_t& out) {
    if (densities_.all_constant || tx != tile_.tile_x || ty != tile_.tile_y || tile_.depth != 0 ||
        rank < rank_ || rank >= thresholds_size_)
      return false;
    std::uint32_t k = class_;
    while (rank >= sure_to_[k]) ++k;
    class_ = k, rank_ = rank;
    out = rank >= sure_from_[k] ? static_cast<std::uint8_t>(k) : read_class(PointId{tx, ty, rank});
    return true;
  }

  /// Varying densities: ranks [first.rank, first.rank + count) of first's tile into classes[0..count), a
  /// settled range at a time.
  void classify_run(const PointId& first, std::uint32_t count, std::uint8_t* classes) {
    const std::uint32_t end = first.rank + count;
    if (densities_.all_constant || end > thresholds_size_ || first.tile_x != tile_.tile_x ||
        first.tile_y != tile_.tile_y || first.depth != tile_.depth) {
      enter(first);
      if (densities_.all_constant || end > thresholds_size_) {
        (*this)(
            [&](std::size_t i) {
              return PointId{first.tile_x, first.tile_y, first.rank + std::uint32_t(i)};
            },
            classes, count);
        return;
      }
      class_ = 0, rank_ = 0;
    }
    std::uint32_t k = first.rank < rank_ ? 0 : class_;
    PointId id = first;
    while (id.rank < end) {
      while (id.rank >= sure_to_[k]) ++k;
      const bool settled = id.rank >= sure_from_[k];
      const std::uint32_t upto = std::min(end, settled ? sure_to_[k] : sure_from_[k]);
      if (settled)
        std::fill(classes + (id.rank - first.rank), classes + (upto - first.rank),
                  static_cast<std::uint8_t>(k));
      else if (densities_.one_grid && detail::image_runs_fit(*densities_.images.grid->image))
        classify_by_sums(id, upto, classes + (id.rank - first.rank));
      else if (densities_.batch)
        classify_in_batches(id, upto, classes + (id.rank - first.rank));
      else
        for (; id.rank < upto; ++id.rank) classes[id.rank - first.rank] = read_class(id);
      id.rank = upto;
    }
    class_ = k, rank_ = end - 1;
  }

  /// Classes that are all images on one grid: ranks [first.rank, end) of the current tile into out[0 ..),
  /// from the images' running sums a block at a time, every point read (texels are read faster than
  /// cells are tested). The sums rise with the class, so the classes whose count does not pass a point's
  /// threshold are a prefix (read_class's rule).
  void classify_by_sums(const PointId& first, std::uint32_t end, std::uint8_t* out) {
    const double wx = double(first.tile_x) * side_, wy = double(first.tile_y) * side_;
    const detail::ClassImages& images = densities_.images;
    const std::uint32_t last = p_.class_count - 1;
    double x[detail::kImageBlock], y[detail::kImageBlock], sums[detail::kImageBlock * kMaxQueryClasses];
    // By the running sums' own images, only sums [from, to) are read: the tile's bounds have every rank
    // of the range short of the sums below `from` and passing the sums from `to` on (enter_bounds).
    std::uint32_t from = 0, to = last;
    if (densities_.sums) {
      while (from < last && first.rank >= sure_from_[from + 1]) ++from;
      while (to > from && end - 1 < sure_to_[to - 1]) --to;
    }
    for (std::uint32_t r = first.rank; r < end;) {
      const std::uint32_t count = std::min(end - r, detail::kImageBlock);
      if (densities_.sums) {
        detail::image_sum_classes_run(points_ + r, count, wx, wy, side_, *images.grid, images.values + from,
                                      to - from, thresholds_ + r, area_, static_cast<std::uint8_t>(from),
                                      out + (r - first.rank));
      } else {
        detail::image_sums_run(points_ + r, count, wx, wy, side_, *images.grid, images.values, images.count,
                               x, y, sums);
        for (std::uint32_t i = 0; i < count; ++i) {
          const float t = thresholds_[r + i];
          std::uint32_t cls = 0;
          for (std::uint32_t k = 0; k < last; ++k)
            cls += !TilesetShape::emits(t, sums[k * detail::kImageBlock + i] * area_);
          out[r + i - first.rank] = static_cast<std::uint8_t>(cls);
        }
      }
      r += count;
    }
  }

  /// Classes read in batches: ranks [first.rank, end) of the current tile (depth 0) into out[0 ..),
  /// kDensityBatch at a time (classify_points).
  void classify_in_batches(const PointId& first, std::uint32_t end, std::uint8_t* out) {
    const double wx = double(first.tile_x) * side_, wy = double(first.tile_y) * side_;
    std::uint32_t ranks[kDensityBatch];
    double x[kDensityBatch], y[kDensityBatch];
    for (std::uint32_t r = first.rank; r < end;) {
      const std::uint32_t count = std::min<std::uint32_t>(end - r, kDensityBatch);
      for (std::uint32_t i = 0; i < count; ++i) {
        const TilePoint& point = points_[r + i];
        ranks[i] = r + i, x[i] = wx + point.unit_x() * side_, y[i] = wy + point.unit_y() * side_;
      }
      classify_points(first.tile_x, first.tile_y, ranks, count, x, y, out + (r - first.rank));
      r += count;
    }
  }

  /// Ranks ranks[0 … n) of depth-0 tile (tx, ty) at their stable positions (x[i], y[i]) into out[0 … n):
  /// those the bounds leave open are read together, each class's values in one batch (read_class's rule).
  void classify_points(std::int64_t tx, std::int64_t ty, const std::uint32_t* ranks, std::size_t n,
                       const double* x, const double* y, std::uint8_t* out) {
    if (!densities_.batch) {
      for (std::size_t i = 0; i < n; ++i) class_ranks(this, tx, ty, ranks[i], 1, out + i);
      return;
    }
    if (tx != tile_.tile_x || ty != tile_.tile_y || tile_.depth != 0) {
      enter(PointId{tx, ty, ranks[0]});
      class_ = 0, rank_ = 0;
    }
    std::uint32_t open[kDensityBatch];  // the points the bounds leave open
    double ox[kDensityBatch], oy[kDensityBatch];
    std::size_t m = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t rank = ranks[i];
      if (rank >= thresholds_size_) {  // not a point of its tile (never for a valid set): the last class
        out[i] = static_cast<std::uint8_t>(p_.class_count - 1);
        continue;
      }
      std::uint32_t k = 0;
      while (rank >= sure_to_[k]) ++k;
      if (rank >= sure_from_[k]) {
        out[i] = static_cast<std::uint8_t>(k);
        continue;
      }
      if (settled_by_cell(rank, out[i])) continue;
      open[m] = std::uint32_t(i), ox[m] = x[i], oy[m++] = y[i];
    }
    if (m == 0) return;
    float t[kDensityBatch];
    double area[kDensityBatch];
    for (std::size_t i = 0; i < m; ++i) t[i] = thresholds_[ranks[open[i]]], area[i] = area_;
    classes_of_open(m, open, t, area, ox, oy, out);
  }

  /// Points out[open[i]] (i < m) of thresholds t[i] at (x[i], y[i]), expected counts density times
  /// area[i]: their classes from the running sums there. The classes short of a threshold are a prefix.
  void classes_of_open(std::size_t m, const std::uint32_t* open, const float* t, const double* area,
                       const double* x, const double* y, std::uint8_t* out) const {
    const std::uint32_t last = p_.class_count - 1;
    double sums[kMaxQueryClasses][kDensityBatch];
    densities_.sums_at(m, x, y, last, sums);
    for (std::size_t i = 0; i < m; ++i) {
      std::uint32_t k = 0;
      for (std::uint32_t c = 0; c < last; ++c) k += !TilesetShape::emits(t[i], sums[c][i] * area[i]);
      out[open[i]] = static_cast<std::uint8_t>(k);
    }
  }

  /// Points of any depths (classes read in batches): each by read_class's rule, those the bounds leave
  /// open gathered, kDensityBatch at a time, and each class's values read for them in one batch.
  void classify_records(const QueryPoint* p, std::size_t n, std::uint8_t* out) {
    std::uint32_t open[kDensityBatch];
    float t[kDensityBatch];
    double x[kDensityBatch], y[kDensityBatch], area[kDensityBatch];
    std::size_t m = 0;
    auto read_open = [&] {
      classes_of_open(m, open, t, area, x, y, out);
      m = 0;
    };
    for (std::size_t i = 0; i < n; ++i) {
      const PointId& id = p[i].id;
      if (id.tile_x != tile_.tile_x || id.tile_y != tile_.tile_y || id.depth != tile_.depth) {
        enter(id);
        class_ = 0, rank_ = 0;
      }
      if (id.rank >= thresholds_size_) {  // not a point of its tile (never for a valid set): the last class
        out[i] = static_cast<std::uint8_t>(p_.class_count - 1);
        continue;
      }
      const TilePoint& point = points_[id.rank];
      const double wx = double(id.tile_x) * side_, wy = double(id.tile_y) * side_;
      if (float appearing; appearing_threshold(id.rank, appearing)) {
        open[m] = std::uint32_t(i), t[m] = appearing, area[m] = area_;
        x[m] = wx + point.unit_x() * side_, y[m++] = wy + point.unit_y() * side_;
        if (m == kDensityBatch) read_open();
        continue;
      }
      std::uint32_t k = 0;
      while (id.rank >= sure_to_[k]) ++k;
      if (id.rank >= sure_from_[k]) {
        out[i] = static_cast<std::uint8_t>(k);
        continue;
      }
      if (settled_by_cell(id.rank, out[i])) continue;
      open[m] = std::uint32_t(i), t[m] = thresholds_[id.rank], area[m] = area_;
      x[m] = wx + point.unit_x() * side_, y[m++] = wy + point.unit_y() * side_;
      if (m == kDensityBatch) read_open();
    }
    if (m > 0) read_open();
  }

  /// The class of rank `rank` of the current tile if the bounds of the cell it lies in settle it (read_cell).
  bool settled_by_cell(std::uint32_t rank, std::uint8_t& out) {
    const TilePoint& point = points_[rank];
    const float t = thresholds_[rank];
    const std::uint32_t cx = point.x >> (16 - kCellBits), cy = point.y >> (16 - kCellBits);
    const std::uint32_t cell = cy << kCellBits | cx;
    if (!(cells_read_ >> cell & 1)) read_cell(cx, cy, cell);
    // The cumulative bounds rise with the class (every class's bounds are finite and ≥ 0), so the classes
    // whose count falls short of t everywhere in the cell are a prefix, as are those whose count may: the
    // point is settled where the two end, counted without a branch the class's changes would mispredict.
    const std::uint32_t last = p_.class_count - 1;
    std::uint32_t short_everywhere = 0, short_somewhere = 0;
    for (std::uint32_t k = 0; k < last; ++k) {
      short_everywhere += !TilesetShape::emits(t, cell_hi_[cell][k]);
      short_somewhere += !TilesetShape::emits(t, cell_lo_[cell][k]);
    }
    out = static_cast<std::uint8_t>(short_everywhere);
    return short_everywhere == short_somewhere;
  }

  /// A point of the current tile whose class its tile's bounds leave open: settled by the bounds of the
  /// cell of the tile it lies in where they can, else by the classes' densities at its stable position,
  /// computed as query_points computes it (depth 0), so the densities read are its.
  [[gnu::always_inline]] std::uint8_t read_class(const PointId& id) {
    std::uint8_t k;
    if (settled_by_cell(id.rank, k)) return k;
    const TilePoint& point = points_[id.rank];
    const double wx = double(id.tile_x) * side_, wy = double(id.tile_y) * side_;
    return densities_.class_of(thresholds_[id.rank], wx + point.unit_x() * side_, wy + point.unit_y() * side_,
                               area_);
  }

  /// A sub-point that appears on its own (a rank of a subtile below its hand-over keyframe that carries
  /// its subtile's id) comes after every point of its parent in the union's order, at its place in the
  /// parent's list (descent.cpp): its class follows that threshold, over m² into its subtile's counts,
  /// not its rank's, or the parent's points and it would both fill the first classes. False for any
  /// other point of the current tile.
  bool appearing_threshold(std::uint32_t rank, float& t) const {
    if (rank >= appearing_ranks_ || !QueryTables::appearing(appearing_row_[rank])) return false;
    const double a = appearing_row_[rank] & ~QueryTables::kAppearing, top = set_.level_nominal.back();
    const double m2 = double(tables_.subtiles) * tables_.subtiles;
    t = static_cast<float>((top + (a + 0.5) / appearing_listed_ * (set_.appearing_end() - top)) / m2);
    return true;
  }
  /// The class of point `id` of the current tile with threshold `t`, from the classes' densities at its
  /// stable position.
  std::uint8_t class_at(const PointId& id, float t) const {
    const TilePoint& point = points_[id.rank];
    const double wx = double(id.tile_x) * side_, wy = double(id.tile_y) * side_;
    return densities_.class_of(t, wx + point.unit_x() * side_, wy + point.unit_y() * side_, area_);
  }

  /// The classes' cumulative expected counts' bounds over cell (cx, cy) of the current tile, widened by
  /// 10^-9 as the tile's. The cell's sides are computed as positions are (corner plus a fraction times the
  /// side), and rounding is monotonic, so every point of the cell lies in the rectangle bounded.
  void read_cell(std::uint32_t cx, std::uint32_t cy, std::uint32_t cell) {
    constexpr double kStep = 1.0 / (1 << kCellBits);
    const double wx = double(tile_.tile_x) * side_, wy = double(tile_.tile_y) * side_;
    double lo[kMaxQueryClasses], hi[kMaxQueryClasses];
    densities_.cumulative_bounds(wx + (cx * kStep) * side_, wy + (cy * kStep) * side_,
                                 wx + ((cx + 1) * kStep) * side_, wy + ((cy + 1) * kStep) * side_, lo, hi);
    for (std::uint32_t k = 0; k + 1 < p_.class_count; ++k)
      cell_lo_[cell][k] = lo[k] * area_ * (1 - 1e-9), cell_hi_[cell][k] = hi[k] * area_ * (1 + 1e-9);
    cells_read_ |= std::uint64_t(1) << cell;
  }

  /// Reads what the points of id's tile share.
  void enter(const PointId& id) {
    tile_ = id;
    cells_read_ = 0;
    const std::size_t index = id.depth == 0
                                  ? tileset_.tile_index_at(id.tile_x, id.tile_y)
                                  : static_cast<std::size_t>(tile_of(tileset_, id) - set_.tiles.data());
    thresholds_ = tables_.thresholds[index].data();
    thresholds_size_ = tables_.thresholds[index].size();
    points_ = set_.tiles[index].points.data();
    appearing_ranks_ = 0;
    if (id.depth > 0) {  // its parent's table of which of its ranks it inherits and which appear
      const std::int64_t m = tables_.subtiles;
      const std::int64_t cx = ((id.tile_x % m) + m) % m, cy = ((id.tile_y % m) + m) % m;
      const PointId parent{(id.tile_x - cx) / m, (id.tile_y - cy) / m, 0, id.depth - 1};
      const auto p = static_cast<std::size_t>(tile_of(tileset_, parent) - set_.tiles.data());
      const std::uint32_t* start =
          tables_.inherited_start.data() + p * std::size_t(m * m + 1) + (cy * m + cx);
      appearing_row_ = tables_.inherited[p].data() + start[0];
      appearing_ranks_ = start[1] - start[0];
      appearing_listed_ = double(set_.tiles[p].appearing.size());
    }
    side_ = id.depth == 0 ? S_ : S_ / std::pow(double(tables_.subtiles), double(id.depth));
    area_ = side_ * side_ * scale_;
    if (!densities_.all_constant) {
      enter_bounds(id);
      return;
    }
    // The first rank past each cumulative count: the ranks below it pass (TilesetShape::emits).
    double sum = 0;
    for (std::uint32_t k = 0; k + 1 < p_.class_count; ++k) {
      sum += density_or_zero(p_.classes[k].constant);
      const double count = sum * area_;
      first_rank_[k] = static_cast<std::uint32_t>(
          std::lower_bound(thresholds_, thresholds_ + thresholds_size_, count,
                           [](float t, double c) { return TilesetShape::emits(t, c); }) -
          thresholds_);
    }
  }

  /// Varying densities: the ranks [sure_from_[k], sure_to_[k]) of the tile that are of class k wherever they
  /// lie in it. Class k holds a point when the first k classes' count at it does not pass its threshold
  /// and the first k + 1 classes' does; the tile's bounds of those counts, widened by 10^-9 for rounding
  /// (query.cpp's margin), settle both for a range of thresholds, and thresholds are sorted.
  void enter_bounds(const PointId& id) {
    const double wx = double(id.tile_x) * side_, wy = double(id.tile_y) * side_;
    auto first_not_emitted = [&](double count) {
      return static_cast<std::uint32_t>(
          std::lower_bound(thresholds_, thresholds_ + thresholds_size_, count,
                           [](float t, double c) { return TilesetShape::emits(t, c); }) -
          thresholds_);
    };
    double lo[kMaxQueryClasses], hi[kMaxQueryClasses];
    densities_.cumulative_bounds(wx, wy, wx + side_, wy + side_, lo, hi);
    for (std::uint32_t k = 0; k < p_.class_count; ++k) {
      sure_from_[k] = k == 0 ? 0 : first_not_emitted(hi[k - 1] * area_ * (1 + 1e-9));
      sure_to_[k] = k + 1 == p_.class_count ? ~0u : first_not_emitted(lo[k] * area_ * (1 - 1e-9));
    }
  }

  const Tileset& tileset_;
  const TilesetData& set_;
  const detail::QueryTables& tables_;
  const ClassQueryParams& p_;
  const ClassDensities& densities_;
  const double S_, scale_;
  // The tile of the last point classified.
  PointId tile_{0, 0, 0, ~0u};
  const float* thresholds_ = nullptr;
  std::size_t thresholds_size_ = 0;
  const TilePoint* points_ = nullptr;
  // Past the top level: which of the current subtile's first ranks its parent hands over (share's table).
  const std::uint32_t* appearing_row_ = nullptr;
  std::uint32_t appearing_ranks_ = 0;
  double appearing_listed_ = 1;
  double side_ = 0, area_ = 0;
  std::uint32_t first_rank_[kMaxQueryClasses] = {};
  std::uint32_t sure_from_[kMaxQueryClasses] = {}, sure_to_[kMaxQueryClasses] = {};
  std::uint32_t class_ = 0, rank_ = 0;  // the last point's class and rank
  // Varying densities: a tile's 2^kCellBits × 2^kCellBits cells, whose bounds read_class reads for the
  // points its tile's bounds leave open (cell c's when bit c of cells_read_ is set): narrower bands, fewer
  // densities read.
  static constexpr std::uint32_t kCellBits = 2;  // at most 3: cells_read_ has a bit per cell
  std::uint64_t cells_read_ = 0;
  double cell_lo_[1 << (2 * kCellBits)][kMaxQueryClasses] = {},
                            cell_hi_[1 << (2 * kCellBits)][kMaxQueryClasses] = {};
};

}  // namespace kdm::detail
