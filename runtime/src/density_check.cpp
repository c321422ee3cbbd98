// Density callbacks checked as queries read them (density_check.h).
#include "kdm/runtime/density_check.h"

#include <cstdio>
#include <cstdlib>

namespace kdm {
namespace {

/// `v` in the fewest significant digits that read back as `v` (into a buffer of 32).
const char* shortest(double v, char (&text)[32]) {
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, v);
    if (std::strtod(text, nullptr) == v) break;
  }
  return text;  // NaN never reads back equal: printed as "nan" at 17 digits, the same text
}

}  // namespace

QueryDensity DensityCheck::wrap(const QueryDensity& density) {
  if (density.kind != QueryDensity::Kind::kCallback) return density;
  inner_ = density;
  QueryDensity wrapped = density;
  wrapped.user = this;
  wrapped.callback = density.callback ? &DensityCheck::call : nullptr;
  wrapped.batch_callback = density.batch_callback ? &DensityCheck::call_batch : nullptr;
  wrapped.bounds = density.bounds ? &DensityCheck::call_bounds : nullptr;
  return wrapped;
}

void DensityCheck::check(double value, double x, double y) {
  if (density_value_fits(value, inner_.callback_max)) return;
  int none = 0;  // the first finding is kept: later threads' leave it alone
  if (!state_.compare_exchange_strong(none, 1, std::memory_order_acq_rel)) return;
  finding_ = DensityFinding{value, x, y, inner_.callback_max};
  state_.store(2, std::memory_order_release);
}

double DensityCheck::call(void* user, double x, double y) {
  auto* self = static_cast<DensityCheck*>(user);
  const double v = self->inner_.callback(self->inner_.user, x, y);
  self->check(v, x, y);
  return v;
}

void DensityCheck::call_batch(void* user, std::size_t n, const double* x, const double* y, double* out) {
  auto* self = static_cast<DensityCheck*>(user);
  self->inner_.batch_callback(self->inner_.user, n, x, y, out);
  for (std::size_t i = 0; i < n; ++i) self->check(out[i], x[i], y[i]);
}

void DensityCheck::call_bounds(void* user, double x0, double y0, double x1, double y1, double* lo,
                               double* hi) {
  const auto* self = static_cast<const DensityCheck*>(user);
  self->inner_.bounds(self->inner_.user, x0, y0, x1, y1, lo, hi);
}

bool DensityCheck::failed(DensityFinding* finding) const {
  if (state_.load(std::memory_order_acquire) != 2) return false;
  if (finding) *finding = finding_;
  return true;
}

std::size_t DensityCheck::describe(char* text, std::size_t size) const {
  DensityFinding f;
  char line[200], value[32], x[32], y[32], limit[32];
  int n;
  if (!failed(&f)) {
    n = std::snprintf(line, sizeof line, "no bad density value");
  } else {
    n = std::snprintf(line, sizeof line, "density callback returned %s at (%s, %s)", shortest(f.value, value),
                      shortest(f.x, x), shortest(f.y, y));
    if (f.value > f.limit && f.value < HUGE_VAL && n > 0 && std::size_t(n) < sizeof line)
      n += std::snprintf(line + n, sizeof line - std::size_t(n), ", above its bound callback_max %s",
                         shortest(f.limit, limit));
  }
  if (size) std::snprintf(text, size, "%s", line);
  return n > 0 ? std::size_t(n) : 0;
}

void DensityCheck::reset() {
  state_.store(0, std::memory_order_release);
}

}  // namespace kdm
