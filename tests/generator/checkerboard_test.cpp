// The parallel sweep's schedule (checkerboard.h) and the level set-up on many threads (Chain::splat_all):
// the same order and the same bits as the one-thread definitions, for any thread count.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <thread>
#include <vector>

#include "sampler/chain.h"
#include "sampler/checkerboard.h"
#include "sampler/rng.h"

namespace kdm::gen {
namespace {

template <int D>
std::vector<Particle<D>> random_particles(const Grid<D>& g, std::size_t n, std::uint64_t seed) {
  Rng rng(seed, 1);
  std::vector<Particle<D>> out(n);
  for (auto& p : out) {
    for (int k = 0; k < D; ++k) p.x[k] = rng.uniform() * g.dims[k];
    p.active = rng.below(10) != 0;  // some background kernels, which the sweep skips
  }
  return out;
}

template <int D>
int cell_index(const Checkerboard<D>& board, const Vec<D>& x) {
  int id = 0, mul = 1;
  for (int k = 0; k < D; ++k) {
    const int c =
        std::clamp(static_cast<int>(x[k] / board.cell_width()[k]), 0, board.cells_per_axis()[k] - 1);
    id += c * mul;
    mul *= board.cells_per_axis()[k];
  }
  return id;
}

// The definition of the order: cells in storage order, ascending particle index within a cell.
template <int D>
void expect_serial_order(const Checkerboard<D>& board, const std::vector<Particle<D>>& particles,
                         const std::vector<Particle<D>>& sorted, const char* what, int threads) {
  std::vector<int> expected;
  for (int c = 0; c < board.cell_count(); ++c) {
    ASSERT_EQ(board.first(c), static_cast<int>(expected.size())) << what << ", threads " << threads;
    for (std::size_t j = 0; j < particles.size(); ++j)
      if (particles[j].active && cell_index<D>(board, particles[j].x) == c)
        expected.push_back(static_cast<int>(j));
  }
  ASSERT_EQ(board.order(), expected) << what << ", threads " << threads;
  ASSERT_EQ(sorted.size(), expected.size());
  for (std::size_t t = 0; t < expected.size(); ++t) ASSERT_EQ(sorted[t].x, particles[expected[t]].x) << what;
}

TEST(CheckerboardTest, SortMatchesTheSerialDefinitionForAnyThreadCount) {
  Grid<2> g;
  g.dims = {1008, 760};
  const auto particles = random_particles(g, 30000, 3);  // past the size where the sort runs in parallel
  for (const int threads : {1, 2, 3, 5}) {
    Checkerboard<2> board;
    board.layout(g, 15.0);
    std::vector<Particle<2>> sorted;
    board.sort(particles, threads, sorted);
    expect_serial_order(board, particles, sorted, "sort", threads);
  }
}

// After the particles move (most a little, as in a sweep, some across several cells), resorting the last
// order gives what sorting them afresh by index gives, sweep after sweep.
TEST(CheckerboardTest, ResortMatchesTheSerialDefinitionForAnyThreadCount) {
  Grid<2> g;
  g.dims = {1008, 760};
  for (const int threads : {1, 2, 3, 5}) {
    auto particles = random_particles(g, 30000, 4);
    Checkerboard<2> board;
    board.layout(g, 15.0);
    std::vector<Particle<2>> sorted;
    board.sort(particles, threads, sorted);
    Rng rng(9, static_cast<std::uint64_t>(threads));
    for (int sweep = 0; sweep < 3; ++sweep) {
      for (std::size_t t = 0; t < sorted.size(); ++t) {
        Particle<2>& p = particles[board.order()[t]];
        const double reach = rng.below(20) == 0 ? 200.0 : 8.0;
        for (int k = 0; k < 2; ++k)
          p.x[k] = std::fmod(p.x[k] + (2 * rng.uniform() - 1) * reach + g.dims[k], double(g.dims[k]));
        sorted[t] = p;
      }
      board.resort(sorted, threads);
      expect_serial_order(board, particles, sorted, "resort", threads);
    }
  }
}

// Two cells of one colour are never neighbours, across the torus seam included, and every cell is at
// least two reaches wide: two kernels updated at once never touch the same node.
TEST(CheckerboardTest, CellsOfOneColourNeverTouch) {
  for (const int side : {63, 126, 504, 1008, 2016}) {
    Grid<2> g;
    g.dims = {side, side / 2 * 2};
    const double reach = 15.0;
    Checkerboard<2> board;
    board.layout(g, reach);
    const auto n = board.cells_per_axis();
    for (int k = 0; k < 2; ++k) {
      if (n[k] == 1) continue;
      EXPECT_GE(board.cell_width()[k], 2 * reach) << "side " << side;
      EXPECT_EQ(n[k] % 2, 0) << "side " << side;
    }
    int listed = 0;
    for (int colour = 0; colour < 4; ++colour) {
      const std::vector<int>& cells = board.cells_of_colour(colour);
      listed += static_cast<int>(cells.size());
      for (int a : cells)
        for (int b : cells) {
          if (a == b) continue;
          bool neighbours = true;
          for (int k = 0, ra = a, rb = b; k < 2; ++k, ra /= n[k - 1], rb /= n[k - 1]) {
            const int d = std::abs(ra % n[k] - rb % n[k]);
            neighbours = neighbours && (d <= 1 || d == n[k] - 1);
          }
          EXPECT_FALSE(neighbours) << "side " << side << " cells " << a << " and " << b;
        }
    }
    EXPECT_EQ(listed, board.cell_count());
  }
}

// Every cell is claimed exactly once however the threads race, owners take their runs front to back, and
// the runs hold about equal numbers of updates.
TEST(CheckerboardTest, CellRunsHandOutEveryCellOnce) {
  constexpr int kCells = 997, kThreads = 4;
  std::vector<int> updates(kCells);
  for (int i = 0; i < kCells; ++i) updates[i] = 50 + (i * 37) % 400;
  for (int round = 0; round < 50; ++round) {
    CellRuns runs;
    runs.share(kCells, kThreads, [&](int i) { return updates[i]; });
    std::vector<std::atomic<int>> claimed(kCells);
    std::vector<std::vector<int>> own(kThreads);
    std::vector<std::thread> workers;
    for (int thread = 0; thread < kThreads; ++thread)
      workers.emplace_back([&, thread] {
        int ci, next;
        while ((ci = runs.claim(thread, true, next)) >= 0) {
          own[thread].push_back(ci);
          claimed[ci].fetch_add(1);
        }
        for (int k = 1; k < kThreads; ++k)
          while ((ci = runs.claim((thread + k) % kThreads, false, next)) >= 0) claimed[ci].fetch_add(1);
      });
    for (auto& w : workers) w.join();
    for (int i = 0; i < kCells; ++i) ASSERT_EQ(claimed[i].load(), 1) << "cell " << i << " round " << round;
    for (const auto& cells : own) ASSERT_TRUE(std::is_sorted(cells.begin(), cells.end()));
  }
  // Balance: the cut falls within one cell of the ideal share.
  CellRuns runs;
  runs.share(kCells, kThreads, [&](int i) { return updates[i]; });
  std::int64_t total = 0;
  for (int u : updates) total += u;
  int start = 0;
  for (int r = 0; r < kThreads; ++r) {
    std::int64_t held = 0;
    int ci, next;
    while ((ci = runs.claim(r, true, next)) >= 0) {
      EXPECT_EQ(ci, start++);
      held += updates[ci];
    }
    EXPECT_NEAR(double(held), double(total) / kThreads, 450.0) << "run " << r;
  }
  EXPECT_EQ(start, kCells);
}

template <int D>
void expect_splat_all_matches_splat(bool torus, bool varying) {
  DensityGrid<D> d;
  d.grid.dims.fill(D == 2 ? 96 : 32);
  d.grid.torus = torus;
  d.rho.resize(static_cast<std::size_t>(d.grid.size()));
  for (std::size_t i = 0; i < d.rho.size(); ++i)
    d.rho[i] = varying ? 0.02f + 0.4f * static_cast<float>(i % d.grid.dims[0]) / d.grid.dims[0] : 0.43f;
  auto particles = random_particles(d.grid, D == 2 ? 3000 : 4000, 7);
  for (std::size_t j = 0; j < particles.size(); ++j) particles[j].splits = j % 7 == 0 ? 1 : 0;
  Chain<D> one(d, ChainParams{});
  typename Chain<D>::Scratch s;
  for (const auto& p : particles) one.splat(p, 1.0f, s);
  for (const int threads : {1, 2, 3, 7}) {
    Chain<D> many(d, ChainParams{});
    many.splat_all(particles, threads);
    ASSERT_EQ(
        std::memcmp(many.residual().data(), one.residual().data(), one.residual().size() * sizeof(float)), 0)
        << "D " << D << " torus " << torus << " varying " << varying << " threads " << threads;
  }
}

TEST(SplatAllTest, SameBitsAsSplattingOneByOne) {
  for (const bool torus : {true, false})
    for (const bool varying : {false, true}) {
      expect_splat_all_matches_splat<2>(torus, varying);
      expect_splat_all_matches_splat<3>(torus, varying);
    }
}

}  // namespace
}  // namespace kdm::gen
