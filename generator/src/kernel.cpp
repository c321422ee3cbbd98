#include "kernel.h"

namespace kdm::gen {

double truncated_factor_integral() {
  // Simpson's rule on [-kCut, kCut]; the integrand is smooth except for the kink at the cut (an endpoint).
  static const double value = [] {
    const int steps = 20000;
    const double e = kernel_edge_value(), h = 2 * kCut / steps;
    double sum = 0;
    for (int i = 0; i <= steps; ++i) {
      const double t = -kCut + i * h;
      const double f = std::max(0.0, std::exp(-(t / kKernelWidth) * (t / kKernelWidth)) - e);
      sum += f * (i == 0 || i == steps ? 1 : (i % 2 ? 4 : 2));
    }
    return sum * h / 3;
  }();
  return value;
}

void build_axis(AxisFactor& a, double x, double sigma, int m, bool torus, bool with_derivative) {
  const double reach = kCut * sigma;
  const std::int64_t lo = static_cast<std::int64_t>(std::ceil(x - 0.5 - reach));
  const std::int64_t hi = static_cast<std::int64_t>(std::floor(x - 0.5 + reach));
  const int len = static_cast<int>(std::max<std::int64_t>(0, hi - lo + 1));
  const double inv = 1.0 / (kKernelWidth * sigma);
  const double edge = kernel_edge_value();
  // Gaussian by recurrence: g(t0 + k h) = g(t0)·r_k, r_{k+1} = r_k·q, avoiding one exp per node.
  const double t0 = (lo + 0.5 - x) * inv, h = inv;
  double g = std::exp(-t0 * t0);
  double r = std::exp(-2 * t0 * h - h * h);
  const double q = std::exp(-2 * h * h);
  const double dscale = 2 * inv;  // d/dx φ((p - x)/s) = φ · 2 (p - x) / s^2 = φ · 2 t / s

  const bool direct = (torus && len <= m) || (!torus && lo >= 0 && hi < m);
  if (direct) {
    a.count = len;
    if (static_cast<int>(a.index.size()) < len) {
      a.index.resize(len);
      a.value.resize(len);
      a.deriv.resize(len);
    }
    std::int64_t idx = lo;  // direct on a torus means len <= m, so one wrap at most
    if (torus) {
      if (idx < 0) idx += m;
      if (idx >= m) idx -= m;
    }
    for (int k = 0; k < len; ++k) {
      const double t = t0 + k * h;
      const double v = g - edge;
      a.index[k] = static_cast<int>(idx);
      a.value[k] = v > 0 ? static_cast<float>(v) : 0.0f;
      a.deriv[k] = (with_derivative && v > 0) ? static_cast<float>(g * dscale * t) : 0.0f;
      if (++idx == m) idx = 0;
      g *= r;
      r *= q;
    }
    a.build_runs();
    return;
  }
  // Folded: accumulate every virtual node into its image inside [0, m).
  if (static_cast<int>(a.fold_value.size()) < m) {
    a.fold_value.assign(m, 0.0);
    a.fold_deriv.assign(m, 0.0);
  }
  a.fold_touched.clear();
  for (int k = 0; k < len; ++k) {
    const double t = t0 + k * h;
    const double gauss = g;
    const double v = gauss - edge;
    g *= r;
    r *= q;
    if (v <= 0) continue;
    std::int64_t i = lo + k;
    if (torus) {
      i = ((i % m) + m) % m;
    } else {
      const std::int64_t period = 2 * std::int64_t(m);
      i = ((i % period) + period) % period;
      if (i >= m) i = period - 1 - i;
    }
    if (a.fold_value[i] == 0) a.fold_touched.push_back(static_cast<int>(i));
    a.fold_value[i] += v;
    if (with_derivative) a.fold_deriv[i] += gauss * dscale * t;
  }
  std::sort(a.fold_touched.begin(), a.fold_touched.end());
  const int count = static_cast<int>(a.fold_touched.size());
  a.count = count;
  if (static_cast<int>(a.index.size()) < count) {
    a.index.resize(count);
    a.value.resize(count);
    a.deriv.resize(count);
  }
  for (int k = 0; k < count; ++k) {
    const int i = a.fold_touched[k];
    a.index[k] = i;
    a.value[k] = static_cast<float>(a.fold_value[i]);
    a.deriv[k] = static_cast<float>(a.fold_deriv[i]);
    a.fold_value[i] = 0;
    a.fold_deriv[i] = 0;
  }
  a.build_runs();
}

}  // namespace kdm::gen
