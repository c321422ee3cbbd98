// Several classes in one query (kdm/runtime/class_query.h): the one-class query at the sum of the
// densities, then each emitted point's class from its threshold and the cumulative densities at its
// stable position.
#include "kdm/runtime/class_query.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "descent.h"
#include "emit_tile.h"
#include "image_runs.h"
#include "image_sampler.h"
#include "kdm/runtime/hash.h"
#include "query_counted.h"
#include "query_tables.h"

namespace kdm {

using detail::density_or_zero;
using detail::ImageSampler;

namespace {

// Static names for QueryProblem::parameter, one per class.
constexpr const char* kConstantNames[kMaxQueryClasses] = {
    "classes[0].constant", "classes[1].constant", "classes[2].constant", "classes[3].constant",
    "classes[4].constant", "classes[5].constant", "classes[6].constant", "classes[7].constant"};
constexpr const char* kImageNames[kMaxQueryClasses] = {
    "classes[0].image", "classes[1].image", "classes[2].image", "classes[3].image",
    "classes[4].image", "classes[5].image", "classes[6].image", "classes[7].image"};
constexpr const char* kCallbackNames[kMaxQueryClasses] = {
    "classes[0].callback", "classes[1].callback", "classes[2].callback", "classes[3].callback",
    "classes[4].callback", "classes[5].callback", "classes[6].callback", "classes[7].callback"};
constexpr const char* kCallbackMaxNames[kMaxQueryClasses] = {
    "classes[0].callback_max", "classes[1].callback_max", "classes[2].callback_max",
    "classes[3].callback_max", "classes[4].callback_max", "classes[5].callback_max",
    "classes[6].callback_max", "classes[7].callback_max"};
constexpr const char* kJointMaxNames[kMaxQueryClasses] = {"joint.max[0]", "joint.max[1]", "joint.max[2]",
                                                          "joint.max[3]", "joint.max[4]", "joint.max[5]",
                                                          "joint.max[6]", "joint.max[7]"};

/// The classes' densities, read as query_points reads a one-class density, so that a class's values and
/// their running sums are the very numbers the one-class queries compare.
struct ClassDensities {
  const ClassQueryParams* params = nullptr;
  ImageSampler samplers[kMaxQueryClasses];
  bool all_constant = true;
  bool one_grid = false;         ///< every class an image on class 0's texels (sum_of_images)
  bool batch = false;            ///< a class read in batches (sum_of_batches), or the joint density
  bool joint = false;            ///< the joint density gives every class's (ClassQueryParams::joint)
  detail::ClassImages images{};  ///< when one_grid: the images, read a block of points at a time
  /// Where sum_of_densities last read the classes, and their running sums there (emit_tile.h's
  /// VaryingClassSink classes the candidate just read from it).
  mutable detail::ClassScratch scratch;

  double at(std::uint32_t k, double x, double y) const {
    const QueryDensity& d = params->classes[k];
    switch (d.kind) {
      case QueryDensity::Kind::kConstant:
        return density_or_zero(d.constant);
      case QueryDensity::Kind::kImage:
        return samplers[k].at(x, y);
      case QueryDensity::Kind::kCallback:
        break;
    }
    return detail::callback_value(d, x, y);
  }
  /// The joint density's values at (x, y) into v[0 … class_count), each to be read as query_points reads
  /// one value (density_or_zero) where it is added: a separate pass would load pairs of values just
  /// stored one by one, which the processor cannot forward.
  void joint_at(double x, double y, double* v) const {
    const JointClassDensity& j = params->joint;
    if (j.densities)
      j.densities(j.user, x, y, v);
    else
      j.batch_densities(j.user, 1, &x, &y, v);  // class k's value at v[k · 1 + 0]
  }
  /// Class k's values at n positions into v[0 … n), as at() reads each: a batch callback's in one call.
  void values_of(std::uint32_t k, std::size_t n, const double* x, const double* y, double* v) const {
    const QueryDensity& d = params->classes[k];
    if (d.kind != QueryDensity::Kind::kCallback || !d.batch_callback) {
      for (std::size_t i = 0; i < n; ++i) v[i] = at(k, x[i], y[i]);
      return;
    }
    d.batch_callback(d.user, n, x, y, v);
    for (std::size_t i = 0; i < n; ++i) v[i] = density_or_zero(v[i]);
  }
  /// The running sums of classes 0 … count - 1 at n ≤ kDensityBatch positions into sums[k][i], added as
  /// sum_of_densities adds them: a batch callback's values in one call, a joint batch's all in one.
  void sums_at(std::size_t n, const double* x, const double* y, std::uint32_t count,
               double (*sums)[kDensityBatch]) const {
    if (!joint) {
      for (std::uint32_t k = 0; k < count; ++k) {
        values_of(k, n, x, y, sums[k]);
        if (k > 0)
          for (std::size_t i = 0; i < n; ++i) sums[k][i] += sums[k - 1][i];
      }
      return;
    }
    double v[kMaxQueryClasses * kDensityBatch];  // class k's value at position i in v[k · n + i]
    const JointClassDensity& j = params->joint;
    if (j.batch_densities) {
      j.batch_densities(j.user, n, x, y, v);
    } else {
      double one[kMaxQueryClasses];
      for (std::size_t i = 0; i < n; ++i) {
        j.densities(j.user, x[i], y[i], one);
        for (std::uint32_t k = 0; k < count; ++k) v[k * n + i] = one[k];
      }
    }
    for (std::uint32_t k = 0; k < count; ++k)
      for (std::size_t i = 0; i < n; ++i)
        sums[k][i] = (k > 0 ? sums[k - 1][i] : 0.0) + density_or_zero(v[k * n + i]);
  }
  /// Bounds of every class's density over [x0, x1] × [y0, y1] into lo[k], hi[k], as query_points takes
  /// one density's.
  void bounds(double x0, double y0, double x1, double y1, double* lo, double* hi) const {
    const JointClassDensity& j = params->joint;
    if (!joint) {
      for (std::uint32_t k = 0; k < params->class_count; ++k)
        detail::density_bounds(params->classes[k], x0, y0, x1, y1, lo[k], hi[k]);
      return;
    }
    double l[kMaxQueryClasses], h[kMaxQueryClasses];
    std::fill(l, l + kMaxQueryClasses, std::nan("")), std::fill(h, h + kMaxQueryClasses, std::nan(""));
    if (j.bounds) j.bounds(j.user, x0, y0, x1, y1, l, h);
    for (std::uint32_t k = 0; k < params->class_count; ++k)
      detail::trusted_bounds(l[k], h[k], j.max[k], lo[k], hi[k]);
  }
  /// The first class whose cumulative expected count (densities times `area`) passes `threshold`; the
  /// last class if none does (past the top level, where a point's own threshold only approximates the
  /// rule that emitted it). Separate densities are read only up to the class found.
  std::uint8_t class_of(float threshold, double x, double y, double area) const {
    const std::uint32_t last = params->class_count - 1;
    double v[kMaxQueryClasses];
    if (joint) joint_at(x, y, v);
    ImageSampler::Texels t{};
    if (one_grid) t = samplers[0].texels(x, y);
    double sum = 0;
    for (std::uint32_t k = 0; k < last; ++k) {
      sum += joint      ? density_or_zero(v[k])
             : one_grid ? ImageSampler::blend(params->classes[k].image->values, t)
                        : at(k, x, y);
      if (TilesetShape::emits(threshold, sum * area)) return static_cast<std::uint8_t>(k);
    }
    return static_cast<std::uint8_t>(last);
  }
};

// The union's density (QueryDensity::callback) from separate densities and from a joint one: the classes'
// running sums, left in the scratch for the sink to class the candidate.
double sum_of_densities(void* user, double x, double y) {
  const auto& c = *static_cast<const ClassDensities*>(user);
  double sum = 0;
  for (std::uint32_t k = 0; k < c.params->class_count; ++k) c.scratch.cumulative[k] = sum += c.at(k, x, y);
  c.scratch.x = x, c.scratch.y = y;
  return sum;
}
/// The union's density (QueryDensity::batch_callback) when a class, or the joint density, is read in
/// batches: the classes' running sums at the n positions (ClassDensities::sums_at), left in the scratch's
/// batch for the sink to class the positions read.
void sum_of_batches(void* user, std::size_t n, const double* x, const double* y, double* out) {
  const auto& c = *static_cast<const ClassDensities*>(user);
  detail::ClassScratch& s = c.scratch;
  const std::uint32_t count = c.params->class_count;
  c.sums_at(n, x, y, count, s.batch_cumulative);
  std::copy(s.batch_cumulative[count - 1], s.batch_cumulative[count - 1] + n, out);
  std::copy(x, x + n, s.batch_x), std::copy(y, y + n, s.batch_y);
  s.batch_count = n;
  if (n != 1) return;
  for (std::uint32_t k = 0; k < count; ++k) s.cumulative[k] = s.batch_cumulative[k][0];
  s.x = x[0], s.y = y[0];  // a single read, as sum_of_densities leaves it (VaryingClassSink::class_at)
}
/// Classes that are all images on one grid of texels: where a position falls among them is found once.
double sum_of_images(void* user, double x, double y) {
  const auto& c = *static_cast<const ClassDensities*>(user);
  const ImageSampler::Texels t = c.samplers[0].texels(x, y);
  double sum = 0;
  for (std::uint32_t k = 0; k < c.params->class_count; ++k)
    c.scratch.cumulative[k] = sum += ImageSampler::blend(c.params->classes[k].image->values, t);
  c.scratch.x = x, c.scratch.y = y;
  return sum;
}
double sum_of_joint(void* user, double x, double y) {
  const auto& c = *static_cast<const ClassDensities*>(user);
  double v[kMaxQueryClasses], sum = 0;
  c.joint_at(x, y, v);
  for (std::uint32_t k = 0; k < c.params->class_count; ++k)
    c.scratch.cumulative[k] = sum += density_or_zero(v[k]);
  c.scratch.x = x, c.scratch.y = y;
  return sum;
}

/// The union's bounds (QueryDensity::bounds): the sum of the classes'.
void sum_of_bounds(void* user, double x0, double y0, double x1, double y1, double* lo, double* hi) {
  const auto& c = *static_cast<const ClassDensities*>(user);
  double l[kMaxQueryClasses], h[kMaxQueryClasses];
  c.bounds(x0, y0, x1, y1, l, h);
  *lo = *hi = 0;
  for (std::uint32_t k = 0; k < c.params->class_count; ++k) *lo += l[k], *hi += h[k];
}

/// An upper bound of class `d`'s density wherever a point that can show in the region is decided: the
/// region widened by `reach` (world units; in smooth mode points glide in from outside it).
double density_bound(const QueryDensity& d, const QueryParams& q, double reach) {
  switch (d.kind) {
    case QueryDensity::Kind::kConstant:
      return density_or_zero(d.constant);
    case QueryDensity::Kind::kImage:
      return d.image->max_over(q.x0 - reach, q.y0 - reach, q.x1 + reach, q.y1 + reach);
    case QueryDensity::Kind::kCallback:
      break;
  }
  return d.callback_max;
}

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
    for (std::uint32_t r = first.rank; r < end;) {
      const std::uint32_t count = std::min(end - r, detail::kImageBlock);
      detail::image_sums_run(points_ + r, count, wx, wy, side_, *images.grid, images.values, images.count, x,
                             y, sums);
      for (std::uint32_t i = 0; i < count; ++i) {
        const float t = thresholds_[r + i];
        std::uint32_t cls = 0;
        for (std::uint32_t k = 0; k < last; ++k)
          cls += !TilesetShape::emits(t, sums[k * detail::kImageBlock + i] * area_);
        out[r + i - first.rank] = static_cast<std::uint8_t>(cls);
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
      std::uint32_t k = 0;
      while (id.rank >= sure_to_[k]) ++k;
      if (id.rank >= sure_from_[k]) {
        out[i] = static_cast<std::uint8_t>(k);
        continue;
      }
      if (settled_by_cell(id.rank, out[i])) continue;
      const TilePoint& point = points_[id.rank];
      const double wx = double(id.tile_x) * side_, wy = double(id.tile_y) * side_;
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

  /// The classes' cumulative expected counts' bounds over cell (cx, cy) of the current tile, widened by
  /// 10^-9 as the tile's. The cell's sides are computed as positions are (corner plus a fraction times the
  /// side), and rounding is monotonic, so every point of the cell lies in the rectangle bounded.
  void read_cell(std::uint32_t cx, std::uint32_t cy, std::uint32_t cell) {
    constexpr double kStep = 1.0 / (1 << kCellBits);
    const double wx = double(tile_.tile_x) * side_, wy = double(tile_.tile_y) * side_;
    double l[kMaxQueryClasses], h[kMaxQueryClasses];
    densities_.bounds(wx + (cx * kStep) * side_, wy + (cy * kStep) * side_, wx + ((cx + 1) * kStep) * side_,
                      wy + ((cy + 1) * kStep) * side_, l, h);
    double lo = 0, hi = 0;
    for (std::uint32_t k = 0; k + 1 < p_.class_count; ++k) {
      lo += l[k], hi += h[k];
      cell_lo_[cell][k] = lo * area_ * (1 - 1e-9), cell_hi_[cell][k] = hi * area_ * (1 + 1e-9);
    }
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
    double l[kMaxQueryClasses], h[kMaxQueryClasses];
    densities_.bounds(wx, wy, wx + side_, wy + side_, l, h);
    double lo = 0, hi = 0;
    for (std::uint32_t k = 0; k < p_.class_count; ++k) {
      sure_from_[k] = k == 0 ? 0 : first_not_emitted(hi * area_ * (1 + 1e-9));
      lo += l[k], hi += h[k];
      sure_to_[k] = k + 1 == p_.class_count ? ~0u : first_not_emitted(lo * area_ * (1 - 1e-9));
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

}  // namespace

std::uint64_t query_fingerprint(const ClassQueryParams& p) {
  QueryParams q = p.query;
  q.density = QueryDensity{};
  std::uint64_t h = mix64(query_fingerprint(q) ^ 0x636c6173736573ull);  // "classes"
  auto add = [&](std::uint64_t v) { h = mix64(h ^ v); };
  auto add_double = [&](double v) {
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    add(bits);
  };
  add(p.class_count);
  add(reinterpret_cast<std::uintptr_t>(p.joint.densities));
  add(reinterpret_cast<std::uintptr_t>(p.joint.batch_densities));
  add(reinterpret_cast<std::uintptr_t>(p.joint.user));
  for (std::uint32_t k = 0; k < p.class_count && k < kMaxQueryClasses; ++k) add_double(p.joint.max[k]);
  for (std::uint32_t k = 0; k < p.class_count && k < kMaxQueryClasses; ++k) {
    const QueryDensity& d = p.classes[k];
    add(static_cast<std::uint64_t>(d.kind));
    add_double(d.constant), add_double(d.callback_max);
    add(reinterpret_cast<std::uintptr_t>(d.image));
    add(reinterpret_cast<std::uintptr_t>(d.callback));
    add(reinterpret_cast<std::uintptr_t>(d.batch_callback));
    add(reinterpret_cast<std::uintptr_t>(d.user));
  }
  return h;
}

namespace {

/// Checks `p` and `written` (set to 0) and sets up what both outputs share: the classes' densities and the
/// one-class query at their sum (`q`). kOk, or kInvalidArgument by `refuse`.
Status prepare_union(const Tileset& tileset, const ClassQueryParams& p, std::size_t* written,
                     ClassDensities& densities, QueryParams& q, detail::Refusal& refuse) {
  using Kind = QueryProblem::Kind;
  if (written) *written = 0;
  if (!written) return refuse(Kind::kMissingArgument, "written");
  if (p.class_count < 1 || p.class_count > kMaxQueryClasses)
    return refuse(Kind::kBadClassCount, "class_count", p.class_count, kMaxQueryClasses);
  densities.params = &p;
  const bool joint = densities.joint = p.joint.densities || p.joint.batch_densities;
  if (p.joint.densities && p.joint.batch_densities)  // which one is meant is unclear
    return refuse(Kind::kBadDensity, "joint.batch_densities");
  for (std::uint32_t k = 0; k < p.class_count && joint; ++k) {
    if (!std::isfinite(p.joint.max[k])) return refuse(Kind::kNotFinite, kJointMaxNames[k], p.joint.max[k]);
    if (p.joint.max[k] < 0) return refuse(Kind::kNegative, kJointMaxNames[k], p.joint.max[k]);
    densities.all_constant = false;
  }
  for (std::uint32_t k = 0; k < p.class_count && !joint; ++k) {
    const QueryDensity& d = p.classes[k];
    switch (d.kind) {
      case QueryDensity::Kind::kConstant:
        if (!std::isfinite(d.constant)) return refuse(Kind::kNotFinite, kConstantNames[k], d.constant);
        if (d.constant < 0) return refuse(Kind::kNegative, kConstantNames[k], d.constant);
        continue;
      case QueryDensity::Kind::kImage:
        if (!d.image || !d.image->values || !d.image->max_mip || !detail::image_rect_usable(*d.image))
          return refuse(Kind::kBadDensity, kImageNames[k]);
        densities.samplers[k] = ImageSampler(d.image);
        break;
      case QueryDensity::Kind::kCallback:
        if (!d.callback == !d.batch_callback) return refuse(Kind::kBadDensity, kCallbackNames[k]);
        if (!std::isfinite(d.callback_max))
          return refuse(Kind::kNotFinite, kCallbackMaxNames[k], d.callback_max);
        if (d.callback_max < 0) return refuse(Kind::kNegative, kCallbackMaxNames[k], d.callback_max);
        break;
      default:
        return refuse(Kind::kBadDensity, kCallbackNames[k], static_cast<double>(static_cast<int>(d.kind)));
    }
    densities.all_constant = false;
  }

  // The union: a constant when every class is one (query_points' fastest path), else their sum by callback.
  q = p.query;
  q.density = QueryDensity{};
  if (densities.all_constant) {
    q.density.constant = 0;  // not QueryDensity's default of 1
    for (std::uint32_t k = 0; k < p.class_count; ++k)
      q.density.constant += density_or_zero(p.classes[k].constant);
    return Status::kOk;
  }
  q.density.kind = QueryDensity::Kind::kCallback;
  bool& one_grid = densities.one_grid = !joint;
  for (std::uint32_t k = 0; k < p.class_count && one_grid; ++k)
    one_grid = p.classes[k].kind == QueryDensity::Kind::kImage &&
               densities.samplers[0].same_grid(*p.classes[k].image);
  bool& batch = densities.batch = p.joint.batch_densities != nullptr;  // read in batches: the union too
  for (std::uint32_t k = 0; k < p.class_count && !joint && !one_grid; ++k)
    batch |= p.classes[k].kind == QueryDensity::Kind::kCallback && p.classes[k].batch_callback;
  if (batch)
    q.density.batch_callback = sum_of_batches;
  else
    q.density.callback = joint ? sum_of_joint : one_grid ? sum_of_images : sum_of_densities;
  if (one_grid) {
    densities.images.grid = &densities.samplers[0], densities.images.count = p.class_count;
    for (std::uint32_t k = 0; k < p.class_count; ++k) densities.images.values[k] = p.classes[k].image->values;
  }
  q.density.bounds = sum_of_bounds;
  q.density.user = &densities;
  // Smooth mode: as far as any point of the set glides, or lies past its tile down its subtiles.
  double reach = 0;
  if (q.mode == QueryMode::kSmooth && tileset.has_glide_track()) {
    const detail::QueryTables& tables = detail::TilesetInternals::tables(tileset);
    for (std::size_t g = 0; g < tables.glide_reach.size(); ++g)
      reach = std::max(reach, tables.glide_reach[g]);
    reach = (std::max(reach, tables.descent_reach) + 2.0 / 65536.0) * q.tile_size;
  }
  q.density.callback_max = 0;
  // Bounds of a region query_points will accept (it refuses the others, with their names, later).
  const bool finite = std::isfinite(q.x0) && std::isfinite(q.y0) && std::isfinite(q.x1) &&
                      std::isfinite(q.y1) && std::isfinite(reach);
  for (std::uint32_t k = 0; k < p.class_count && finite; ++k)
    q.density.callback_max += joint ? p.joint.max[k] : density_bound(p.classes[k], q, reach);
  return Status::kOk;
}

/// Constant classes: their cumulative expected counts per depth-0 tile, as Classifier::enter computes them.
void constant_counts(const ClassQueryParams& p, const QueryParams& q, double counts[kMaxQueryClasses]) {
  const double area = q.tile_size * q.tile_size * q.scale;
  double sum = 0;
  for (std::uint32_t k = 0; k + 1 < p.class_count; ++k)
    counts[k] = (sum += density_or_zero(p.classes[k].constant)) * area;
}

/// The union's query into `out` (QueryPoint records or a CompactPoints) with each point's class into
/// `classes`, classed as it is written, in one piece. The cursor carries the class query's fingerprint
/// between calls and the union's while it runs.
template <class Output>
Status run_classed(const Tileset& tileset, const ClassQueryParams& p, const QueryParams& q,
                   const ClassDensities& densities, Classifier& classify, Output out, std::uint8_t* classes,
                   std::size_t capacity, std::size_t* written, QueryCursor* cursor, detail::Refusal& refuse) {
  const std::uint64_t fingerprint = query_fingerprint(p);
  if (cursor && cursor->started) {
    if (cursor->fingerprint != fingerprint) return refuse(QueryProblem::Kind::kCursorMismatch, "cursor");
    cursor->fingerprint = query_fingerprint(q);
  }
  std::uint64_t examined = 0;
  Status status;
  if (densities.all_constant) {
    double counts[kMaxQueryClasses];
    constant_counts(p, q, counts);
    const detail::ConstantClasses c{classes, counts, p.class_count - 1, Classifier::class_of_id, &classify};
    status = detail::query_classes_counted(tileset, q, out, c, capacity, written, cursor, &refuse.problem(),
                                           examined);
  } else {
    const detail::VaryingClasses c{classes,
                                   &densities.scratch,
                                   q.tile_size * q.tile_size * q.scale,
                                   p.class_count - 1,
                                   Classifier::class_ranks,
                                   Classifier::class_of_id,
                                   Classifier::class_points,
                                   Classifier::class_records,
                                   &classify,
                                   densities.one_grid ? &densities.images : nullptr};
    status = detail::query_classes_counted(tileset, q, out, c, capacity, written, cursor, &refuse.problem(),
                                           examined);
  }
  if (status != Status::kInvalidArgument && cursor) cursor->fingerprint = fingerprint;
  return status;
}

}  // namespace

Status query_classes(const Tileset& tileset, const ClassQueryParams& p, QueryPoint* out,
                     std::uint8_t* classes, std::size_t capacity, std::size_t* written, QueryCursor* cursor,
                     QueryProblem* problem) {
  detail::Refusal refuse(problem);
  ClassDensities densities;
  QueryParams q;
  if (prepare_union(tileset, p, written, densities, q, refuse) != Status::kOk)
    return Status::kInvalidArgument;
  if (capacity > 0 && !classes) return refuse(QueryProblem::Kind::kMissingArgument, "classes");
  Classifier classify(tileset, p, densities, q);
  return run_classed(tileset, p, q, densities, classify, out, classes, capacity, written, cursor, refuse);
}

Status query_classes_compact(const Tileset& tileset, const ClassQueryParams& p, const CompactPoints& out,
                             std::uint8_t* classes, std::size_t capacity, std::size_t* written,
                             QueryCursor* cursor, QueryProblem* problem) {
  detail::Refusal refuse(problem);
  ClassDensities densities;
  QueryParams q;
  if (prepare_union(tileset, p, written, densities, q, refuse) != Status::kOk)
    return Status::kInvalidArgument;
  if (detail::compact_refusal(tileset, q, out.keys != nullptr, refuse) != Status::kOk)
    return Status::kInvalidArgument;
  if (capacity > 0 && !out.xy) return refuse(QueryProblem::Kind::kMissingArgument, "out.xy");
  if (capacity > 0 && !classes) return refuse(QueryProblem::Kind::kMissingArgument, "classes");
  Classifier classify(tileset, p, densities, q);
  return run_classed(tileset, p, q, densities, classify, out, classes, capacity, written, cursor, refuse);
}

}  // namespace kdm
