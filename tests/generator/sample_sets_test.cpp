// sample_sets(): many small sets at once, each bit for bit the sample() call with its seed, whatever the
// thread count; bad input refused by name.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "kdm/generator/sampler.h"

namespace kdm::gen {
namespace {

std::vector<std::uint64_t> seeds_from(std::uint64_t first, int count) {
  std::vector<std::uint64_t> seeds;
  for (int k = 0; k < count; ++k) seeds.push_back(first + 1000003 * static_cast<std::uint64_t>(k));
  return seeds;
}

// Each set against sample() with its seed (on one thread: the output does not depend on it), points and
// the chain's counts, on `threads` threads and through both overloads.
void expect_single_calls(SamplerOptions o, const Density& density, int sets, int threads) {
  const std::vector<std::uint64_t> seeds = seeds_from(7, sets);
  o.threads = threads;
  const std::vector<SampleResult> batch = sample_sets(o, density, seeds);
  ASSERT_EQ(batch.size(), seeds.size());
  const std::size_t per_set = static_cast<std::size_t>(o.n) * static_cast<std::size_t>(o.dim);
  std::vector<double> into(seeds.size() * per_set, -1.0);
  const std::vector<SampleReport> reports = sample_sets(o, density, seeds, into.data());
  ASSERT_EQ(reports.size(), seeds.size());
  for (std::size_t k = 0; k < seeds.size(); ++k) {
    SamplerOptions single = o;
    single.seed = seeds[k];
    single.threads = 1;
    const SampleResult one = sample(single, density);
    ASSERT_EQ(one.points.size(), per_set);
    EXPECT_EQ(batch[k].dim, o.dim);
    EXPECT_EQ(batch[k].points, one.points) << "set " << k << ", " << threads << " threads";
    EXPECT_EQ(std::vector<double>(into.begin() + k * per_set, into.begin() + (k + 1) * per_set), one.points)
        << "set " << k << " written into the caller's memory";
    EXPECT_EQ(batch[k].report.proposals, one.report.proposals);
    EXPECT_EQ(batch[k].report.accepted, one.report.accepted);
    EXPECT_EQ(reports[k].accepted, one.report.accepted);
    EXPECT_EQ(batch[k].report.levels.size(), one.report.levels.size());
  }
}

TEST(SampleSetsTest, EachSetIsTheSingleCallWithItsSeed) {
  SamplerOptions o;
  for (std::int64_t n : {16, 100, 300}) {  // 300: past the one-level sets, a pyramid of two
    o.n = n;
    o.domain = Domain::kTorus;
    expect_single_calls(o, Density::constant(), 5, 2);
    o.domain = Domain::kBox;
    expect_single_calls(o, Density::constant(), 3, 2);
  }
  SamplerOptions cube;
  cube.dim = 3;
  cube.n = 40;
  expect_single_calls(cube, Density::constant(), 3, 2);
}

TEST(SampleSetsTest, ThreadCountDoesNotChangeTheSets) {
  SamplerOptions o;
  o.n = 64;
  // 1 thread; more sets than threads; fewer (each set then shares out the threads left over).
  for (int threads : {1, 2, 3, 8}) expect_single_calls(o, Density::constant(), 3, threads);
  o.n = 2000;  // a set large enough to run its sweeps on several threads
  expect_single_calls(o, Density::constant(), 1, 4);
}

TEST(SampleSetsTest, VaryingAndConstrainedDensitiesAsSingleCalls) {
  SamplerOptions o;
  o.n = 200;
  o.domain = Domain::kBox;
  Density ramp;
  ramp.function = [](const double* u) { return 0.2 + u[0] * u[1]; };
  expect_single_calls(o, ramp, 3, 2);
  // Constrained sampling changes the model's coarse levels: each set must start from the model as built.
  o.domain = Domain::kTorus;
  o.fixed_points = {0.1, 0.1, 0.5, 0.5, 0.9, 0.3};
  expect_single_calls(o, Density::constant(), 3, 2);
}

TEST(SampleSetsTest, TheDensityIsReadOnceForAllSets) {
  SamplerOptions o;
  o.n = 100;
  o.threads = 2;
  std::atomic<int> calls{0};
  Density counted;
  counted.function = [&](const double* u) {
    ++calls;
    return 1.0 + u[0];
  };
  o.seed = 7;
  sample(o, counted);
  const int single = calls.exchange(0);
  ASSERT_GT(single, 0);
  sample_sets(o, counted, seeds_from(7, 6));
  EXPECT_EQ(calls.load(), single);
}

TEST(SampleSetsTest, ProgressRisesToOneOnTheCallingThreadAndCancels) {
  SamplerOptions o;
  o.n = 64;
  o.threads = 2;
  const std::thread::id caller = std::this_thread::get_id();
  std::vector<double> seen;
  bool elsewhere = false;
  o.progress = [&](double f) {
    elsewhere = elsewhere || std::this_thread::get_id() != caller;
    seen.push_back(f);
  };
  sample_sets(o, Density::constant(), seeds_from(1, 6));
  EXPECT_FALSE(elsewhere);
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.back(), 1.0);
  for (std::size_t i = 1; i < seen.size(); ++i) EXPECT_GE(seen[i], seen[i - 1]);
  int calls = 0;
  o.progress = [&](double) {
    if (++calls == 3) throw std::runtime_error("cancelled");
  };
  EXPECT_THROW(sample_sets(o, Density::constant(), seeds_from(1, 50)), std::runtime_error);
}

TEST(SampleSetsTest, BadInputIsRefusedByName) {
  SamplerOptions o;
  o.n = 16;
  auto message = [&](const SamplerOptions& options, const std::vector<std::uint64_t>& seeds) -> std::string {
    try {
      sample_sets(options, Density::constant(), seeds);
    } catch (const InvalidArgument& e) {
      return e.what();
    }
    return "accepted";
  };
  EXPECT_NE(message(o, {}).find("no seeds"), std::string::npos);
  EXPECT_NE(message(o, std::vector<std::uint64_t>(kMaxSampleSets + 1, 1)).find("too many point sets"),
            std::string::npos);
  SamplerOptions big = o;
  big.n = kMaxSampleSetPoints / 4 + 1;  // refused before any sampling: four sets would overflow the bound
  EXPECT_NE(message(big, seeds_from(1, 4)).find("points in all"), std::string::npos);
  SamplerOptions by_resolution = o;
  by_resolution.n = 0;
  by_resolution.resolution = 64;
  EXPECT_NE(message(by_resolution, {1, 2}).find("n > 0"), std::string::npos);
  SamplerOptions hot = o;
  hot.temperature = -1;  // sample()'s own checks
  EXPECT_NE(message(hot, {1}).find("temperature"), std::string::npos);
  SamplerOptions many_threads = o;
  many_threads.threads = kMaxThreads + 1;
  EXPECT_NE(message(many_threads, {1}).find("threads"), std::string::npos);
  EXPECT_THROW(sample_sets(o, Density::constant(), {1, 2}, nullptr), InvalidArgument);
}

}  // namespace
}  // namespace kdm::gen
