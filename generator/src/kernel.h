// The KDM kernel (paper eq. 1–2): w σ^-d Φ(|x - x_j| / σ) with Φ(r) = exp(-(2r/3)^2) and
// σ = (ρ(x_j) / w)^(-1/d), so its amplitude is ρ(x_j) and its mass w·∫Φ.
//
// We use the separable form Φ(r) = Π_k φ(r_k), φ(t) = exp(-(t/1.5)^2), and cut each factor off smoothly
// at |t| = kCut·σ (φ minus its value there, clamped at 0). The product is radially symmetric to within
// the 1% cut level, exact to evaluate on any grid, and lets a footprint be built from d short 1D arrays.
// Walls fold those arrays: a torus wraps indices, a box reflects them, so mass is conserved either way.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "grid.h"

namespace kdm::gen {

inline constexpr double kKernelWidth = 1.5;  // Φ(r) = exp(-(r / 1.5)^2), paper §3
inline constexpr double kCut = 3.2;          // footprint half-width in units of σ

/// φ's value at the cut, subtracted so the truncated kernel is continuous.
inline double kernel_edge_value() {
  return std::exp(-(kCut / kKernelWidth) * (kCut / kKernelWidth));
}

/// ∫ of the truncated 1D factor over t in units of σ; the kernel's mass is w·J^d.
double truncated_factor_integral();

/// One axis of a footprint: grid indices and the factor (and its derivative w.r.t. the kernel centre).
struct AxisFactor {
  std::vector<int> index;
  std::vector<float> value;
  std::vector<float> deriv;
  int count = 0;
  /// The indices as runs of consecutive nodes (usually one, two where a torus wraps), so inner loops
  /// run over contiguous memory: run k covers index[run_offset[k] .. +run_length[k]).
  std::vector<int> run_offset, run_length;
  void build_runs() {
    run_offset.clear();
    run_length.clear();
    for (int k = 0; k < count; ++k) {
      if (k == 0 || index[k] != index[k - 1] + 1) {
        run_offset.push_back(k);
        run_length.push_back(0);
      }
      ++run_length.back();
    }
  }
  std::vector<double> fold_value, fold_deriv;  // scratch for folding
  std::vector<int> fold_touched;
};

/// Fills `a` for a kernel centred at `x` (grid units) with scale `sigma` on an axis of `m` nodes.
void build_axis(AxisFactor& a, double x, double sigma, int m, bool torus, bool with_derivative);

/// A kernel's footprint on a grid: amplitude times the product of the axis factors.
template <int D>
struct Footprint {
  std::array<AxisFactor, D> axes;
  double amplitude = 0;

  void build(const Grid<D>& grid, const Vec<D>& x, double sigma, double amp, bool with_derivative) {
    amplitude = amp;
    for (int k = 0; k < D; ++k) build_axis(axes[k], x[k], sigma, grid.dims[k], grid.torus, with_derivative);
  }

  /// Calls row(base, P, Pd) for every row along axis 0: `base` is the flat index of the row's axis-0
  /// origin, P the product of amplitude and the outer factors, Pd[k] (k >= 1) the same with factor k
  /// replaced by its derivative.
  template <class RowFn>
  void for_each_row(const Grid<D>& grid, RowFn&& row) const {
    if constexpr (D == 2) {
      const std::int64_t s1 = grid.dims[0];
      const AxisFactor& ay = axes[1];
      for (int b = 0; b < ay.count; ++b) {
        const double p = amplitude * ay.value[b];
        std::array<double, D> pd{};
        pd[1] = amplitude * ay.deriv[b];
        row(ay.index[b] * s1, p, pd);
      }
    } else {
      static_assert(D == 3, "kdm supports dimensions 2 and 3");
      const std::int64_t s1 = grid.dims[0], s2 = std::int64_t(grid.dims[0]) * grid.dims[1];
      const AxisFactor &ay = axes[1], &az = axes[2];
      for (int c = 0; c < az.count; ++c) {
        for (int b = 0; b < ay.count; ++b) {
          const double p = amplitude * ay.value[b] * az.value[c];
          std::array<double, D> pd{};
          pd[1] = amplitude * ay.deriv[b] * az.value[c];
          pd[2] = amplitude * ay.value[b] * az.deriv[c];
          row(az.index[c] * s2 + ay.index[b] * s1, p, pd);
        }
      }
    }
  }
};

}  // namespace kdm::gen
