// The passes of Algorithm 1 (Fattal 2011, chain.h) over a contiguous footprint (kernel.h): each row is
// whole lane vectors over contiguous memory. The common widths get the lane count N at compile time, so
// a row is straight-line code; N = 0 takes any width. Every node is evaluated as in the general passes:
// R ± p·v in float, the sign of R with the kernel in it for eq. 7's gradient.
#pragma once

#include <array>
#include <type_traits>

#include "sampler/grid.h"
#include "sampler/kernel.h"
#include "sampler/simd.h"

namespace kdm::gen::lanes {

template <class F>
decltype(auto) by_width(int width, F&& f) {
  switch (width) {
    case 8:
      return f(std::integral_constant<int, 2>{});
    case 12:
      return f(std::integral_constant<int, 3>{});
    case 16:
      return f(std::integral_constant<int, 4>{});
    default:
      return f(std::integral_constant<int, 0>{});
  }
}

/// Calls row(base, p, pd) for every row of a contiguous footprint: `base` the flat index of its window,
/// p and pd[k] as in Footprint::for_each_row, rounded to float. Everything it reads is hoisted into
/// locals, so stores through R inside `row` cannot force reloads. Always inlined, so that the AVX-512
/// passes (lanes_wide.cpp) get their row bodies inlined too: a function of the baseline target can be
/// inlined into an AVX-512 one, but the AVX-512 body cannot be inlined into a baseline one.
template <int D, class RowFn>
__attribute__((always_inline)) inline void rows(const Grid<D>& grid, const Footprint<D>& fp, RowFn&& row) {
  const double amp = fp.amplitude;
  const std::int64_t s1 = grid.dims[0], start = fp.start;
  const AxisFactor& ay = fp.axes[1];
  const int ny = ay.count;
  const int* iy = ay.index.data();
  const float *vy = ay.value.data(), *dy = ay.deriv.data();
  if constexpr (D == 2) {
    for (int b = 0; b < ny; ++b)
      row(iy[b] * s1 + start, static_cast<float>(amp * vy[b]),
          std::array<float, D>{0, static_cast<float>(amp * dy[b])});
  } else {
    static_assert(D == 3, "kdm supports dimensions 2 and 3");
    const std::int64_t s2 = s1 * grid.dims[1];
    const AxisFactor& az = fp.axes[2];
    const int nz = az.count;
    const int* iz = az.index.data();
    const float *vz = az.value.data(), *dz = az.deriv.data();
    for (int c = 0; c < nz; ++c)
      for (int b = 0; b < ny; ++b)
        row(iz[c] * s2 + iy[b] * s1 + start, static_cast<float>(amp * vy[b] * vz[c]),
            std::array<float, D>{0, static_cast<float>(amp * dy[b] * vz[c]),
                                 static_cast<float>(amp * vy[b] * dz[c])});
  }
}

/// The footprint's axis-0 window as lane vectors: held in registers when N is known.
template <int N>
struct Window {
  static constexpr int kVectors = N > 0 ? N : 1;
  F4 v[kVectors], dv[kVectors];
  const float *pv, *pdv;
  int width;
  template <int D>
  explicit Window(const Footprint<D>& fp)
      : pv(fp.row_value.data()), pdv(fp.row_deriv.data()), width(N > 0 ? 4 * N : fp.width) {
    if constexpr (N > 0)
      for (int q = 0; q < N; ++q) v[q] = load4(pv + 4 * q), dv[q] = load4(pdv + 4 * q);
  }
  F4 value(int q) const {
    if constexpr (N > 0) return v[q];
    return load4(pv + 4 * q);
  }
  F4 deriv(int q) const {
    if constexpr (N > 0) return dv[q];
    return load4(pdv + 4 * q);
  }
};

/// Removes the kernel (kRemove: R -= K, R_before kept in `saved`), returning Σ(|R_before| - |R_after|) and
/// eq. 7's gradient; or, for a kernel not in R (!kRemove, nothing written), Σ(|R + K| - |R|) and the
/// gradient at the new configuration. Four-lane sums (Numerics::kOriginal), any window (N = 0: its width at
/// run time). One pass seen from either side: the kernel is in R `with` and not `without`.
template <int N, bool kRemove, int D, class Gradient>
double measure(std::conditional_t<kRemove, float*, const float*> R, const Grid<D>& grid,
               const Footprint<D>& fp, Gradient& gradient, float* saved) {
  const Window<N> w(fp);
  float* __restrict out = saved;
  F4 e = splat4(0);
  std::array<F4, D> g{};
  rows(grid, fp, [&](std::int64_t base, float p, const std::array<float, D>& pd) {
    const F4 pf = splat4(p);
    auto* __restrict row = R + base;
    F4 sx = splat4(0), sg = splat4(0);
    for (int q = 0; 4 * q < w.width; ++q) {
      const F4 r = load4(row + 4 * q), va = w.value(q);
      const F4 rn = kRemove ? r - pf * va : r + pf * va;
      const F4 with = kRemove ? r : rn, without = kRemove ? rn : r;
      sx += signed_by(with, w.deriv(q));
      sg += signed_by(with, va);
      e += abs4(with) - abs4(without);
      if constexpr (kRemove) {
        store4(out + 4 * q, r);
        store4(row + 4 * q, rn);
      }
    }
    if constexpr (kRemove) out += w.width;
    g[0] += pf * sx;
    for (int k = 1; k < D; ++k) g[k] += splat4(pd[k]) * sg;
  });
  for (int k = 0; k < D; ++k) gradient[k] = sum4(g[k]);
  return sum4(e);
}

// Per-lane sums: each of the window's 4N lanes keeps its own energy and gradient sums across rows, added up
// in one fixed order at the end (lane vectors in order, then sum4). The sums then do not depend on how many
// lanes a machine's vectors hold, so the 16-lane passes (lanes_wide.h) give these bits exactly.

template <int N>
inline double sum_lanes(const F4 (&v)[N]) {
  F4 t = v[0];
  for (int q = 1; q < N; ++q) t += v[q];
  return sum4(t);
}

/// measure() with per-lane sums, for windows of 4N = 8, 12 or 16 nodes.
template <int N, bool kRemove, int D, class Gradient>
double measure_per_lane(std::conditional_t<kRemove, float*, const float*> R, const Grid<D>& grid,
                        const Footprint<D>& fp, Gradient& gradient, float* saved) {
  static_assert(N > 0, "per-lane sums need the window's width at compile time");
  const Window<N> w(fp);
  float* __restrict out = saved;
  F4 e[N] = {}, g[D][N] = {};
  rows(grid, fp, [&](std::int64_t base, float p, const std::array<float, D>& pd) {
    const F4 pf = splat4(p);
    auto* __restrict row = R + base;
    for (int q = 0; q < N; ++q) {
      const F4 r = load4(row + 4 * q), va = w.value(q);
      const F4 rn = kRemove ? r - pf * va : r + pf * va;
      const F4 with = kRemove ? r : rn, without = kRemove ? rn : r;
      g[0][q] += pf * signed_by(with, w.deriv(q));
      const F4 sv = signed_by(with, va);
      for (int k = 1; k < D; ++k) g[k][q] += splat4(pd[k]) * sv;
      e[q] += abs4(with) - abs4(without);
      if constexpr (kRemove) {
        store4(out + 4 * q, r);
        store4(row + 4 * q, rn);
      }
    }
    if constexpr (kRemove) out += 4 * N;
  });
  for (int k = 0; k < D; ++k) gradient[k] = sum_lanes<N>(g[k]);
  return sum_lanes<N>(e);
}

template <int N, int D>
void add(float* R, const Grid<D>& grid, const Footprint<D>& fp, float sign) {
  const Window<N> w(fp);
  rows(grid, fp, [&](std::int64_t base, float p, const std::array<float, D>&) {
    const F4 pf = splat4(sign * p);
    float* __restrict row = R + base;
    for (int q = 0; 4 * q < w.width; ++q) store4(row + 4 * q, load4(row + 4 * q) + pf * w.value(q));
  });
}

template <int N, int D>
void restore(float* R, const Grid<D>& grid, const Footprint<D>& fp, const float* saved) {
  const int width = N > 0 ? 4 * N : fp.width;
  const float* __restrict in = saved;
  rows(grid, fp, [&](std::int64_t base, float, const std::array<float, D>&) {
    float* __restrict row = R + base;
    for (int a = 0; a < width; a += 4) store4(row + a, load4(in + a));
    in += width;
  });
}

}  // namespace kdm::gen::lanes
