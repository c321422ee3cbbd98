#include "kernel.h"

#include "simd.h"

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

void axis_lanes(double x, double sigma, std::int64_t first, int count, std::int64_t lo, std::int64_t hi,
                bool with_derivative, float* v, float* dv) {
  const float inv = static_cast<float>(1.0 / (kKernelWidth * sigma));
  const float dscale = 2 * inv;  // d/dx φ((p - x)/s) = φ · 2 (p - x) / s^2 = φ · 2 t / s
  const float edge = static_cast<float>(kernel_edge_value());
  // t at node lo in double first (x may be thousands of nodes out); node lo + j then has t = a + j·inv,
  // so each value depends only on x, σ and the node, never on where the window starts. One exp per node
  // keeps the kernel smooth in x to float precision (a recurrence in float is not: its error grows with j
  // and jitters E at the 1e-6 level, visible in finite differences of E).
  const float a = static_cast<float>(((static_cast<double>(lo) + 0.5) - x) * (1.0 / (kKernelWidth * sigma)));
  const std::int32_t shift = static_cast<std::int32_t>(lo - first);
  const std::int32_t len = static_cast<std::int32_t>(hi - lo + 1);
  for (int q = 0; q < count; q += 4) {
    const I4 j = I4{q, q + 1, q + 2, q + 3} - shift;  // node first + q + l is node lo + j
    const F4 t = splat4(a) + __builtin_convertvector(j, F4) * inv;
    const F4 g = exp4(-(t * t));
    const F4 value = g - edge;
    const I4 keep = (j >= 0) & (j < len) & (value > 0);
    store4(v + q, reinterpret_cast<F4>(reinterpret_cast<I4>(value) & keep));
    const F4 d = with_derivative ? g * dscale * t : splat4(0);
    store4(dv + q, reinterpret_cast<F4>(reinterpret_cast<I4>(d) & keep));
  }
}

void build_axis(AxisFactor& a, double x, double sigma, int m, bool torus, bool with_derivative) {
  std::int64_t lo, hi;
  axis_reach(x, sigma, lo, hi);
  const int len = static_cast<int>(std::max<std::int64_t>(0, hi - lo + 1));
  const int room = round_up4(len);
  if (static_cast<int>(a.value.size()) < room) {
    a.index.resize(room);
    a.value.resize(room);
    a.deriv.resize(room);
  }
  axis_lanes(x, sigma, lo, len, lo, hi, with_derivative, a.value.data(), a.deriv.data());

  const bool direct = (torus && len <= m) || (!torus && lo >= 0 && hi < m);
  if (direct) {
    a.count = len;
    std::int64_t idx = lo;  // direct on a torus means len <= m, so one wrap at most
    if (torus) {
      if (idx < 0) idx += m;
      if (idx >= m) idx -= m;
    }
    for (int k = 0; k < len; ++k) {
      a.index[k] = static_cast<int>(idx);
      if (++idx == m) idx = 0;
    }
    a.build_runs();
    return;
  }
  // Folded: accumulate every virtual node into its image inside [0, m).
  if (static_cast<int>(a.fold_value.size()) < m) {
    a.fold_value.assign(m, 0.0f);
    a.fold_deriv.assign(m, 0.0f);
  }
  a.fold_touched.clear();
  for (int k = 0; k < len; ++k) {
    if (a.value[k] <= 0) continue;
    std::int64_t i = lo + k;
    if (torus) {
      i = ((i % m) + m) % m;
    } else {
      const std::int64_t period = 2 * std::int64_t(m);
      i = ((i % period) + period) % period;
      if (i >= m) i = period - 1 - i;
    }
    if (a.fold_value[i] == 0) a.fold_touched.push_back(static_cast<int>(i));
    a.fold_value[i] += a.value[k];
    a.fold_deriv[i] += a.deriv[k];
  }
  std::sort(a.fold_touched.begin(), a.fold_touched.end());
  const int count = static_cast<int>(a.fold_touched.size());
  a.count = count;
  for (int k = 0; k < count; ++k) {
    const int i = a.fold_touched[k];
    a.index[k] = i;
    a.value[k] = a.fold_value[i];
    a.deriv[k] = a.fold_deriv[i];
    a.fold_value[i] = 0;
    a.fold_deriv[i] = 0;
  }
  a.build_runs();
}

}  // namespace kdm::gen
