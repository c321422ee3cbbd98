// Several classes in one query (kdm/runtime/class_query.h): the one-class query at the sum of the
// densities, then each emitted point's class from its threshold and the cumulative densities at its
// stable position.
#include "kdm/runtime/class_query.h"

#include <algorithm>
#include <cmath>

#include "class_densities.h"
#include "classifier.h"
#include "fingerprint.h"
#include "kdm/runtime/class_image_sums.h"
#include "query_counted.h"
#include "query_tables.h"

namespace kdm {

using detail::ClassDensities;
using detail::Classifier;
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
constexpr const char* kBatchCallbackNames[kMaxQueryClasses] = {
    "classes[0].batch_callback", "classes[1].batch_callback", "classes[2].batch_callback",
    "classes[3].batch_callback", "classes[4].batch_callback", "classes[5].batch_callback",
    "classes[6].batch_callback", "classes[7].batch_callback"};
constexpr const char* kKindNames[kMaxQueryClasses] = {"classes[0].kind", "classes[1].kind", "classes[2].kind",
                                                      "classes[3].kind", "classes[4].kind", "classes[5].kind",
                                                      "classes[6].kind", "classes[7].kind"};
constexpr const char* kCallbackMaxNames[kMaxQueryClasses] = {
    "classes[0].callback_max", "classes[1].callback_max", "classes[2].callback_max",
    "classes[3].callback_max", "classes[4].callback_max", "classes[5].callback_max",
    "classes[6].callback_max", "classes[7].callback_max"};
constexpr const char* kJointMaxNames[kMaxQueryClasses] = {"joint.max[0]", "joint.max[1]", "joint.max[2]",
                                                          "joint.max[3]", "joint.max[4]", "joint.max[5]",
                                                          "joint.max[6]", "joint.max[7]"};

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

}  // namespace

std::uint64_t query_fingerprint(const ClassQueryParams& p) {
  QueryParams q = p.query;
  q.density = QueryDensity{};
  detail::Fingerprint f(query_fingerprint(q) ^ 0x636c6173736573ull);  // "classes"
  f.add(p.class_count);
  f.add_pointer(reinterpret_cast<const void*>(p.joint.densities));
  f.add_pointer(reinterpret_cast<const void*>(p.joint.batch_densities));
  f.add_pointer(reinterpret_cast<const void*>(p.joint.bounds));
  f.add_pointer(p.joint.user);
  for (std::uint32_t k = 0; k < p.class_count && k < kMaxQueryClasses; ++k) f.add_double(p.joint.max[k]);
  f.add_pointer(p.image_sums);
  for (std::uint32_t k = 0; p.image_sums && k < p.image_sums->count(); ++k)
    f.add_pointer(p.image_sums->sum(k).values);
  for (std::uint32_t k = 0; k < p.class_count && k < kMaxQueryClasses; ++k) {
    const QueryDensity& d = p.classes[k];
    f.add(static_cast<std::uint64_t>(d.kind));
    f.add_double(d.constant), f.add_double(d.callback_max);
    f.add_pointer(d.image);
    f.add_pointer(reinterpret_cast<const void*>(d.callback));
    f.add_pointer(reinterpret_cast<const void*>(d.batch_callback));
    f.add_pointer(d.user);
    f.add_pointer(reinterpret_cast<const void*>(d.bounds));
  }
  return f.value();
}

namespace {

/// prepare_union for classes by their running sums' images (ClassQueryParams::image_sums): the union is the
/// one-class query at the last sum's image.
Status prepare_sums(const ClassQueryParams& p, ClassDensities& densities, QueryParams& q,
                    detail::Refusal& refuse) {
  using Kind = QueryProblem::Kind;
  const ClassImageSums& sums = *p.image_sums;
  if (sums.count() != p.class_count)  // value: the classes asked; limit: those the sums were built for
    return refuse(Kind::kBadDensity, "image_sums", p.class_count, sums.count());
  if (p.joint.densities || p.joint.batch_densities) return refuse(Kind::kBadDensity, "image_sums");
  for (std::uint32_t k = 0; k < p.class_count; ++k) {
    const DensityImageView& im = sums.sum(k);
    if (!detail::image_queryable(im) || !ImageSampler(&sums.sum(0)).same_grid(im))
      return refuse(Kind::kBadDensity, "image_sums");
  }
  densities.all_constant = false;
  densities.one_grid = true;
  densities.sums = &sums;
  densities.samplers[0] = ImageSampler(&sums.sum(0));
  densities.images.grid = &densities.samplers[0], densities.images.count = p.class_count;
  densities.images.cumulative = true;
  for (std::uint32_t k = 0; k < p.class_count; ++k)
    densities.images.values[k] = sums.sum(k).values, densities.images.sums[k] = &sums.sum(k);
  q = p.query;
  q.density = QueryDensity{};
  q.density.kind = QueryDensity::Kind::kImage;
  q.density.image = &sums.sum(p.class_count - 1);
  return Status::kOk;
}

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
  if (p.image_sums) return prepare_sums(p, densities, q, refuse);
  const bool joint = densities.joint = p.joint.densities || p.joint.batch_densities;
  if (p.joint.densities && p.joint.batch_densities)  // which one is meant is unclear
    return refuse(Kind::kBadDensity, "joint.batch_densities");
  for (std::uint32_t k = 0; k < p.class_count && joint; ++k) {
    if (!std::isfinite(p.joint.max[k])) return refuse(Kind::kNotFinite, kJointMaxNames[k], p.joint.max[k]);
    if (p.joint.max[k] < 0) return refuse(Kind::kNegative, kJointMaxNames[k], p.joint.max[k]);
    densities.all_constant = false;
  }
  // Every bound 0 would never call the function: max was left at its default, not meant as no points.
  if (joint && std::all_of(p.joint.max, p.joint.max + p.class_count, [](double m) { return m == 0; }))
    return refuse(Kind::kNotPositive, kJointMaxNames[0], 0.0);
  for (std::uint32_t k = 0; k < p.class_count && !joint; ++k) {
    const QueryDensity& d = p.classes[k];
    switch (d.kind) {
      case QueryDensity::Kind::kConstant:
        if (!std::isfinite(d.constant)) return refuse(Kind::kNotFinite, kConstantNames[k], d.constant);
        if (d.constant < 0) return refuse(Kind::kNegative, kConstantNames[k], d.constant);
        continue;
      case QueryDensity::Kind::kImage:
        if (!d.image || !detail::image_queryable(*d.image)) return refuse(Kind::kBadDensity, kImageNames[k]);
        densities.samplers[k] = ImageSampler(d.image);
        break;
      case QueryDensity::Kind::kCallback:
        if (!d.callback == !d.batch_callback)  // neither or both, named as a one-class query names them
          return refuse(Kind::kBadDensity, d.callback ? kBatchCallbackNames[k] : kCallbackNames[k]);
        if (!std::isfinite(d.callback_max))
          return refuse(Kind::kNotFinite, kCallbackMaxNames[k], d.callback_max);
        if (d.callback_max < 0) return refuse(Kind::kNegative, kCallbackMaxNames[k], d.callback_max);
        break;
      default:
        return refuse(Kind::kBadDensity, kKindNames[k], static_cast<double>(static_cast<int>(d.kind)));
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
    // Each finite, their sum need not be: named as the classes' (the union query would say density).
    if (!std::isfinite(q.density.constant)) return refuse(Kind::kNotFinite, "classes", q.density.constant);
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
    q.density.batch_callback = detail::sum_of_batches;
  else
    q.density.callback = joint      ? detail::sum_of_joint
                         : one_grid ? detail::sum_of_images
                                    : detail::sum_of_densities;
  if (one_grid) {
    densities.images.grid = &densities.samplers[0], densities.images.count = p.class_count;
    for (std::uint32_t k = 0; k < p.class_count; ++k) densities.images.values[k] = p.classes[k].image->values;
  }
  q.density.bounds = detail::sum_of_bounds;
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

/// The union's query over the tiles of `run` into `out` (QueryPoint records or a CompactPoints) with each
/// point's class into `classes`, classed as it is written, in one piece. The cursor carries the class
/// query's fingerprint between calls and the union's while it runs.
template <class Output>
Status run_classed(const Tileset& tileset, const ClassQueryParams& p, const QueryParams& q,
                   const ClassDensities& densities, Classifier& classify, Output out, std::uint8_t* classes,
                   std::size_t capacity, std::size_t* written, QueryCursor* cursor, detail::Refusal& refuse,
                   const detail::TileRun& run) {
  const std::uint64_t identity = detail::tileset_identity(tileset);  // as query_into mixes it in
  const std::uint64_t fingerprint = query_fingerprint(p) ^ identity;
  if (cursor && cursor->started) {
    if (cursor->fingerprint != fingerprint) return refuse(QueryProblem::Kind::kCursorMismatch, "cursor");
    cursor->fingerprint = query_fingerprint(q) ^ identity;
  }
  std::uint32_t reads = 0;  // densities read at each candidate: the bound on a call's work counts them
  if (densities.joint || densities.sums)
    reads = 1;
  else
    for (std::uint32_t k = 0; k < p.class_count; ++k)
      reads += p.classes[k].kind != QueryDensity::Kind::kConstant;
  std::uint64_t examined = detail::first_examined(q, true, reads);
  Status status;
  if (densities.all_constant) {
    double counts[kMaxQueryClasses];
    constant_counts(p, q, counts);
    const detail::ConstantClasses c{classes, counts, p.class_count - 1, Classifier::class_of_id, &classify};
    status = detail::query_classes_counted(tileset, q, out, c, capacity, written, cursor, &refuse.problem(),
                                           examined, run);
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
                                           examined, run);
  }
  if (status != Status::kInvalidArgument && cursor) cursor->fingerprint = fingerprint;
  return status;
}

}  // namespace

Status query_classes(const Tileset& tileset, const ClassQueryParams& p, QueryPoint* out,
                     std::uint8_t* classes, std::size_t capacity, std::size_t* written, QueryCursor* cursor,
                     QueryProblem* problem) {
  return detail::query_classes_run(tileset, p, out, classes, capacity, written, cursor, problem, {});
}

Status query_classes_compact(const Tileset& tileset, const ClassQueryParams& p, const CompactPoints& out,
                             std::uint8_t* classes, std::size_t capacity, std::size_t* written,
                             QueryCursor* cursor, QueryProblem* problem) {
  return detail::query_classes_run(tileset, p, out, classes, capacity, written, cursor, problem, {});
}

Status detail::query_classes_run(const Tileset& tileset, const ClassQueryParams& p, QueryPoint* out,
                                 std::uint8_t* classes, std::size_t capacity, std::size_t* written,
                                 QueryCursor* cursor, QueryProblem* problem, const TileRun& run) {
  detail::Refusal refuse(problem);
  ClassDensities densities;
  QueryParams q;
  if (prepare_union(tileset, p, written, densities, q, refuse) != Status::kOk)
    return Status::kInvalidArgument;
  if (capacity > 0 && !classes) return refuse(QueryProblem::Kind::kMissingArgument, "classes");
  Classifier classify(tileset, p, densities, q);
  return run_classed(tileset, p, q, densities, classify, out, classes, capacity, written, cursor, refuse,
                     run);
}

Status detail::query_classes_run(const Tileset& tileset, const ClassQueryParams& p, const CompactPoints& out,
                                 std::uint8_t* classes, std::size_t capacity, std::size_t* written,
                                 QueryCursor* cursor, QueryProblem* problem, const TileRun& run) {
  detail::Refusal refuse(problem);
  ClassDensities densities;
  QueryParams q;
  if (prepare_union(tileset, p, written, densities, q, refuse) != Status::kOk)
    return Status::kInvalidArgument;
  if (detail::compact_refusal(tileset, out.keys != nullptr, refuse) != Status::kOk)
    return Status::kInvalidArgument;
  if (capacity > 0 && !out.xy) return refuse(QueryProblem::Kind::kMissingArgument, "out.xy");
  if (capacity > 0 && !classes) return refuse(QueryProblem::Kind::kMissingArgument, "classes");
  Classifier classify(tileset, p, densities, q);
  return run_classed(tileset, p, q, densities, classify, out, classes, capacity, written, cursor, refuse,
                     run);
}

}  // namespace kdm
