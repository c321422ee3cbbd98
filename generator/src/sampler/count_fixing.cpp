#include "sampler/count_fixing.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace kdm::gen {
namespace {

/// Sets stale[j] for every kernel j whose footprint may share a node with kernel `gone`'s, their reaches
/// adding up to reach[j] + reach[gone] nodes. On a box too: the torus distance is at most the straight
/// one, and a kernel folded at a wall stays within its reach of its centre. Centres are stored by axis so
/// the loop runs in vector lanes.
template <int D>
void mark_overlapping(const Grid<D>& g, const std::array<std::vector<double>, D>& centres,
                      const std::vector<double>& reach, std::size_t gone, std::vector<char>& stale) {
  const std::size_t count = stale.size();
  for (std::size_t j = 0; j < count; ++j) {
    bool near = true;
    for (int k = 0; k < D; ++k) {
      const double d = std::fabs(centres[k][j] - centres[k][gone]);
      near &= std::min(d, g.dims[k] - d) <= reach[j] + reach[gone];
    }
    stale[j] |= near;
  }
}

}  // namespace

// Each term of the sum is off by at most u(|r| + 2k), and a float sum of at most `nodes` terms by
// γ_nodes Σ|term| (Higham, Accuracy and Stability of Numerical Algorithms, §4.2); Σk is the footprint's
// mass, and Σ|term| at most that plus the terms' own rounding.
template <int D>
double removal_rounding_bound(const Footprint<D>& fp, double max_abs_r) {
  constexpr double u = 0x1p-24;  // float's unit roundoff
  double nodes = 1, mass = fp.amplitude;
  for (int k = 0; k < D; ++k) {
    const bool window = k == 0 && fp.contiguous;
    const int count = window ? fp.width : fp.axes[k].count;
    const float* value = window ? fp.row_value.data() : fp.axes[k].value.data();
    double sum = 0;
    for (int i = 0; i < count; ++i) sum += value[i];
    nodes *= count;
    mass *= sum;
  }
  mass *= 1 + 1e-5;  // the float products of the axis factors
  const double gamma = nodes * u / (1 - nodes * u);
  return u * (nodes * max_abs_r + 2 * mass) + gamma * (1 + 2 * u) * (mass + u * nodes * max_abs_r);
}

template <int D>
std::int64_t remove_surplus(Chain<D>& chain, std::vector<Particle<D>>& particles, double n, double& w) {
  typename Chain<D>::Scratch scratch;
  // Removing a kernel lowers R, and the energy another removal would take away, Σ |r| - |r - k|, only
  // shrinks as r falls: in exact arithmetic a removal never makes another kernel cheaper to remove. A cost
  // worked out before removals that changed R under it, less twice its rounding bound, is therefore a
  // floor for its cost now, and such a stale kernel is worked out again only when its floor is below the
  // cheapest current cost. Costs no removal touched are current bit for bit. Few stale costs are worked
  // out again (docs/design.md §2.5).
  const std::vector<float>& R = chain.residual();
  const std::vector<float>& rho = chain.density().rho;
  double max_abs_r = 0;
  for (std::size_t i = 0; i < R.size(); ++i)
    max_abs_r = std::max({max_abs_r, double(std::fabs(R[i])), double(rho[i])});
  max_abs_r *= 1 + 1e-3;  // removals only lower R, which stays above -ρ but for rounding
  const std::size_t count = particles.size();
  // Removed kernels stay in place (gone) until the end, so indices, which break ties, keep their order.
  std::vector<double> cost(count), slack(count), reach(count), weight(count);
  std::vector<char> stale(count, 0), gone(count, 0);
  auto work_out = [&](std::size_t j) {
    cost[j] = chain.energy_change_if_removed(particles[j], scratch) / weight[j];
    stale[j] = 0;
  };
  std::array<std::vector<double>, D> centres;  // by axis, for mark_overlapping()'s vector loop
  for (int k = 0; k < D; ++k) centres[k].resize(count);
  for (std::size_t j = 0; j < count; ++j) {
    for (int k = 0; k < D; ++k) centres[k][j] = particles[j].x[k];
    weight[j] = particles[j].weight();
    work_out(j);
    const bool massless = !(chain.rho_at(particles[j].x) > 0);  // no footprint: its cost is always 0
    slack[j] = massless ? 0 : 2 * removal_rounding_bound(scratch.old_fp, max_abs_r) / weight[j] * (1 + 1e-6);
    reach[j] = kCut * chain.sigma_at(particles[j]) + 1;
  }
  std::vector<std::pair<double, std::size_t>> floors;  // (floor, index) of stale candidates
  std::int64_t removed = 0;
  std::size_t last = count;  // the kernel the last round removed
  for (std::int64_t left = static_cast<std::int64_t>(count); w > n && left > 0; --left) {
    // The first of lowest cost, heavier than the surplus or not (the caller adds back what a heavy one
    // takes too many): kept to kernels that fit the surplus, the last removals would take a sharp step's
    // light faint kernels by the dozen where one dense kernel costs less (docs/design.md §2.5).
    std::size_t best = count;
    auto below_best = [&](double floor, std::size_t j) {
      return best == count || floor < cost[best] || (floor == cost[best] && j < best);
    };
    // The last removal changed R under these kernels: their costs from before are now only floors.
    if (last < count) mark_overlapping<D>(chain.grid(), centres, reach, last, stale);
    floors.clear();
    for (std::size_t j = 0; j < count; ++j) {
      if (gone[j]) continue;
      if (!stale[j]) {
        if (below_best(cost[j], j)) best = j;
      } else if (below_best(cost[j] - slack[j], j)) {
        floors.emplace_back(cost[j] - slack[j], j);  // compared again with the final best below
      }
    }
    std::sort(floors.begin(), floors.end());
    for (const auto& [floor, j] : floors) {
      if (!below_best(floor, j)) break;  // neither this kernel nor any after it can be cheaper
      work_out(j);
      if (below_best(cost[j], j)) best = j;
    }
    chain.splat(particles[best], -1.0f, scratch);
    w -= weight[best];
    gone[best] = 1;
    ++removed;
    last = best;
  }
  std::size_t kept = 0;
  for (std::size_t j = 0; j < count; ++j)
    if (!gone[j]) particles[kept++] = particles[j];
  particles.resize(kept);
  return removed;
}

template <int D>
std::int64_t remove_surplus_as_first_versions(Chain<D>& chain, std::vector<Particle<D>>& particles, double n,
                                              double& w) {
  typename Chain<D>::Scratch scratch;
  std::int64_t removed = 0;
  while (w > n && !particles.empty()) {
    std::size_t best = particles.size();
    double best_cost = std::numeric_limits<double>::infinity();
    for (int pass = 0; pass < 2 && best == particles.size(); ++pass) {
      for (std::size_t j = 0; j < particles.size(); ++j) {
        if (pass == 0 && particles[j].weight() > w - n) continue;  // prefer not to undershoot
        chain.splat(particles[j], -1.0f, scratch);
        const double cost = -chain.energy_change_if_added(particles[j], scratch) / particles[j].weight();
        chain.splat(particles[j], 1.0f, scratch);
        if (cost < best_cost) best_cost = cost, best = j;
      }
    }
    chain.splat(particles[best], -1.0f, scratch);
    w -= particles[best].weight();
    particles.erase(particles.begin() + static_cast<std::ptrdiff_t>(best));
    ++removed;
  }
  return removed;
}

template double removal_rounding_bound<2>(const Footprint<2>&, double);
template double removal_rounding_bound<3>(const Footprint<3>&, double);
template std::int64_t remove_surplus<2>(Chain<2>&, std::vector<Particle<2>>&, double, double&);
template std::int64_t remove_surplus<3>(Chain<3>&, std::vector<Particle<3>>&, double, double&);
template std::int64_t remove_surplus_as_first_versions<2>(Chain<2>&, std::vector<Particle<2>>&, double,
                                                          double&);
template std::int64_t remove_surplus_as_first_versions<3>(Chain<3>&, std::vector<Particle<3>>&, double,
                                                          double&);

}  // namespace kdm::gen
