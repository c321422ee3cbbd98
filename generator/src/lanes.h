// The passes of Algorithm 1 (Fattal 2011, chain.h) over a contiguous footprint (kernel.h): each row is
// whole lane vectors over contiguous memory. The common widths get the lane count N at compile time, so
// a row is straight-line code; N = 0 takes any width. Every node is evaluated as in the general passes:
// R ± p·v in float, the sign of R with the kernel in it for eq. 7's gradient.
#pragma once

#include <array>
#include <type_traits>

#include "grid.h"
#include "kernel.h"
#include "simd.h"

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

template <int N>
inline int row_width(int width) {
  return N > 0 ? 4 * N : width;
}

/// Removes the kernel, returning Σ(|R_before| - |R_after|) and eq. 7's gradient; R_before goes to `out`.
template <int N, int D, class Gradient>
double remove(float* R, const Grid<D>& grid, const Footprint<D>& fp, Gradient& gradient, float* out) {
  const float *v = fp.row_value.data(), *dv = fp.row_deriv.data();
  const int width = row_width<N>(fp.width);
  F4 e = splat4(0);
  std::array<F4, D> g{};
  fp.for_each_row(grid, [&](std::int64_t base, double p, const std::array<double, D>& pd) {
    const F4 pf = splat4(static_cast<float>(p));
    float* row = R + base + fp.start;
    F4 sx = splat4(0), sg = splat4(0);
    for (int a = 0; a < width; a += 4) {
      const F4 r = load4(row + a), va = load4(v + a);
      const F4 rn = r - pf * va;
      sx += signed_by(r, load4(dv + a));
      sg += signed_by(r, va);
      e += abs4(r) - abs4(rn);
      store4(out + a, r);
      store4(row + a, rn);
    }
    out += width;
    g[0] += pf * sx;
    for (int k = 1; k < D; ++k) g[k] += splat4(static_cast<float>(pd[k])) * sg;
  });
  for (int k = 0; k < D; ++k) gradient[k] = sum4(g[k]);
  return sum4(e);
}

/// For a kernel not in R: Σ(|R + K| - |R|) and the gradient at the new configuration.
template <int N, int D, class Gradient>
double added(const float* R, const Grid<D>& grid, const Footprint<D>& fp, Gradient& gradient) {
  const float *v = fp.row_value.data(), *dv = fp.row_deriv.data();
  const int width = row_width<N>(fp.width);
  F4 e = splat4(0);
  std::array<F4, D> g{};
  fp.for_each_row(grid, [&](std::int64_t base, double p, const std::array<double, D>& pd) {
    const F4 pf = splat4(static_cast<float>(p));
    const float* row = R + base + fp.start;
    F4 sx = splat4(0), sg = splat4(0);
    for (int a = 0; a < width; a += 4) {
      const F4 r = load4(row + a), va = load4(v + a);
      const F4 rn = r + pf * va;
      sx += signed_by(rn, load4(dv + a));
      sg += signed_by(rn, va);
      e += abs4(rn) - abs4(r);
    }
    g[0] += pf * sx;
    for (int k = 1; k < D; ++k) g[k] += splat4(static_cast<float>(pd[k])) * sg;
  });
  for (int k = 0; k < D; ++k) gradient[k] = sum4(g[k]);
  return sum4(e);
}

template <int N, int D>
void add(float* R, const Grid<D>& grid, const Footprint<D>& fp, float sign) {
  const float* v = fp.row_value.data();
  const int width = row_width<N>(fp.width);
  fp.for_each_row(grid, [&](std::int64_t base, double p, const std::array<double, D>&) {
    const F4 pf = splat4(sign * static_cast<float>(p));
    float* row = R + base + fp.start;
    for (int a = 0; a < width; a += 4) store4(row + a, load4(row + a) + pf * load4(v + a));
  });
}

template <int N, int D>
void restore(float* R, const Grid<D>& grid, const Footprint<D>& fp, const float* in) {
  const int width = row_width<N>(fp.width);
  fp.for_each_row(grid, [&](std::int64_t base, double, const std::array<double, D>&) {
    float* row = R + base + fp.start;
    for (int a = 0; a < width; a += 4) store4(row + a, load4(in + a));
    in += width;
  });
}

}  // namespace kdm::gen::lanes
