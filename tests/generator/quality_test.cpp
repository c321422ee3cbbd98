// Blue-noise quality of the full sampler, measured with the analysis library (docs/design.md §6) against the
// reference implementation's statistics (tests/data/reference/README.md: δmin .612, δavg .872, lowP .0044).
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "kdm/analysis/nearest_neighbour.h"
#include "kdm/analysis/periodogram.h"
#include "kdm/generator/sampler.h"

namespace kdm::gen {
namespace {

struct SetStats {
  double dmin = 0, davg = 0, low_p = 0;
};

SetStats sample_and_measure(SamplerOptions o, int seeds) {
  SetStats mean;
  std::vector<tools::PointSet> sets;
  for (int s = 1; s <= seeds; ++s) {
    o.seed = static_cast<std::uint64_t>(s);
    tools::PointSet set;
    set.dim = 2;
    set.coords = sample(o).points;
    const analysis::NNStats nn = analysis::nn_stats(set.coords, 2, /*torus=*/true);
    mean.dmin += nn.dmin / seeds;
    mean.davg += nn.davg / seeds;
    sets.push_back(std::move(set));
  }
  mean.low_p = analysis::spectrum_stats(analysis::average_periodogram(sets, 0.6)).low_p;
  return mean;
}

TEST(QualityTest, DefaultTemperatureMatchesTheReferenceLook) {
  SamplerOptions o;
  o.n = 4096;
  const SetStats s = sample_and_measure(o, 8);
  std::printf("n=4096, 8 seeds: mean δmin %.3f, δavg %.4f, lowP %.4f\n", s.dmin, s.davg, s.low_p);
  // The targets. Measured (seeds 1–8): δmin .606, δavg .8722, lowP .0057; over seeds 1–64: δmin .600
  // (standard deviation of one set's δmin .036, so an 8-seed mean spreads about .013), δavg .8724,
  // lowP .0057. Seed-to-seed spread of δavg is about .003; lowP is the tight one.
  EXPECT_GE(s.davg, 0.865);
  EXPECT_LE(s.low_p, 0.006);
  EXPECT_GE(s.dmin, 0.58);
}

TEST(QualityTest, LowTemperatureIsMoreOrdered) {
  SamplerOptions o;
  o.n = 4096;
  o.temperature = 0.2;  // the documented low-temperature setting: --temperature 0.2 --sweeps 100
  o.sweeps = 100;
  const SetStats s = sample_and_measure(o, 2);
  std::printf("n=4096, T=0.2, 100 sweeps, 2 seeds: mean δmin %.3f, δavg %.4f, lowP %.4f\n", s.dmin, s.davg,
              s.low_p);
  // Measured δavg .904 for seeds 1–2 (spread .001); the target is >= .90.
  EXPECT_GE(s.davg, 0.90);
}

}  // namespace
}  // namespace kdm::gen

namespace kdm::gen {
namespace {

// Constrained sampling (the tile pyramid's step): 1024 fixed points, 3072 new ones sampled from
// P(new | fixed). The union must be as blue as an unconstrained set of 4096.
TEST(QualityTest, ConstrainedSamplingFillsAroundFixedPoints) {
  SamplerOptions base;
  base.n = 1024;
  base.seed = 1;
  const std::vector<double> fixed = sample(base).points;
  SamplerOptions o;
  o.n = 3072;
  o.seed = 2;
  o.sweeps = 100;  // conditioning slows burn-in: measured E/n .61 after 30 sweeps, .54 (converged) after 100
  o.fixed_points = fixed;
  const SampleResult r = sample(o);
  ASSERT_EQ(r.size(), 3072u);
  std::vector<double> all = fixed;
  all.insert(all.end(), r.points.begin(), r.points.end());
  const analysis::NNStats nn = analysis::nn_stats(all, 2, true);
  std::printf("1024 fixed + 3072 new: δmin %.3f δavg %.4f E/n %.4f\n", nn.dmin, nn.davg,
              r.report.energy_per_point);
  // Measured δmin .578, δavg .872 (seed 2); unconstrained 4096-point sets give δavg .872 ± .003.
  EXPECT_GE(nn.davg, 0.865);
  EXPECT_GE(nn.dmin, 0.45);
  SamplerOptions bad = o;
  bad.fixed_points.push_back(0.5);  // odd coordinate count
  EXPECT_THROW(sample(bad), InvalidArgument);
  bad.fixed_points = {1.5, 0.5};
  EXPECT_THROW(sample(bad), InvalidArgument);
}

}  // namespace
}  // namespace kdm::gen
