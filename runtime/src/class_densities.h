// Internal: the classes' densities of a class query (kdm/runtime/class_query.h), read as query_points reads
// a one-class density, and the union's density and bounds the class query runs the one-class query with.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "density_bounds.h"
#include "image_sampler.h"
#include "kdm/runtime/check.h"
#include "kdm/runtime/class_image_sums.h"
#include "kdm/runtime/class_query.h"
#include "kdm/runtime/tileset.h"
#include "query_counted.h"

namespace kdm::detail {

/// The classes' densities, read as query_points reads a one-class density, so that a class's values and
/// their running sums are the very numbers the one-class queries compare.
struct ClassDensities {
  const ClassQueryParams* params = nullptr;
  ImageSampler samplers[kMaxQueryClasses];
  bool all_constant = true;
  bool one_grid = false;  ///< every class an image on class 0's texels (sum_of_images)
  bool batch = false;     ///< a class read in batches (sum_of_batches), or the joint density
  bool joint = false;     ///< the joint density gives every class's (ClassQueryParams::joint)
  /// The images of the classes' running sums (ClassQueryParams::image_sums), else null: then one_grid,
  /// samplers[0] reads them and the union's density is the last sum's image.
  const ClassImageSums* sums = nullptr;
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
    for (std::uint32_t k = 0; k < params->class_count; ++k)
      if (j.max[k] == 0) v[k] = 0;  // a class bounded by 0 has no points, as a callback class's
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
        sums[k][i] = (k > 0 ? sums[k - 1][i] : 0.0) + (j.max[k] == 0 ? 0.0 : density_or_zero(v[k * n + i]));
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
      if (sums)
        sum = ImageSampler::blend(images.values[k], t);
      else
        sum += joint      ? density_or_zero(v[k])
               : one_grid ? ImageSampler::blend(images.values[k], t)
                          : at(k, x, y);
      if (TilesetShape::emits(threshold, sum * area)) return static_cast<std::uint8_t>(k);
    }
    return static_cast<std::uint8_t>(last);
  }
  /// Bounds of the classes' running sums over [x0, x1] × [y0, y1] into lo[k], hi[k] (classes 0 … k's
  /// summed density): the sums of bounds(), or the sums' own images' bounds.
  void cumulative_bounds(double x0, double y0, double x1, double y1, double* lo, double* hi) const {
    if (sums) {
      for (std::uint32_t k = 0; k < params->class_count; ++k) {
        const DensityImageView& im = sums->sum(k);
        lo[k] = im.min_over(x0, y0, x1, y1), hi[k] = im.max_over(x0, y0, x1, y1);
      }
      return;
    }
    bounds(x0, y0, x1, y1, lo, hi);
    for (std::uint32_t k = 1; k < params->class_count; ++k) lo[k] += lo[k - 1], hi[k] += hi[k - 1];
  }
};

// The union's density (QueryDensity::callback) from separate densities and from a joint one: the classes'
// running sums, left in the scratch for the sink to class the candidate.
inline double sum_of_densities(void* user, double x, double y) {
  const auto& c = *static_cast<const ClassDensities*>(user);
  double sum = 0;
  for (std::uint32_t k = 0; k < c.params->class_count; ++k) c.scratch.cumulative[k] = sum += c.at(k, x, y);
  c.scratch.x = x, c.scratch.y = y;
  return sum;
}
/// The union's density (QueryDensity::batch_callback) when a class, or the joint density, is read in
/// batches: the classes' running sums at the n positions (ClassDensities::sums_at), left in the scratch's
/// batch for the sink to class the positions read.
inline void sum_of_batches(void* user, std::size_t n, const double* x, const double* y, double* out) {
  KDM_CHECK(n >= 1 && n <= kDensityBatch);  // the scratch holds one batch
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
inline double sum_of_images(void* user, double x, double y) {
  const auto& c = *static_cast<const ClassDensities*>(user);
  const ImageSampler::Texels t = c.samplers[0].texels(x, y);
  double sum = 0;
  for (std::uint32_t k = 0; k < c.params->class_count; ++k)
    c.scratch.cumulative[k] = sum += ImageSampler::blend(c.params->classes[k].image->values, t);
  c.scratch.x = x, c.scratch.y = y;
  return sum;
}
inline double sum_of_joint(void* user, double x, double y) {
  const auto& c = *static_cast<const ClassDensities*>(user);
  double v[kMaxQueryClasses], sum = 0;
  c.joint_at(x, y, v);
  for (std::uint32_t k = 0; k < c.params->class_count; ++k)
    c.scratch.cumulative[k] = sum += density_or_zero(v[k]);
  c.scratch.x = x, c.scratch.y = y;
  return sum;
}

/// The union's bounds (QueryDensity::bounds): the sum of the classes'.
inline void sum_of_bounds(void* user, double x0, double y0, double x1, double y1, double* lo, double* hi) {
  const auto& c = *static_cast<const ClassDensities*>(user);
  double l[kMaxQueryClasses], h[kMaxQueryClasses];
  c.bounds(x0, y0, x1, y1, l, h);
  *lo = *hi = 0;
  for (std::uint32_t k = 0; k < c.params->class_count; ++k) *lo += l[k], *hi += h[k];
}

}  // namespace kdm::detail
