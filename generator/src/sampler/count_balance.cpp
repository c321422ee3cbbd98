#include "sampler/count_balance.h"

#include <algorithm>
#include <cmath>

#include "kdm/runtime/check.h"

namespace kdm::gen {
namespace {

constexpr double kNegligibleStep = 0.003;  ///< coarse nodes: about 1% of a point spacing
constexpr double kMinImprovement = 0.02;   ///< stop when a step lowers the mismatch by less than this
/// Moves into frozen territory keep at least this share of the local spacing to every other point.
constexpr double kFrozenMinSpacing = 0.5;
constexpr double kMaxStep = 0.5;     ///< coarse nodes per iteration: the map stays smooth and one-to-one
constexpr double kTolerance = 1e-4;  ///< relative residual of the Poisson solve: flux to well under 1%

/// The particles of each coarse node at the start of a step (a counting sort), for the spacing test.
template <int D>
struct Buckets {
  const Grid<D>& g;
  std::array<double, D> scale;  ///< finest units to coarse, per axis
  std::vector<std::int64_t> first;
  std::vector<std::int32_t> members;

  Buckets(const Grid<D>& grid, const std::vector<Particle<D>>& particles,
          const std::array<double, D>& to_coarse)
      : g(grid),
        scale(to_coarse),
        first(static_cast<std::size_t>(grid.size()) + 1, 0),
        members(particles.size()) {
    std::vector<std::int64_t> cell(particles.size());
    for (std::size_t j = 0; j < particles.size(); ++j) ++first[(cell[j] = cell_of(particles[j].x)) + 1];
    for (std::size_t i = 1; i < first.size(); ++i) first[i] += first[i - 1];
    std::vector<std::int64_t> next(first.begin(), first.end() - 1);
    for (std::size_t j = 0; j < particles.size(); ++j)
      members[next[cell[j]]++] = static_cast<std::int32_t>(j);
  }

  std::int64_t cell_of(const Vec<D>& x) const {
    std::int64_t idx = 0;
    for (int k = 0; k < D; ++k)
      idx += std::clamp<std::int64_t>(static_cast<std::int64_t>(x[k] * scale[k]), 0, g.dims[k] - 1) *
             g.stride(k);
    return idx;
  }

  /// Whether a particle other than `self` lies within `radius` (finest units) of `x`. Particles move at
  /// most half a node per step, so the nodes within radius + 1/2 of x's node hold every candidate.
  bool any_within(const std::vector<Particle<D>>& particles, const Grid<D>& finest, const Vec<D>& x,
                  double radius, const Particle<D>* self) const {
    std::array<int, D> centre{}, offset{}, reach{}, side{};
    int cells = 1;
    for (int k = 0; k < D; ++k) {
      reach[k] = static_cast<int>(std::ceil(radius * scale[k] + 0.5));
      side[k] = 2 * reach[k] + 1;
      centre[k] = static_cast<int>(
          std::clamp<std::int64_t>(static_cast<std::int64_t>(x[k] * scale[k]), 0, g.dims[k] - 1));
      cells *= std::min(side[k], g.dims[k]);
    }
    for (int c = 0; c < cells; ++c) {
      std::int64_t idx = 0;
      bool inside = true;
      for (int k = 0, rest = c; k < D; ++k) {
        const int span = std::min(side[k], g.dims[k]);
        offset[k] = rest % span - (span == side[k] ? reach[k] : span / 2);
        rest /= span;
        int n = centre[k] + offset[k];
        if (g.torus)
          n = ((n % g.dims[k]) + g.dims[k]) % g.dims[k];
        else if (n < 0 || n >= g.dims[k])
          inside = false;
        idx += std::int64_t(n) * g.stride(k);
      }
      if (!inside) continue;
      for (std::int64_t m = first[idx]; m < first[idx + 1]; ++m) {
        const Particle<D>& q = particles[static_cast<std::size_t>(members[m])];
        if (&q == self) continue;
        double d2 = 0;
        for (int k = 0; k < D; ++k) {
          double d = std::abs(q.x[k] - x[k]);
          if (finest.torus) d = std::min(d, finest.dims[k] - d);
          d2 += d * d;
        }
        if (d2 < radius * radius) return true;
      }
    }
    return false;
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

/// Each node's 2D neighbours (axis k down, axis k up, ...; -1 past a box wall), worked out once.
template <int D>
std::vector<std::int64_t> neighbour_table(const Grid<D>& g) {
  std::vector<std::int64_t> table(static_cast<std::size_t>(g.size()) * 2 * D);
  for (std::int64_t i = 0; i < g.size(); ++i)
    for (int k = 0; k < D; ++k) {
      table[static_cast<std::size_t>(i) * 2 * D + 2 * k] = neighbour(g, i, k, -1);
      table[static_cast<std::size_t>(i) * 2 * D + 2 * k + 1] = neighbour(g, i, k, 1);
    }
  return table;
}

/// y = −Lψ for the grid Laplacian L (unit spacing; Neumann at box walls, periodic on a torus).
template <int D>
void minus_laplacian(const std::vector<std::int64_t>& neighbours, const std::vector<double>& x,
                     std::vector<double>& y) {
  for (std::size_t i = 0; i < x.size(); ++i) {
    double v = 0;
    for (int e = 0; e < 2 * D; ++e) {
      const std::int64_t j = neighbours[i * 2 * D + e];
      if (j >= 0) v += x[i] - x[static_cast<std::size_t>(j)];
    }
    y[i] = v;
  }
}

/// Solves Lψ = s by conjugate gradients on −L (symmetric, positive semi-definite; constants are its null
/// space, so `s` is made to sum to zero first), starting from `psi` (the last step's solution: each step
/// changes the counts a little).
template <int D>
void solve_poisson(const std::vector<std::int64_t>& neighbours, const std::vector<double>& s,
                   std::vector<double>& psi) {
  const std::size_t n = s.size();
  double mean = 0;
  for (double v : s) mean += v / static_cast<double>(n);
  std::vector<double> r(n), p(n), ap(n);
  minus_laplacian<D>(neighbours, psi, ap);
  double rr = 0, bb = 0;
  for (std::size_t i = 0; i < n; ++i) {
    r[i] = -(s[i] - mean) - ap[i];  // residual of −Lψ = −s at the starting ψ
    p[i] = r[i];
    rr += r[i] * r[i];
    bb += (s[i] - mean) * (s[i] - mean);
  }
  const int max_iterations = 4 * static_cast<int>(std::sqrt(static_cast<double>(n))) + 100;
  for (int it = 0; it < max_iterations && rr > kTolerance * kTolerance * bb; ++it) {
    minus_laplacian<D>(neighbours, p, ap);
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
}

}  // namespace

template <int D>
CountBalanceReport balance_counts(std::vector<Particle<D>>& particles, const DensityGrid<D>& finest,
                                  const DensityGrid<D>& source, int source_factor,
                                  const std::array<int, D>& coarse_dims,
                                  const CountBalanceSettings<D>& settings) {
  const double min_target = settings.min_target;
  KDM_CHECK(source_factor >= 1);
  Grid<D> g = finest.grid;
  std::array<double, D> scale;  // finest units to coarse: 1 / (finest nodes per coarse node)
  for (int k = 0; k < D; ++k) {
    KDM_CHECK(coarse_dims[k] >= 1 && std::int64_t(coarse_dims[k]) * source_factor <= finest.grid.dims[k]);
    KDM_CHECK(std::int64_t(source.grid.dims[k]) * source_factor == finest.grid.dims[k]);
    g.dims[k] = coarse_dims[k];
    scale[k] = double(coarse_dims[k]) / finest.grid.dims[k];
  }
  CountBalanceReport report;
  for (int k = 0; k < D; ++k) report.grid[k] = g.dims[k];
  const std::size_t nodes = static_cast<std::size_t>(g.size());
  auto to_coarse = [&](const Vec<D>& x) {
    Vec<D> c;
    for (int k = 0; k < D; ++k) c[k] = x[k] * scale[k];
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
    const NodeCorners<D> c(g, to_coarse(x));
    for (int j = 0; j < (1 << D); ++j) target[c.index[j]] += c.weight[j] * v;
    total_rho += v;
  }
  if (!(total_weight > 0) || !(total_rho > 0)) return report;
  for (double& t : target) t *= total_weight / total_rho;

  std::vector<double> count(nodes);
  auto bin = [&] {
    std::fill(count.begin(), count.end(), 0.0);
    for (const auto& p : particles) {
      const NodeCorners<D> c(g, to_coarse(p.x));
      for (int j = 0; j < (1 << D); ++j) count[c.index[j]] += c.weight[j] * p.weight();
    }
    double off = 0;
    for (std::size_t i = 0; i < nodes; ++i) off += std::abs(count[i] - target[i]);
    return off / total_weight;
  };

  report.mismatch_before = report.mismatch_after = bin();
  const std::vector<std::int64_t> neighbours = neighbour_table(g);
  std::vector<double> psi(nodes, 0.0);
  // Wholly inside the support of the finest density (a coarse level's support reaches a node further).
  auto inside_support = [&](const Vec<D>& x) {
    if (!settings.support) return finest.min_around(x) > 0;
    Vec<D> xs;
    for (int k = 0; k < D; ++k) xs[k] = x[k] * settings.support_scale;
    return settings.support->min_around(xs) > 0;
  };
  std::vector<double> rho_of(particles.size());   // ρ at each particle, kept as they move
  std::vector<char> inside_of(particles.size());  // and whether it lies wholly inside the support
  for (std::size_t j = 0; j < particles.size(); ++j)
    rho_of[j] = finest.at(particles[j].x), inside_of[j] = inside_support(particles[j].x);
  std::vector<double> surplus_at(nodes), lambda(nodes);
  std::vector<std::array<double, D>> flux(nodes);
  for (int it = 0; it < settings.max_iterations; ++it) {
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
    solve_poisson<D>(neighbours, surplus_at, psi);
    for (std::int64_t i = 0; i < g.size(); ++i)
      for (int k = 0; k < D; ++k) {
        const std::int64_t down = neighbours[static_cast<std::size_t>(i) * 2 * D + 2 * k],
                           up = neighbours[static_cast<std::size_t>(i) * 2 * D + 2 * k + 1];
        flux[i][k] = 0.5 * (psi[up >= 0 ? up : i] - psi[down >= 0 ? down : i]);
      }
    const std::vector<Particle<D>> before = particles;
    const Buckets<D> buckets(g, particles, scale);
    for (std::int32_t member : buckets.members) {  // node by node: the finest grid is read in order
      Particle<D>& p = particles[static_cast<std::size_t>(member)];
      const NodeCorners<D> c(g, to_coarse(p.x));
      Vec<D> f{};
      double l = 0;
      bool unresolved = false;
      for (int j = 0; j < (1 << D); ++j) {
        for (int k = 0; k < D; ++k) f[k] += c.weight[j] * flux[c.index[j]][k];
        l += c.weight[j] * lambda[c.index[j]];
        unresolved |= target[c.index[j]] < min_target;
      }
      const std::size_t j = static_cast<std::size_t>(member);
      const double rho_old = rho_of[j];
      const bool frozen = rho_old < settings.frozen_below * p.weight();
      if (unresolved || !(l > 0) || (frozen && !settings.move_frozen)) continue;
      Vec<D> u;
      double largest = 0;
      for (int k = 0; k < D; ++k) {
        u[k] = std::clamp(f[k] / l, -kMaxStep, kMaxStep);
        largest = std::max(largest, std::abs(u[k]));
      }
      if (largest < kNegligibleStep) continue;  // spares the density lookups where little is left to do
      Vec<D> x = p.x;
      for (int k = 0; k < D; ++k) {
        x[k] += u[k] / scale[k];
        if (!finest.grid.torus) {  // reflect at the walls, as refinement does
          const double m = finest.grid.dims[k];
          if (x[k] < 0) x[k] = std::min(-x[k], std::nextafter(m, 0.0));
          if (x[k] >= m) x[k] = std::max(0.0, 2 * m - x[k] - 1e-9);
        }
      }
      finest.grid.canonical(x);
      // Not into the fringe where interpolation fades to zero: kernels there are so wide that they freeze
      // where they land. A point already in it may still move towards denser places.
      const double rho_new = finest.at(x);
      const bool inside = inside_support(x);
      if (!(rho_new > 0) || !(inside || (!inside_of[j] && rho_new >= rho_old))) continue;
      if (rho_new < settings.frozen_below * p.weight()) {  // where no sweep will relax it
        if (!settings.move_frozen) continue;
        const double spacing = std::pow(settings.mass_per_point * p.weight() / rho_new, 1.0 / D);
        if (buckets.any_within(particles, finest.grid, x, kFrozenMinSpacing * spacing, &p)) continue;
      }
      p.x = x;
      rho_of[j] = rho_new, inside_of[j] = inside;
    }
    const double mismatch = bin();
    if (!(mismatch < report.mismatch_after)) {  // no longer helping: keep the better configuration
      particles = before;
      for (std::size_t j = 0; j < particles.size(); ++j)
        rho_of[j] = finest.at(particles[j].x), inside_of[j] = inside_support(particles[j].x);
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
                                              const DensityGrid<2>&, int, const std::array<int, 2>&,
                                              const CountBalanceSettings<2>&);
template CountBalanceReport balance_counts<3>(std::vector<Particle<3>>&, const DensityGrid<3>&,
                                              const DensityGrid<3>&, int, const std::array<int, 3>&,
                                              const CountBalanceSettings<3>&);

}  // namespace kdm::gen
