// Computational grids of the KDM model (paper §3): nodes at cell centres i + 1/2 in grid units
// (Δx = 1), axis 0 fastest in memory. A torus wraps every axis; a box reflects at its walls.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace kdm::gen {

template <int D>
using Vec = std::array<double, D>;

/// std::floor / std::ceil for |x| < 2^63, inline (baseline x86-64 has no rounding instruction, and the
/// library calls showed in profiles). Exact, so results do not change.
inline double floor_small(double x) {
  const double t = static_cast<double>(static_cast<std::int64_t>(x));
  return t > x ? t - 1 : t;
}
inline double ceil_small(double x) {
  const double t = static_cast<double>(static_cast<std::int64_t>(x));
  return t < x ? t + 1 : t;
}

template <int D>
struct Grid {
  std::array<int, D> dims{};
  bool torus = true;

  std::int64_t size() const {
    std::int64_t s = 1;
    for (int k = 0; k < D; ++k) s *= dims[k];
    return s;
  }
  std::int64_t stride(int axis) const {
    std::int64_t s = 1;
    for (int k = 0; k < axis; ++k) s *= dims[k];
    return s;
  }
  /// Maps a position into the domain: wraps on a torus; on a box returns false when outside [0, m).
  bool canonical(Vec<D>& x) const {
    for (int k = 0; k < D; ++k) {
      const double m = dims[k];
      if (x[k] >= 0 && x[k] < m) continue;  // the usual case, and a no-op below
      if (torus) {
        x[k] -= m * std::floor(x[k] / m);
        if (x[k] >= m) x[k] = 0;  // -tiny wraps to m in floating point
      } else if (!(x[k] >= 0 && x[k] < m)) {
        return false;
      }
    }
    return true;
  }
};

/// The 2^D nodes around x along each axis (flat offsets i0, i1) and x's fraction f between them: the one
/// rule for which nodes multilinear interpolation reads. Periodic on a torus, clamped at box walls.
/// x must be canonical (inside [0, m)), so the floor is in [-1, m - 1]: wrap or clamp without a division.
template <int D>
void bracket(const Grid<D>& grid, const Vec<D>& x, std::array<std::int64_t, D>& i0,
             std::array<std::int64_t, D>& i1, std::array<double, D>& f) {
  for (int k = 0; k < D; ++k) {
    const int m = grid.dims[k];
    const double u = x[k] - 0.5;
    const double fl = floor_small(u);
    f[k] = u - fl;
    std::int64_t a = static_cast<std::int64_t>(fl), b = a + 1;
    if (grid.torus) {
      if (a < 0) a += m;
      if (b >= m) b -= m;
    } else {
      if (a < 0) a = 0;
      if (b > m - 1) b = m - 1;
    }
    const std::int64_t s = grid.stride(k);
    i0[k] = a * s;
    i1[k] = b * s;
  }
}

/// The 2^D nodes multilinear interpolation at x reads (flat indices) and their weights, which sum to 1.
template <int D>
struct NodeCorners {
  std::array<std::int64_t, (1 << D)> index{};
  std::array<double, (1 << D)> weight{};

  NodeCorners(const Grid<D>& grid, const Vec<D>& x) {
    std::array<std::int64_t, D> i0{}, i1{};
    std::array<double, D> f{};
    bracket<D>(grid, x, i0, i1, f);
    for (int corner = 0; corner < (1 << D); ++corner) {
      double w = 1;
      std::int64_t idx = 0;
      for (int k = 0; k < D; ++k) {
        const bool hi = (corner >> k) & 1;
        w *= hi ? f[k] : 1 - f[k];
        idx += hi ? i1[k] : i0[k];
      }
      index[corner] = idx, weight[corner] = w;
    }
  }
};

/// The target density at one level of the pyramid, with multilinear interpolation between nodes.
template <int D>
struct DensityGrid {
  Grid<D> grid;
  std::vector<float> rho;

  /// ρ at position x (grid units). Periodic interpolation on a torus, clamped at box walls.
  double at(const Vec<D>& x) const {
    const NodeCorners<D> c(grid, x);
    double value = 0;
    for (int corner = 0; corner < (1 << D); ++corner) value += c.weight[corner] * rho[c.index[corner]];
    return value;
  }

  /// The smallest of the 2^D node values at(x) interpolates: > 0 when x lies wholly inside the density's
  /// support, not in the fringe where interpolation fades to zero.
  double min_around(const Vec<D>& x) const {
    const NodeCorners<D> c(grid, x);
    double lo = std::numeric_limits<double>::infinity();
    for (std::int64_t idx : c.index) lo = std::min<double>(lo, rho[idx]);
    return lo;
  }

  /// Starts fetching the nodes at(x) reads: on a grid larger than the caches, an update's first look at
  /// ρ otherwise waits for memory.
  void prefetch(const Vec<D>& x) const {
    std::array<std::int64_t, D> i0{}, i1{};
    std::array<double, D> f{};
    bracket<D>(grid, x, i0, i1, f);
    for (int corner = 0; corner < (1 << D); corner += 2) {  // each row's two nodes: one line, or two
      std::int64_t idx = 0;
      for (int k = 1; k < D; ++k) idx += ((corner >> k) & 1) ? i1[k] : i0[k];
      __builtin_prefetch(rho.data() + idx + i0[0]);
      __builtin_prefetch(rho.data() + idx + i1[0]);
    }
  }
};

}  // namespace kdm::gen
