#include "sampler/count_balance.h"

#include <algorithm>
#include <cmath>

#include "kdm/runtime/check.h"

namespace kdm::gen {
namespace {

constexpr int kMaxIterations = 12;
constexpr double kMinImprovement = 0.02;  ///< stop when a step lowers the mismatch by less than this
constexpr double kMaxStep = 0.5;          ///< coarse nodes per iteration: the map stays smooth and one-to-one
constexpr double kTolerance = 1e-4;       ///< relative residual of the Poisson solve: flux to well under 1%

/// Multilinear (cloud-in-cell) weights of position `x` (coarse units) on the 2^D surrounding nodes.
/// A torus wraps; a box folds the outside node onto the edge node, so no weight leaves the grid.
template <int D>
struct Corners {
  std::array<std::int64_t, (1 << D)> index{};
  std::array<double, (1 << D)> weight{};

  Corners(const Grid<D>& g, const Vec<D>& x) {
    std::array<std::int64_t, D> lo{}, hi{};
    std::array<double, D> f{};
    for (int k = 0; k < D; ++k) {
      const double t = x[k] - 0.5;
      const double t0 = std::floor(t);
      f[k] = t - t0;
      std::int64_t i0 = static_cast<std::int64_t>(t0), i1 = i0 + 1;
      const std::int64_t m = g.dims[k];
      if (g.torus) {
        i0 = (i0 % m + m) % m, i1 = (i1 % m + m) % m;
      } else {
        i0 = std::clamp<std::int64_t>(i0, 0, m - 1), i1 = std::clamp<std::int64_t>(i1, 0, m - 1);
      }
      lo[k] = i0 * g.stride(k), hi[k] = i1 * g.stride(k);
    }
    for (int c = 0; c < (1 << D); ++c) {
      double w = 1;
      std::int64_t idx = 0;
      for (int k = 0; k < D; ++k) {
        const bool up = (c >> k) & 1;
        w *= up ? f[k] : 1 - f[k];
        idx += up ? hi[k] : lo[k];
      }
      index[c] = idx, weight[c] = w;
    }
  }
};

/// The node one step along `axis` (dir = ±1), or -1 past a box wall.
template <int D>
std::int64_t neighbour(const Grid<D>& g, std::int64_t i, int axis, int dir) {
  const std::int64_t s = g.stride(axis), m = g.dims[axis];
  const std::int64_t c = (i / s) % m;
  const std::int64_t n = c + dir;
  if (n >= 0 && n < m) return i + dir * s;
  if (!g.torus) return -1;
  return i + (n < 0 ? (m - 1) : -(m - 1)) * s;
}

/// y = −Lψ for the grid Laplacian L (unit spacing; Neumann at box walls, periodic on a torus).
template <int D>
void minus_laplacian(const Grid<D>& g, const std::vector<double>& x, std::vector<double>& y) {
  for (std::int64_t i = 0; i < g.size(); ++i) {
    double v = 0;
    for (int k = 0; k < D; ++k)
      for (int dir : {-1, 1}) {
        const std::int64_t j = neighbour(g, i, k, dir);
        if (j >= 0) v += x[i] - x[j];
      }
    y[i] = v;
  }
}

/// Solves Lψ = s by conjugate gradients on −L (symmetric, positive semi-definite; constants are its null
/// space, so `s` is made to sum to zero first). Starts from zero, so ψ has no constant component.
template <int D>
std::vector<double> solve_poisson(const Grid<D>& g, std::vector<double> s) {
  const std::size_t n = s.size();
  double mean = 0;
  for (double v : s) mean += v / static_cast<double>(n);
  std::vector<double> psi(n, 0.0), r(n), p(n), ap(n);
  double rr = 0, bb = 0;
  for (std::size_t i = 0; i < n; ++i) {
    r[i] = -(s[i] - mean);  // residual of −Lψ = −s at ψ = 0
    p[i] = r[i];
    rr += r[i] * r[i];
  }
  bb = rr;
  const int max_iterations = 4 * static_cast<int>(std::sqrt(static_cast<double>(n))) + 100;
  for (int it = 0; it < max_iterations && rr > kTolerance * kTolerance * bb; ++it) {
    minus_laplacian(g, p, ap);
    double pap = 0;
    for (std::size_t i = 0; i < n; ++i) pap += p[i] * ap[i];
    if (!(pap > 0)) break;
    const double alpha = rr / pap;
    double next = 0;
    for (std::size_t i = 0; i < n; ++i) {
      psi[i] += alpha * p[i];
      r[i] -= alpha * ap[i];
      next += r[i] * r[i];
    }
    const double beta = next / rr;
    rr = next;
    for (std::size_t i = 0; i < n; ++i) p[i] = r[i] + beta * p[i];
  }
  return psi;
}

}  // namespace

template <int D>
CountBalanceReport balance_counts(std::vector<Particle<D>>& particles, const DensityGrid<D>& finest,
                                  const DensityGrid<D>& source, int source_factor, int factor,
                                  double min_target) {
  KDM_CHECK(source_factor >= 1 && factor >= source_factor);
  Grid<D> g = finest.grid;
  for (int k = 0; k < D; ++k) {
    KDM_CHECK(finest.grid.dims[k] % factor == 0);
    KDM_CHECK(std::int64_t(source.grid.dims[k]) * source_factor == finest.grid.dims[k]);
    g.dims[k] = finest.grid.dims[k] / factor;
  }
  CountBalanceReport report;
  for (int k = 0; k < D; ++k) report.grid[k] = g.dims[k];
  const std::size_t nodes = static_cast<std::size_t>(g.size());
  const double scale = 1.0 / factor;
  auto to_coarse = [&](const Vec<D>& x) {
    Vec<D> c;
    for (int k = 0; k < D; ++k) c[k] = x[k] * scale;
    return c;
  };
  // The target is binned exactly as the points are (each source node's mass at its centre, spread over
  // the coarse nodes around it), so a set that follows ρ matches it whatever ρ's curvature.
  std::vector<double> target(nodes, 0.0);
  double total_weight = 0, total_rho = 0;
  for (const auto& p : particles) total_weight += p.weight();
  for (std::int64_t i = 0; i < source.grid.size(); ++i) {
    const float v = source.rho[static_cast<std::size_t>(i)];
    if (!(v > 0)) continue;
    Vec<D> x;
    std::int64_t rest = i;
    for (int k = 0; k < D; ++k) {
      x[k] = (rest % source.grid.dims[k] + 0.5) * source_factor;
      rest /= source.grid.dims[k];
    }
    const Corners<D> c(g, to_coarse(x));
    for (int j = 0; j < (1 << D); ++j) target[c.index[j]] += c.weight[j] * v;
    total_rho += v;
  }
  if (!(total_weight > 0) || !(total_rho > 0)) return report;
  for (double& t : target) t *= total_weight / total_rho;

  std::vector<double> count(nodes);
  auto bin = [&] {
    std::fill(count.begin(), count.end(), 0.0);
    for (const auto& p : particles) {
      const Corners<D> c(g, to_coarse(p.x));
      for (int j = 0; j < (1 << D); ++j) count[c.index[j]] += c.weight[j] * p.weight();
    }
    double off = 0;
    for (std::size_t i = 0; i < nodes; ++i) off += std::abs(count[i] - target[i]);
    return off / total_weight;
  };

  report.mismatch_before = report.mismatch_after = bin();
  std::vector<double> surplus_at(nodes), lambda(nodes);
  std::vector<std::array<double, D>> flux(nodes);
  for (int it = 0; it < kMaxIterations; ++it) {
    double surplus = 0, resolved = 0;
    for (std::size_t i = 0; i < nodes; ++i) {
      const bool in = target[i] >= min_target;
      surplus_at[i] = in ? count[i] - target[i] : 0.0;
      lambda[i] = in ? std::max(count[i], target[i]) : 0.0;
      surplus += surplus_at[i], resolved += in;
    }
    if (!(resolved > 0)) break;
    for (std::size_t i = 0; i < nodes; ++i)
      if (target[i] >= min_target) surplus_at[i] -= surplus / resolved;  // what the resolved part holds
    // ∇·(λu) = count − target with λu = ∇ψ, ∇²ψ = count − target: the smallest smooth flux that
    // carries the surplus to where points are missing (points leave regions with too many).
    const std::vector<double> psi = solve_poisson(g, surplus_at);
    for (std::int64_t i = 0; i < g.size(); ++i)
      for (int k = 0; k < D; ++k) {
        const std::int64_t up = neighbour(g, i, k, 1), down = neighbour(g, i, k, -1);
        flux[i][k] = 0.5 * (psi[up >= 0 ? up : i] - psi[down >= 0 ? down : i]);
      }
    const std::vector<Particle<D>> before = particles;
    for (auto& p : particles) {
      const Corners<D> c(g, to_coarse(p.x));
      Vec<D> f{};
      double l = 0;
      bool unresolved = false;
      for (int j = 0; j < (1 << D); ++j) {
        for (int k = 0; k < D; ++k) f[k] += c.weight[j] * flux[c.index[j]][k];
        l += c.weight[j] * lambda[c.index[j]];
        unresolved |= target[c.index[j]] < min_target;
      }
      if (unresolved || !(l > 0)) continue;
      Vec<D> x = p.x;
      for (int k = 0; k < D; ++k) {
        const double u = std::clamp(f[k] / l, -kMaxStep, kMaxStep);
        x[k] += u * factor;
        if (!finest.grid.torus) {  // reflect at the walls, as refinement does
          const double m = finest.grid.dims[k];
          if (x[k] < 0) x[k] = std::min(-x[k], std::nextafter(m, 0.0));
          if (x[k] >= m) x[k] = std::max(0.0, 2 * m - x[k] - 1e-9);
        }
      }
      finest.grid.canonical(x);
      if (finest.at(x) > 0) p.x = x;
    }
    const double mismatch = bin();
    if (!(mismatch < report.mismatch_after)) {  // no longer helping: keep the better configuration
      particles = before;
      bin();
      break;
    }
    const bool converged = mismatch > (1 - kMinImprovement) * report.mismatch_after;
    report.mismatch_after = mismatch;
    report.iterations = it + 1;
    if (converged) break;
  }
  return report;
}

template CountBalanceReport balance_counts<2>(std::vector<Particle<2>>&, const DensityGrid<2>&,
                                              const DensityGrid<2>&, int, int, double);
template CountBalanceReport balance_counts<3>(std::vector<Particle<3>>&, const DensityGrid<3>&,
                                              const DensityGrid<3>&, int, int, double);

}  // namespace kdm::gen
