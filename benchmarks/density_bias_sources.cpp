// Where the full sampler's per-band count bias on a varying density comes from, and what removes it.
// Each row samples a 1:1000 density (20,000 points, several seeds) and prints count/target in each tenth
// of the density's log range (the bands of `kdm analyze --density`): the default sampler; the same without
// the count balance; and, without it, one suspect changed at a time (freezing wide kernels, the grid's
// resolution, the temperature, the walls of a box, more finest sweeps); and the finest chain alone
// started from exactly the target counts. docs/design.md §2 quotes its output.
// Run: build/benchmarks/density_bias_sources [seeds]   (Markdown on stdout; about 4 minutes at 4 seeds)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "kdm/generator/sampler.h"

namespace {

using kdm::gen::Domain;
using kdm::gen::SamplerOptions;

constexpr int kPoints = 20000;
constexpr double kRange = 1000;

struct Map {
  bool radial;
  double a = std::log(kRange);
  double rho(double x, double y) const { return std::exp(-a * tenth_coordinate(x, y)); }
  /// Where in the log range a point lies, in [0, 1]: x for the ramp, 2r (capped) for the radial map.
  double tenth_coordinate(double x, double y) const {
    if (!radial) return x;
    return std::min(1.0, 2 * std::hypot(x - 0.5, y - 0.5));
  }
  int band(double x, double y) const { return std::min(9, static_cast<int>(tenth_coordinate(x, y) * 10)); }
};

std::vector<double> expected_counts(const Map& map) {
  const int m = 2000;
  std::vector<double> mass(10, 0.0);
  double total = 0;
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) {
      const double x = (i + 0.5) / m, y = (j + 0.5) / m, v = map.rho(x, y);
      mass[map.band(x, y)] += v, total += v;
    }
  for (double& v : mass) v *= kPoints / total;
  return mass;
}

/// A start with the target's counts: a uniform blue-noise set mapped through the ramp's inverse CDF in x.
std::vector<double> exact_start(const Map& map, std::uint64_t seed) {
  SamplerOptions u;
  u.n = kPoints;
  u.seed = seed;
  std::vector<double> p = kdm::gen::sample(u).points;
  for (std::size_t j = 0; j < p.size(); j += 2) {
    const double q = p[j];
    p[j] = std::min(-std::log(1 - q * (1 - std::exp(-map.a))) / map.a, std::nextafter(1.0, 0.0));
  }
  return p;
}

struct Row {
  std::string name;
  Map map;
  std::function<void(SamplerOptions&, std::uint64_t seed)> change;
};

void print_row(const Row& row, int seeds, const std::vector<double>& expected) {
  std::vector<double> count(10, 0.0);
  for (int s = 0; s < seeds; ++s) {
    SamplerOptions o;
    o.n = kPoints;
    o.seed = 100 + s;
    o.domain = Domain::kBox;
    row.change(o, o.seed);
    kdm::gen::Density d;
    d.function = [map = row.map](const double* u) { return map.rho(u[0], u[1]); };
    d.thread_safe = true;
    const kdm::gen::SampleResult r = kdm::gen::sample(o, d);
    for (std::size_t j = 0; j < r.size(); ++j) count[row.map.band(r.points[2 * j], r.points[2 * j + 1])] += 1;
  }
  std::printf("| %s |", row.name.c_str());
  for (int b = 0; b < 10; ++b) std::printf(" %.3f |", count[b] / (expected[b] * seeds));
  std::printf("\n");
  std::fflush(stdout);
}

void print_table(const char* title, const std::vector<Row>& rows, int seeds) {
  const std::vector<double> expected = expected_counts(rows.front().map);
  std::printf("\n%s, %d points, %d seeds: count/target per tenth of the log density range, densest first\n\n",
              title, kPoints, seeds);
  std::printf("| expected points per run |");
  for (double e : expected) std::printf(" %.0f |", e);
  std::printf("\n|---|");
  for (int b = 0; b < 10; ++b) std::printf("---|");
  std::printf("\n");
  for (const Row& row : rows) print_row(row, seeds, expected);
}

}  // namespace

int main(int argc, char** argv) {
  const int seeds = argc > 1 ? std::max(1, std::atoi(argv[1])) : 4;
  const Map ramp{false}, radial{true};
  auto off = [](SamplerOptions& o) { o.count_balance = false; };
  print_table("Log ramp 1:1000 in a box",
              {{"default (count balance)", ramp, [](SamplerOptions&, std::uint64_t) {}},
               {"no count balance", ramp, [&](SamplerOptions& o, std::uint64_t) { off(o); }},
               {"no balance, no frozen kernels (σmax 1000)", ramp,
                [&](SamplerOptions& o, std::uint64_t) { off(o), o.sigma_max = 1000; }},
               {"no balance, 4× finer grid (peak density 0.1)", ramp,
                [&](SamplerOptions& o, std::uint64_t) { off(o), o.peak_density = 0.1; }},
               {"no balance, T = 0 on every level", ramp,
                [&](SamplerOptions& o, std::uint64_t) { off(o), o.temperature = 0; }},
               {"no balance, 300 finest sweeps", ramp,
                [&](SamplerOptions& o, std::uint64_t) { off(o), o.sweeps = 300, o.sigma_max = 1000; }},
               {"finest chain only, from the target's counts, 400 sweeps", ramp,
                [&](SamplerOptions& o, std::uint64_t seed) {
                  o.initial_points = exact_start(ramp, seed), o.sweeps = 400, o.sigma_max = 1000;
                }}},
              seeds);
  print_table(
      "Radial 1:1000: walls or none",
      {{"box, default", radial, [](SamplerOptions&, std::uint64_t) {}},
       {"box, no count balance", radial, [&](SamplerOptions& o, std::uint64_t) { off(o); }},
       {"torus, default", radial, [](SamplerOptions& o, std::uint64_t) { o.domain = Domain::kTorus; }},
       {"torus, no count balance", radial,
        [&](SamplerOptions& o, std::uint64_t) { off(o), o.domain = Domain::kTorus; }}},
      seeds);
  return 0;
}
