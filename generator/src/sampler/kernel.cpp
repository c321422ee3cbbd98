#include "sampler/kernel.h"

#include "platform/huge_pages.h"
#include "platform/parallel.h"
#include "sampler/lanes_wide.h"
#include "sampler/simd.h"

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

void KernelTable::prepare(double s) {
  if (s == sigma && !coef.empty()) return;
  sigma = s;
  coef.assign(std::size_t(kPieces) * kCoefs * kLanes, 0.0f);
  const double inv = 1.0 / (kKernelWidth * s), h = 1.0 / kPieces;
  for (int p = 0; p < kPieces; ++p) {
    for (int lane = 0; lane < kLanes; ++lane) {
      // Node c + j seen from x = c + u: G(u) = exp(-t^2), t = (j + 0.5 - u)·inv, dG/du = 2 inv t G.
      const int j = lane - kHalf;
      const double t0 = (j + 0.5 - p * h) * inv, t1 = (j + 0.5 - (p + 1) * h) * inv;
      const double g0 = std::exp(-t0 * t0), g1 = std::exp(-t1 * t1);
      const double d0 = 2 * inv * t0 * g0 * h, d1 = 2 * inv * t1 * g1 * h;
      const double c[4] = {g0, d0, 3 * (g1 - g0) - 2 * d0 - d1, 2 * (g0 - g1) + d0 + d1};
      const double e[3] = {c[1] / h, 2 * c[2] / h, 3 * c[3] / h};
      float* out = coef.data() + std::size_t(p) * kCoefs * kLanes + lane;
      for (int k = 0; k < 4; ++k) out[k * kLanes] = static_cast<float>(c[k]);
      for (int k = 0; k < 3; ++k) out[(4 + k) * kLanes] = static_cast<float>(e[k]);
    }
  }
}

void axis_lanes(double x, double sigma, std::int64_t first, int count, std::int64_t lo, std::int64_t hi,
                bool with_derivative, float* v, float* dv, const KernelTable* table, wide::Isa isa) {
  const float edge = static_cast<float>(kernel_edge_value());
  // Lanes are numbered from the node c = floor(x) whose cell holds x (u = x - c in [0, 1)), in double
  // first: x may be thousands of nodes out. Each value then depends only on x, σ and the node, never on
  // the window it is written into.
  const double cell = floor_small(x), u = x - cell;
  const std::int64_t c = static_cast<std::int64_t>(cell);
  const int rounded = round_up4(count);
  const std::int32_t j0 = static_cast<std::int32_t>(first - c);  // lane k is node c + j0 + k
  const std::int32_t jlo = static_cast<std::int32_t>(lo - c), jhi = static_cast<std::int32_t>(hi - c);
  const bool tabulated =
      table && j0 >= -KernelTable::kHalf && j0 + rounded <= KernelTable::kLanes - KernelTable::kHalf;
  if (tabulated) {
    const double pu = u * KernelTable::kPieces;
    const int piece = std::min(static_cast<int>(pu), KernelTable::kPieces - 1);
    const F4 s = splat4(static_cast<float>(pu - piece));
    const float* row = table->coef.data() + std::size_t(piece) * KernelTable::kCoefs * KernelTable::kLanes +
                       (j0 + KernelTable::kHalf);
    constexpr int L = KernelTable::kLanes;
    if (table->isa != wide::Isa::kNone && wide::fits_width(rounded)) {
      wide::tabulated_axis(table->isa, row, L, rounded, s[0], j0, jlo, jhi, edge, with_derivative, v, dv);
      return;
    }
    I4 j = I4{0, 1, 2, 3} + j0;
    for (int q = 0; q < rounded; q += 4, j += 4) {
      const float* r = row + q;
      const F4 g = ((load4(r + 3 * L) * s + load4(r + 2 * L)) * s + load4(r + L)) * s + load4(r);
      const F4 value = g - edge;
      const I4 keep = (j > jlo - 1) & (jhi + 1 > j) & (value > 0);
      store4(v + q, reinterpret_cast<F4>(reinterpret_cast<I4>(value) & keep));
      const F4 d =
          with_derivative ? (load4(r + 6 * L) * s + load4(r + 5 * L)) * s + load4(r + 4 * L) : splat4(0);
      store4(dv + q, reinterpret_cast<F4>(reinterpret_cast<I4>(d) & keep));
    }
    return;
  }
  const float inv = static_cast<float>(1.0 / (kKernelWidth * sigma));
  const float dscale = 2 * inv;  // d/dx φ((p - x)/s) = φ · 2 (p - x) / s^2 = φ · 2 t / s
  const float a = static_cast<float>((0.5 - u) * (1.0 / (kKernelWidth * sigma)));  // t at node c
  if (isa != wide::Isa::kNone && wide::fits_width(rounded)) {
    wide::computed_axis(isa, rounded, a, inv, dscale, j0, jlo, jhi, edge, with_derivative, v, dv);
    return;
  }
  I4 j = I4{0, 1, 2, 3} + j0;
  for (int q = 0; q < rounded; q += 4, j += 4) {
    const F4 t = splat4(a) + __builtin_convertvector(j, F4) * inv;
    const F4 g = exp4(-(t * t));
    const F4 value = g - edge;
    const I4 keep = (j > jlo - 1) & (jhi + 1 > j) & (value > 0);
    store4(v + q, reinterpret_cast<F4>(reinterpret_cast<I4>(value) & keep));
    const F4 d = with_derivative ? g * dscale * t : splat4(0);
    store4(dv + q, reinterpret_cast<F4>(reinterpret_cast<I4>(d) & keep));
  }
}

void build_axis(AxisFactor& a, double x, double sigma, int m, bool torus, bool with_derivative,
                const KernelTable* table, bool runs, wide::Isa isa) {
  std::int64_t lo, hi;
  axis_reach(x, sigma, lo, hi);
  const int len = static_cast<int>(std::max<std::int64_t>(0, hi - lo + 1));
  const int room = std::max(round_up4(len), CachedFootprint<2>::kLanes);
  if (static_cast<int>(a.value.size()) < room) {
    a.index.resize(room);
    a.value.resize(room);
    a.deriv.resize(room);
  }
  axis_lanes(x, sigma, lo, len, lo, hi, with_derivative, a.value.data(), a.deriv.data(), table, isa);

  const bool direct = (torus && len <= m) || (!torus && lo >= 0 && hi < m);
  if (direct) {
    a.count = len;
    if (lo >= 0 && hi < m) {
      for (int k = 0; k < len; ++k) a.index[k] = static_cast<int>(lo) + k;
    } else {
      std::int64_t idx = lo;  // direct on a torus means len <= m, so one wrap at most
      if (idx < 0) idx += m;
      if (idx >= m) idx -= m;
      for (int k = 0; k < len; ++k) {
        a.index[k] = static_cast<int>(idx);
        if (++idx == m) idx = 0;
      }
    }
    if (runs) a.build_runs();
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
  if (runs) a.build_runs();
}

template <int D>
void FootprintCache<D>::reserve(std::size_t n) {
  if (n <= capacity_) return;
  entries_.reset();
  size_ = capacity_ = 0;
  entries_.reset(static_cast<CachedFootprint<D>*>(
      ::operator new (n * sizeof(CachedFootprint<D>), std::align_val_t{alignof(CachedFootprint<D>)})));
  // Faulted in 512 times less often, and, touched by every update in an order unrelated to its layout,
  // kinder to the TLB (docs/design.md §2.9).
  advise_huge_pages(entries_.get(), n * sizeof(CachedFootprint<D>));
  capacity_ = n;
}

template <int D>
void FootprintCache<D>::reset(std::size_t n, int threads) {
  reserve(n);
  CachedFootprint<D>* entries = entries_.get();
  const std::int64_t count = static_cast<std::int64_t>(n);
  // A few thousand entries are set faster than a sleeping team wakes up.
  parallel_for(count, threads, count >= 4096,
               [&](std::int64_t j) { new (entries + j) CachedFootprint<D>(); });
  size_ = n;
}

template class FootprintCache<2>;
template class FootprintCache<3>;

}  // namespace kdm::gen
