#include "count_fixing.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace kdm::gen {
namespace {

/// Whether footprints centred at a and b, whose reaches add up to `reach` nodes, may share a node. On a
/// box too: the torus distance is at most the straight one, and a kernel folded at a wall stays within its
/// reach of its centre.
template <int D>
bool may_overlap(const Grid<D>& g, const Vec<D>& a, const Vec<D>& b, double reach) {
  for (int k = 0; k < D; ++k) {
    const double d = std::fabs(a[k] - b[k]);
    if (std::min(d, g.dims[k] - d) > reach) return false;
  }
  return true;
}

}  // namespace

template <int D>
std::int64_t remove_surplus(Chain<D>& chain, std::vector<Particle<D>>& particles, double n, double& w) {
  typename Chain<D>::Scratch scratch;
  // Kept costs: at n = 16,384 a full rescan after each of some 30 removals took about 2 ms, a third of
  // the coarsest level, and in 3D at n = 32,768 (some 440 removals) 2.5 s of a 4.5 s run; keeping them,
  // 0.5 ms and 0.12 s.
  std::vector<double> cost(particles.size()), reach(particles.size());
  auto cost_of = [&](std::size_t j) {
    return chain.energy_change_if_removed(particles[j], scratch) / particles[j].weight();
  };
  for (std::size_t j = 0; j < particles.size(); ++j)
    cost[j] = cost_of(j), reach[j] = kCut * chain.sigma_at(particles[j]) + 1;
  std::int64_t removed = 0;
  while (w > n && !particles.empty()) {
    std::size_t best = particles.size();
    for (int pass = 0; pass < 2 && best == particles.size(); ++pass)
      for (std::size_t j = 0; j < particles.size(); ++j) {
        if (pass == 0 && particles[j].weight() > w - n) continue;  // prefer not to undershoot
        if (best == particles.size() || cost[j] < cost[best]) best = j;
      }
    const Particle<D> gone = particles[best];
    const double gone_reach = reach[best];
    chain.splat(gone, -1.0f, scratch);
    w -= gone.weight();
    const auto at = static_cast<std::ptrdiff_t>(best);
    particles.erase(particles.begin() + at);
    cost.erase(cost.begin() + at);
    reach.erase(reach.begin() + at);
    ++removed;
    for (std::size_t j = 0; j < particles.size(); ++j)
      if (may_overlap<D>(chain.grid(), particles[j].x, gone.x, reach[j] + gone_reach)) cost[j] = cost_of(j);
  }
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

template std::int64_t remove_surplus<2>(Chain<2>&, std::vector<Particle<2>>&, double, double&);
template std::int64_t remove_surplus<3>(Chain<3>&, std::vector<Particle<3>>&, double, double&);
template std::int64_t remove_surplus_as_first_versions<2>(Chain<2>&, std::vector<Particle<2>>&, double,
                                                          double&);
template std::int64_t remove_surplus_as_first_versions<3>(Chain<3>&, std::vector<Particle<3>>&, double,
                                                          double&);

}  // namespace kdm::gen
