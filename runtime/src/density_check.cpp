// Density callbacks checked as queries read them (density_check.h).
#include "kdm/runtime/density_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace kdm {
namespace {

/// `v` in the fewest significant digits that read back as `v` (into a buffer of 32), without an exponent
/// from 10^-4 to 10^15 (50, not 5e+01).
const char* shortest(double v, char (&text)[32]) {
  const bool plain = std::fabs(v) >= 1e-4 && std::fabs(v) < 1e15;
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, v);
    if (std::strtod(text, nullptr) == v && !(plain && std::strchr(text, 'e'))) break;
  }
  return text;  // NaN never reads back equal: printed as "nan" at 17 digits, the same text
}

}  // namespace

bool DensityCheck::routes(const QueryDensity& density) const {
  return density.user == this && (!density.callback || density.callback == &DensityCheck::call) &&
         (!density.batch_callback || density.batch_callback == &DensityCheck::call_batch);
}

Status DensityCheck::wrap(QueryDensity* density) {
  if (!density) return Status::kInvalidArgument;
  if (density->kind != QueryDensity::Kind::kCallback) return Status::kOk;
  if (routes(*density)) {  // wrapped already: only its bound may have changed
    inner_.callback_max = density->callback_max;
    return Status::kOk;
  }
  const bool same = density->callback == inner_.callback &&
                    density->batch_callback == inner_.batch_callback && density->bounds == inner_.bounds &&
                    density->user == inner_.user;
  if (wrapping_ && (classes_ || !same)) return Status::kInvalidArgument;
  inner_ = *density, wrapping_ = true;
  density->user = this;
  density->callback = inner_.callback ? &DensityCheck::call : nullptr;
  density->batch_callback = inner_.batch_callback ? &DensityCheck::call_batch : nullptr;
  density->bounds = inner_.bounds ? &DensityCheck::call_bounds : nullptr;
  return Status::kOk;
}

Status DensityCheck::wrap(JointClassDensity* joint, std::uint32_t class_count) {
  if (!joint || class_count < 1 || class_count > kMaxQueryClasses) return Status::kInvalidArgument;
  if (joint->user == this && (!joint->densities || joint->densities == &DensityCheck::call_joint) &&
      (!joint->batch_densities || joint->batch_densities == &DensityCheck::call_joint_batch)) {
    if (class_count != classes_) return Status::kInvalidArgument;
    std::copy(joint->max, joint->max + kMaxQueryClasses, inner_joint_.max);  // wrapped: only its bounds
    return Status::kOk;
  }
  const bool same = classes_ == class_count && joint->densities == inner_joint_.densities &&
                    joint->batch_densities == inner_joint_.batch_densities &&
                    joint->bounds == inner_joint_.bounds && joint->user == inner_joint_.user;
  if (wrapping_ && !same) return Status::kInvalidArgument;
  inner_joint_ = *joint, classes_ = class_count, wrapping_ = true;
  joint->user = this;
  joint->densities = inner_joint_.densities ? &DensityCheck::call_joint : nullptr;
  joint->batch_densities = inner_joint_.batch_densities ? &DensityCheck::call_joint_batch : nullptr;
  joint->bounds = inner_joint_.bounds ? &DensityCheck::call_joint_bounds : nullptr;
  return Status::kOk;
}

void DensityCheck::record(const DensityFinding& finding) {
  int none = 0;  // the first finding is kept: later threads' leave it alone
  if (!state_.compare_exchange_strong(none, 1, std::memory_order_acq_rel)) return;
  finding_ = finding;
  state_.store(2, std::memory_order_release);
}

void DensityCheck::check(double value, double x, double y, double limit, int cls) {
  double seen = largest_.load(std::memory_order_relaxed);
  while (value > seen && value < HUGE_VAL &&
         !largest_.compare_exchange_weak(seen, value, std::memory_order_relaxed)) {
  }
  if (density_value_fits(value, limit)) return;
  DensityFinding f;
  f.value = value, f.x = x, f.y = y, f.limit = limit, f.cls = cls;
  record(f);
}

bool DensityCheck::check_bounds(double value, double x, double y, double lo, double hi, const double (&r)[4],
                                double limit, int cls) {
  if (!(value < lo * (1 - 1e-9) || value > hi * (1 + 1e-9)) || !density_value_fits(value, HUGE_VAL))
    return false;
  DensityFinding f;
  f.kind = DensityFinding::Kind::kBounds;
  f.value = value, f.x = x, f.y = y, f.limit = limit, f.lo = lo, f.hi = hi, f.cls = cls;
  std::copy(r, r + 4, f.rect);
  record(f);
  return true;
}

namespace {

/// The corners, edge middles and centre of [x0, x1] × [y0, y1], where bounds are checked.
void nine_points(double x0, double y0, double x1, double y1, double (&x)[9], double (&y)[9]) {
  for (int i = 0; i < 9; ++i) {
    x[i] = i % 3 == 0 ? x0 : i % 3 == 1 ? 0.5 * (x0 + x1) : x1;
    y[i] = i / 3 == 0 ? y0 : i / 3 == 1 ? 0.5 * (y0 + y1) : y1;
  }
}

}  // namespace

double DensityCheck::call(void* user, double x, double y) {
  auto* self = static_cast<DensityCheck*>(user);
  const double v = self->inner_.callback(self->inner_.user, x, y);
  self->check(v, x, y, self->inner_.callback_max);
  return v;
}

void DensityCheck::call_batch(void* user, std::size_t n, const double* x, const double* y, double* out) {
  auto* self = static_cast<DensityCheck*>(user);
  self->inner_.batch_callback(self->inner_.user, n, x, y, out);
  for (std::size_t i = 0; i < n; ++i) self->check(out[i], x[i], y[i], self->inner_.callback_max);
}

void DensityCheck::call_joint(void* user, double x, double y, double* values) {
  auto* self = static_cast<DensityCheck*>(user);
  const JointClassDensity& j = self->inner_joint_;
  j.densities(j.user, x, y, values);
  for (std::uint32_t k = 0; k < self->classes_; ++k) self->check(values[k], x, y, j.max[k], int(k));
}

void DensityCheck::call_joint_batch(void* user, std::size_t n, const double* x, const double* y,
                                    double* values) {
  auto* self = static_cast<DensityCheck*>(user);
  const JointClassDensity& j = self->inner_joint_;
  j.batch_densities(j.user, n, x, y, values);
  for (std::uint32_t k = 0; k < self->classes_; ++k)
    for (std::size_t i = 0; i < n; ++i) self->check(values[k * n + i], x[i], y[i], j.max[k], int(k));
}

void DensityCheck::call_joint_bounds(void* user, double x0, double y0, double x1, double y1, double* lo,
                                     double* hi) {
  auto* self = static_cast<DensityCheck*>(user);
  const JointClassDensity& j = self->inner_joint_;
  j.bounds(j.user, x0, y0, x1, y1, lo, hi);
  double x[9], y[9], v[kMaxQueryClasses * 9];  // class k's value at point i in v[k · 9 + i]
  nine_points(x0, y0, x1, y1, x, y);
  if (j.densities) {
    double one[kMaxQueryClasses];
    for (int i = 0; i < 9; ++i) {
      j.densities(j.user, x[i], y[i], one);
      for (std::uint32_t k = 0; k < self->classes_; ++k) v[k * 9 + i] = one[k];
    }
  } else {
    j.batch_densities(j.user, 9, x, y, v);
  }
  const double r[4] = {x0, y0, x1, y1};
  for (std::uint32_t k = 0; k < self->classes_; ++k) {
    if (!(lo[k] <= hi[k])) continue;  // NaN or crossed bounds: the query ignores them
    for (int i = 0; i < 9; ++i) {
      self->check(v[k * 9 + i], x[i], y[i], j.max[k], int(k));
      if (self->check_bounds(v[k * 9 + i], x[i], y[i], lo[k], hi[k], r, j.max[k], int(k))) return;
    }
  }
}

void DensityCheck::call_bounds(void* user, double x0, double y0, double x1, double y1, double* lo,
                               double* hi) {
  auto* self = static_cast<DensityCheck*>(user);
  const QueryDensity& d = self->inner_;
  d.bounds(d.user, x0, y0, x1, y1, lo, hi);
  if (!(*lo <= *hi)) return;  // NaN or crossed bounds: the query ignores them
  // The density at the rectangle's corners, edge middles and centre must lie within them.
  double x[9], y[9], v[9];
  nine_points(x0, y0, x1, y1, x, y);
  if (d.callback)
    for (int i = 0; i < 9; ++i) v[i] = d.callback(d.user, x[i], y[i]);
  else
    d.batch_callback(d.user, 9, x, y, v);
  const double r[4] = {x0, y0, x1, y1};
  for (int i = 0; i < 9; ++i) {
    self->check(v[i], x[i], y[i], d.callback_max);
    if (self->check_bounds(v[i], x[i], y[i], *lo, *hi, r, d.callback_max, -1)) return;
  }
}

bool DensityCheck::failed(DensityFinding* finding) const {
  if (state_.load(std::memory_order_acquire) != 2) return false;
  if (finding) *finding = finding_;
  return true;
}

std::size_t DensityCheck::describe(char* text, std::size_t size) const {
  DensityFinding f;
  char line[320], n0[32], n1[32], n2[32], n3[32], n4[32], n5[32], n6[32], n7[32], n8[32];
  int n;
  if (!failed(&f)) {
    n = std::snprintf(line, sizeof line, "no bad density value");
    const double most = largest();
    if (!classes_ && most >= 0 && most < 0.5 * inner_.callback_max)
      n += std::snprintf(line + n, sizeof line - std::size_t(n),
                         "; the largest value read, %s, is under half of callback_max %s: a tighter bound "
                         "makes queries faster",
                         shortest(most, n0), shortest(inner_.callback_max, n1));
  } else {
    char whose[40] = "density";  // or a joint density's class
    if (f.cls >= 0) std::snprintf(whose, sizeof whose, "joint density's class %d", f.cls);
    if (f.kind == DensityFinding::Kind::kBounds) {
      n = std::snprintf(
          line, sizeof line, "%s bounds gave [%s, %s] over (%s, %s) to (%s, %s), but %s is %s at (%s, %s)",
          whose, shortest(f.lo, n0), shortest(f.hi, n1), shortest(f.rect[0], n2), shortest(f.rect[1], n3),
          shortest(f.rect[2], n4), shortest(f.rect[3], n5), f.cls >= 0 ? "it" : "the density",
          shortest(f.value, n6), shortest(f.x, n7), shortest(f.y, n8));
    } else {
      n = std::snprintf(line, sizeof line, "%s %s %s at (%s, %s)", whose,
                        f.cls >= 0 ? "was" : "callback returned", shortest(f.value, n0), shortest(f.x, n1),
                        shortest(f.y, n2));
      if (f.value > f.limit && f.value < HUGE_VAL && n > 0 && std::size_t(n) < sizeof line)
        n += std::snprintf(line + n, sizeof line - std::size_t(n), ", above its bound %s %s",
                           f.cls >= 0 ? "max" : "callback_max", shortest(f.limit, n3));
    }
  }
  if (size) std::snprintf(text, size, "%s", line);
  return n > 0 ? std::size_t(n) : 0;
}

void DensityCheck::reset() {
  wrapping_ = false, classes_ = 0;
  largest_.store(-1, std::memory_order_relaxed);
  state_.store(0, std::memory_order_release);
}

}  // namespace kdm
