// Exact counts (count_fixing.h): removal with kept costs against removal that works every cost out
// afresh, and the energy change of a removal against E itself.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "sampler/count_fixing.h"
#include "sampler/rng.h"

namespace kdm::gen {
namespace {

// A density that varies by a factor of 20 across the grid, so kernels of one weight have different σ
// and reaches, on a torus or a box; or (varying = false) the peak density everywhere.
template <int D>
DensityGrid<D> varying_density(int side, bool torus, bool varying = true) {
  DensityGrid<D> d;
  d.grid.dims.fill(side);
  d.grid.torus = torus;
  d.rho.resize(static_cast<std::size_t>(d.grid.size()));
  for (std::int64_t i = 0; i < d.grid.size(); ++i) {
    double shape = 1;
    std::int64_t rest = i;
    for (int k = 0; k < D; ++k, rest /= side) shape *= 0.6 + 0.4 * std::sin(0.3 * double(rest % side) + k);
    d.rho[static_cast<std::size_t>(i)] =
        static_cast<float>(varying ? 0.43 * (0.05 + 0.95 * shape * shape) : 0.43);
  }
  return d;
}

// Kernels at random places, a third of them heavy (weight 2^D), all in the chain's R.
template <int D>
std::vector<Particle<D>> random_kernels(Chain<D>& chain, int count, std::uint64_t seed) {
  Rng rng(seed);
  typename Chain<D>::Scratch scratch;
  std::vector<Particle<D>> particles(static_cast<std::size_t>(count));
  for (Particle<D>& p : particles) {
    for (int k = 0; k < D; ++k) p.x[k] = rng.uniform() * chain.grid().dims[k];
    p.splits = rng.uniform() < 1.0 / 3 ? 1 : 0;
    chain.splat(p, 1.0f, scratch);
  }
  return particles;
}

// The rule of remove_surplus(), stated directly: the first of lowest cost per unit of weight, however
// heavy, with every cost worked out again before each choice.
template <int D>
std::int64_t remove_with_fresh_costs(Chain<D>& chain, std::vector<Particle<D>>& particles, double n,
                                     double& w) {
  std::int64_t removed = 0;
  for (typename Chain<D>::Scratch scratch; w > n && !particles.empty(); ++removed) {
    std::vector<std::pair<double, std::size_t>> all;  // (cost, index): pairs order ties by index
    for (std::size_t j = 0; j < particles.size(); ++j)
      all.emplace_back(chain.energy_change_if_removed(particles[j], scratch) / particles[j].weight(), j);
    const std::size_t best = std::min_element(all.begin(), all.end())->second;
    chain.splat(particles[best], -1.0f, scratch);
    w -= particles[best].weight();
    particles.erase(particles.begin() + static_cast<std::ptrdiff_t>(best));
  }
  return removed;
}

template <int D>
double total_weight(const std::vector<Particle<D>>& particles) {
  double w = 0;
  for (const auto& p : particles) w += p.weight();
  return w;
}

template <int D>
void expect_same_choices_as_fresh_costs(int side, int count, double surplus, bool torus) {
  const DensityGrid<D> density = varying_density<D>(side, torus);
  ChainParams params;
  Chain<D> kept_chain(density, params), fresh_chain(density, params);
  std::vector<Particle<D>> kept = random_kernels(kept_chain, count, 7);
  std::vector<Particle<D>> fresh = random_kernels(fresh_chain, count, 7);
  const double n = total_weight(kept) - surplus;
  double kept_w = total_weight(kept), fresh_w = kept_w;
  const std::int64_t removed = remove_surplus(kept_chain, kept, n, kept_w);
  EXPECT_EQ(removed, remove_with_fresh_costs(fresh_chain, fresh, n, fresh_w));
  EXPECT_GE(removed, static_cast<std::int64_t>(surplus / (1 << D)));
  EXPECT_LE(kept_w, n);
  EXPECT_EQ(kept_w, fresh_w);
  ASSERT_EQ(kept.size(), fresh.size());
  for (std::size_t j = 0; j < kept.size(); ++j) EXPECT_EQ(kept[j].x, fresh[j].x) << "kernel " << j;
  EXPECT_EQ(kept_chain.residual(), fresh_chain.residual());
}

// Any cost left stale by too small an overlap test would change a later choice here: over 40 removals
// among crowded kernels, most removals change some neighbour's cost.
TEST(CountFixingTest, KeptCostsChooseAsFreshCostsOnATorus) {
  expect_same_choices_as_fresh_costs<2>(48, 300, 60.5, true);
}

// Two overlapping pairs, one across the torus's seam (1 node apart), one in the middle (1.2 apart), and
// two lone kernels: removing two kernels must take one of each pair. Were the seam pair's second kernel
// not seen as the first one's neighbour, its kept cost would still be the lowest and it would go too.
TEST(CountFixingTest, KeptCostsSeeNeighboursAcrossTheTorusSeam) {
  const DensityGrid<2> density = varying_density<2>(48, true, false);
  Chain<2> chain(density, ChainParams{});
  Chain<2>::Scratch scratch;
  std::vector<Particle<2>> particles(6);
  const Vec<2> places[6] = {{0.4, 10}, {47.4, 10}, {24, 30}, {25.2, 30}, {10, 40}, {36, 40}};
  for (int j = 0; j < 6; ++j) particles[j].x = places[j], chain.splat(particles[j], 1.0f, scratch);
  double w = 6;
  ASSERT_EQ(remove_surplus(chain, particles, 4, w), 2);
  ASSERT_EQ(particles.size(), 4u);
  int seam_pair = 0, middle_pair = 0;
  for (const Particle<2>& p : particles) seam_pair += p.x[1] == 10, middle_pair += p.x[1] == 30;
  EXPECT_EQ(seam_pair, 1);
  EXPECT_EQ(middle_pair, 1);
}

// Light kernels each on its own spot and two heavy ones stacked on one, with a surplus lighter than a
// heavy kernel: one of the stacked pair is the cheapest removal per unit of weight, and taking it leaves
// every light kernel. Kept to kernels that fit the surplus, removal took three light kernels instead,
// which is how the faint side of a sharp step lost its points.
TEST(CountFixingTest, RemovesAHeavyKernelWhenItIsTheCheapest) {
  const DensityGrid<2> density = varying_density<2>(48, true, false);
  Chain<2> chain(density, ChainParams{});
  Chain<2>::Scratch scratch;
  std::vector<Particle<2>> particles;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) particles.push_back({Vec<2>{3.0 + 12 * x, 3.0 + 12 * y}, 0});
  for (int j = 0; j < 2; ++j) particles.push_back({Vec<2>{9.0, 9.0}, 1});  // weight 4 each
  for (const Particle<2>& p : particles) chain.splat(p, 1.0f, scratch);
  double w = total_weight(particles);
  ASSERT_EQ(w, 24);
  EXPECT_EQ(remove_surplus(chain, particles, 21.5, w), 1);
  EXPECT_EQ(w, 20);
  int light = 0, heavy = 0;
  for (const Particle<2>& p : particles) (p.splits ? heavy : light) += 1;
  EXPECT_EQ(light, 16);
  EXPECT_EQ(heavy, 1);
}

TEST(CountFixingTest, KeptCostsChooseAsFreshCostsOnABox) {
  expect_same_choices_as_fresh_costs<2>(48, 300, 60.5, false);
}

TEST(CountFixingTest, KeptCostsChooseAsFreshCostsIn3D) {
  expect_same_choices_as_fresh_costs<3>(20, 250, 60.5, true);
}

TEST(CountFixingTest, FirstVersionsRemovalReachesTheCount) {
  const DensityGrid<2> density = varying_density<2>(48, true);
  Chain<2> chain(density, ChainParams{});
  std::vector<Particle<2>> particles = random_kernels(chain, 300, 7);
  double w = total_weight(particles);
  const double n = w - 60.5;
  const std::int64_t removed = remove_surplus_as_first_versions(chain, particles, n, w);
  EXPECT_LE(w, n);
  EXPECT_GT(w, n - 4);  // the last removal takes at most one heavy kernel past n
  EXPECT_EQ(w, total_weight(particles));
  EXPECT_EQ(static_cast<std::size_t>(300 - removed), particles.size());
}

// What remove_surplus() relies on: removals never make another kernel cheaper to remove, but for the
// float rounding that removal_rounding_bound() bounds. Kernels the removals reach get dearer by far more
// than that; those in deficit (R < 0 under the whole footprint) have a cost that is constant in exact
// arithmetic, and their float cost moves by rounding alone, either way, which a zero bound would miss.
template <int D>
void expect_costs_never_fall_past_the_bound(int side, int count) {
  const DensityGrid<D> density = varying_density<D>(side, true);
  Chain<D> chain(density, ChainParams{});
  std::vector<Particle<D>> particles = random_kernels(chain, count, 5);
  typename Chain<D>::Scratch scratch;
  double max_abs_r = 0;
  for (std::size_t i = 0; i < chain.residual().size(); ++i)
    max_abs_r = std::max({max_abs_r, double(std::fabs(chain.residual()[i])), double(density.rho[i])});
  std::vector<double> before(particles.size()), bound(particles.size());
  for (std::size_t j = 0; j < particles.size(); ++j) {
    before[j] = chain.energy_change_if_removed(particles[j], scratch);
    bound[j] = removal_rounding_bound(scratch.old_fp, max_abs_r * (1 + 1e-3));
    // Costs are of the order of a kernel's mass (w·J^D: about 7 in 2D, 18 in 3D for w = 1). Measured here:
    // bounds 5e-5 to 4e-3 in 2D, 9e-4 to 0.07 in 3D; the falls below stay under 5e-6.
    EXPECT_LT(bound[j], 0.1) << "kernel " << j;
  }
  Rng rng(9);
  int fell = 0;
  for (int round = 0; round < 60; ++round) {
    const std::size_t gone = rng.below(particles.size());
    chain.splat(particles[gone], -1.0f, scratch);
    particles.erase(particles.begin() + static_cast<std::ptrdiff_t>(gone));
    before.erase(before.begin() + static_cast<std::ptrdiff_t>(gone));
    bound.erase(bound.begin() + static_cast<std::ptrdiff_t>(gone));
    for (std::size_t j = 0; j < particles.size(); ++j) {
      const double now = chain.energy_change_if_removed(particles[j], scratch);
      ASSERT_GE(now, before[j] - 2 * bound[j]) << "kernel " << j << " after removal " << round;
      fell += now < before[j];
      before[j] = now;
    }
  }
  EXPECT_GT(fell, 0);  // rounding did lower some costs: the bound was needed
}

TEST(CountFixingTest, RemovalsNeverMakeAKernelCheaperButForRounding) {
  expect_costs_never_fall_past_the_bound<2>(48, 300);
  expect_costs_never_fall_past_the_bound<3>(20, 250);
}

// The energy change of a removal is E after minus E before, and asking leaves R bit for bit as it was.
TEST(CountFixingTest, RemovalChangeMatchesEnergyAndLeavesRAsItWas) {
  const DensityGrid<2> density = varying_density<2>(48, false);
  Chain<2> chain(density, ChainParams{});
  const std::vector<Particle<2>> particles = random_kernels(chain, 200, 11);
  Chain<2>::Scratch scratch;
  for (std::size_t j = 0; j < particles.size(); j += 17) {
    const std::vector<float> before = chain.residual();
    const double e_before = chain.energy();
    const double change = chain.energy_change_if_removed(particles[j], scratch);
    ASSERT_EQ(chain.residual(), before) << "kernel " << j;
    chain.splat(particles[j], -1.0f, scratch);
    // Float sums over a few hundred nodes of |R| <= 1: a few 1e-5 at most.
    EXPECT_NEAR(change, chain.energy() - e_before, 1e-4) << "kernel " << j;
    EXPECT_NE(change, 0) << "kernel " << j;
    chain.residual() = before;
  }
}

}  // namespace
}  // namespace kdm::gen
