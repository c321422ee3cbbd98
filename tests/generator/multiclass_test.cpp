// The full sampler's classes: exact counts, class order, determinism across thread counts, the union's and
// class 0's spacing against one-class samples, densities of every kind, refusals.
#include <gtest/gtest.h>

#include <cmath>

#include <cstdio>
#include <vector>

#include "kdm/analysis/nearest_neighbour.h"
#include "kdm/generator/multiclass.h"

namespace kdm::gen {
namespace {

std::vector<Density> one_two_four() {
  return {Density::from_values(1, 1, {1.0f}), Density::from_values(1, 1, {2.0f}),
          Density::from_values(1, 1, {4.0f})};
}

std::vector<double> class_points(const ClassSample& s, int k) {
  std::vector<double> c;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.classes[i] == k) c.insert(c.end(), {s.points[2 * i], s.points[2 * i + 1]});
  return c;
}

TEST(MultiClassTest, ExactCountsInClassOrderTheSameOnAnyThreadCount) {
  SamplerOptions o;
  o.n = 7001;
  o.seed = 5;
  o.threads = 1;
  const ClassSample a = sample_classes(o, one_two_four());
  ASSERT_EQ(a.counts, (std::vector<std::int64_t>{1000, 2000, 4001}));
  ASSERT_EQ(a.size(), 7001u);
  ASSERT_EQ(a.points.size(), 2 * a.size());
  for (std::size_t i = 1; i < a.size(); ++i) ASSERT_LE(a.classes[i - 1], a.classes[i]);  // class 0 first
  o.threads = 2;
  const ClassSample b = sample_classes(o, one_two_four());
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.classes, b.classes);
  o.seed = 6;
  EXPECT_NE(sample_classes(o, one_two_four()).points, a.points);
}

TEST(MultiClassTest, UnionAndClassZeroAgainstOneClassSamples) {
  // 1 : 2 : 4 over 14,000 points. Measured (seed 1): union δmin .563, δavg .870 (a one-class sample of
  // 14,000: .872); class 0 δavg .781 (.871 before the joint sweeps, .872 for a one-class sample of 2,000).
  // Bars 0.02 below each, about four times the spread of δavg between seeds (±.004).
  SamplerOptions o;
  o.n = 14000;
  o.seed = 1;
  const ClassSample s = sample_classes(o, one_two_four());
  const analysis::NNStats all = analysis::nn_stats(s.points, 2, true);
  const analysis::NNStats zero = analysis::nn_stats(class_points(s, 0), 2, true);
  std::printf("union δmin %.3f δavg %.3f, class 0 δavg %.3f\n", all.dmin, all.davg, zero.davg);
  EXPECT_GE(all.dmin, 0.45);  // no two points of any classes on top of each other
  EXPECT_GE(all.davg, 0.851);
  EXPECT_GE(zero.davg, 0.76);
  // Without the joint sweeps class 0 is a one-class sample and the union is what fixed classes allow.
  const ClassSample fixed = sample_classes(o, one_two_four(), 0);
  const double fixed_zero = analysis::nn_stats(class_points(fixed, 0), 2, true).davg;
  const double fixed_all = analysis::nn_stats(fixed.points, 2, true).davg;
  std::printf("without joint sweeps: union δavg %.3f, class 0 δavg %.3f\n", fixed_all, fixed_zero);
  EXPECT_GE(fixed_zero, 0.85);
  EXPECT_LT(fixed_all, all.davg);
}

TEST(MultiClassTest, VaryingDensitiesSplitByTheirIntegrals) {
  // A left ramp and a right ramp (integrals equal) and a constant of a quarter of their peak.
  Density left, right;
  left.function = [](const double* u) { return 1 - u[0]; };
  right.function = [](const double* u) { return u[0]; };
  left.thread_safe = right.thread_safe = true;
  SamplerOptions o;
  o.n = 4000;
  o.domain = Domain::kBox;
  const std::vector<Density> d = {left, right, Density::from_values(1, 1, {0.25f})};
  const std::vector<std::int64_t> counts = class_counts(o, d, 4000);
  EXPECT_EQ(counts, (std::vector<std::int64_t>{1600, 1600, 800}));
  const ClassSample s = sample_classes(o, d);
  // The left class lies mostly left: its mean x is 1/3 for density 1 − x.
  double mean = 0;
  const std::vector<double> c = class_points(s, 0);
  for (std::size_t i = 0; i < c.size(); i += 2) mean += c[i];
  EXPECT_NEAR(mean / double(c.size() / 2), 1.0 / 3, 0.03);
}

// Classes with batch functions (alone, or beside a function and a constant) give the same points as the
// same classes read node by node: the class means and summed densities read through the batches.
TEST(MultiClassTest, BatchDensitiesGiveTheSameBitsAsTheirFunctions) {
  const DensityFunction ramp = [](const double* u) { return 0.1 + u[0] * u[1]; };
  const DensityFunction wave = [](const double* u) { return 1.1 + std::sin(7 * u[0]); };
  int batch_calls = 0;
  const auto batched = [&](const DensityFunction& f) {
    Density d;
    d.function = f;
    d.batch = [f, &batch_calls](const double* u, std::size_t count, double* out) {
      ++batch_calls;
      for (std::size_t i = 0; i < count; ++i) out[i] = f(u + 2 * i);
    };
    return d;
  };
  Density plain_ramp, plain_wave;
  plain_ramp.function = ramp, plain_wave.function = wave;
  SamplerOptions o;
  o.n = 3000;
  o.seed = 4;
  o.domain = Domain::kBox;
  const ClassSample a = sample_classes(o, {plain_ramp, plain_wave, Density::constant(0.5)});
  const ClassSample b = sample_classes(o, {batched(ramp), plain_wave, Density::constant(0.5)});
  const ClassSample c = sample_classes(o, {batched(ramp), batched(wave), Density::constant(0.5)});
  EXPECT_GT(batch_calls, 0);
  EXPECT_EQ(a.counts, b.counts);
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.classes, b.classes);
  EXPECT_EQ(a.points, c.points);
  EXPECT_EQ(a.classes, c.classes);
}

TEST(MultiClassTest, BadInputIsRefused) {
  SamplerOptions o;
  o.n = 100;
  EXPECT_THROW(sample_classes(o, {}), InvalidArgument);
  EXPECT_THROW(sample_classes(o, std::vector<Density>(9)), InvalidArgument);
  EXPECT_THROW(sample_classes(o, one_two_four(), -1), InvalidArgument);
  Density zero;
  zero.function = [](const double*) { return 0.0; };
  EXPECT_THROW(sample_classes(o, {zero, zero}), InvalidArgument);
  o.fixed_points = {0.5, 0.5};
  EXPECT_THROW(sample_classes(o, one_two_four()), InvalidArgument);
  o.fixed_points.clear();
  o.n = 0;
  EXPECT_THROW(sample_classes(o, one_two_four()), InvalidArgument);
  EXPECT_THROW(class_counts(o, one_two_four(), -1), InvalidArgument);  // had given {-1, 0, 0}
}

// Density::constant(v) gives a class its share without a function of one's own: the shares of 1:2:4,
// as from_values' one-texel images give them.
TEST(MultiClassTest, ConstantsWithValuesSetTheShares) {
  SamplerOptions o;
  const std::vector<Density> constants = {Density::constant(1), Density::constant(2), Density::constant(4)};
  EXPECT_EQ(class_counts(o, constants, 7001), class_counts(o, one_two_four(), 7001));
  EXPECT_EQ(class_counts(o, constants, 700), (std::vector<std::int64_t>{100, 200, 400}));
  EXPECT_THROW(Density::constant(-1), InvalidArgument);
  EXPECT_THROW(Density::constant(std::nan("")), InvalidArgument);
  o.n = 300;
  o.threads = 1;
  EXPECT_EQ(sample(o, Density::constant(5)).points, sample(o).points);  // alone, only its shape matters
}

// A class never lies where its own density is zero: class 1 (the left half only) was sampled at the sum
// with class 0 (everywhere) fixed, so it filled class 0's gaps on the right too, and the joint sweeps moved
// points by the sum alone; such a point takes the class whose density is there, and every class keeps the
// count its density's integral gives it.
TEST(MultiClassTest, NoClassWhereItsDensityIsZero) {
  SamplerOptions o;
  o.n = 4000;
  o.seed = 3;
  o.threads = 1;
  o.domain = Domain::kBox;
  std::vector<float> left(64 * 64, 0.0f);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 32; ++x) left[std::size_t(y) * 64 + x] = 1.0f;
  const std::vector<Density> densities = {Density::from_values(1, 1, {1.0f}),
                                          Density::from_values(64, 64, left)};
  const ClassSample s = sample_classes(o, densities);
  ASSERT_EQ(s.size(), 4000u);
  std::int64_t counted[2] = {0, 0}, stray = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    ++counted[s.classes[i]];
    if (s.classes[i] == 1 && s.points[2 * i] > 33.0 / 64) ++stray;  // past the interpolated edge
    if (i > 0) {
      ASSERT_LE(s.classes[i - 1], s.classes[i]);  // class 0's points first
    }
  }
  EXPECT_EQ(stray, 0);
  EXPECT_EQ(counted[0], s.counts[0]);
  EXPECT_EQ(counted[1], s.counts[1]);
  // Each point that changed class gave its class back another, inside that class's density: the counts
  // are the shares (class 1 lost 24 of its 1,333 at 50,000 points of three classes before).
  EXPECT_EQ(s.counts, class_counts(o, densities, o.n));
}

}  // namespace
}  // namespace kdm::gen
