// Least-cost sparse assignment (bake/min_cost_assignment.h) against exhaustive search on small graphs, and
// on a large spatial matching against the greedy nearest-first matching it must never lose to.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "bake/min_cost_assignment.h"

namespace kdm::gen {
namespace {

constexpr double kNone = std::numeric_limits<double>::infinity();

// The least total cost of giving each row a distinct column, by trying every choice (kNone if none).
double exhaustive(std::uint32_t rows, std::uint32_t columns, const std::vector<double>& cost, std::uint32_t r,
                  std::vector<char>& used) {
  if (r == rows) return 0;
  double best = kNone;
  for (std::uint32_t c = 0; c < columns; ++c) {
    if (used[c] || cost[r * columns + c] == kNone) continue;
    used[c] = 1;
    best = std::min(best, cost[r * columns + c] + exhaustive(rows, columns, cost, r + 1, used));
    used[c] = 0;
  }
  return best;
}

double total(const std::vector<AssignmentEdge>& edges, const std::vector<std::uint32_t>& row_column) {
  double sum = 0;
  for (std::uint32_t r = 0; r < row_column.size(); ++r) {
    double cheapest = kNone;  // duplicates may list a pair twice: the cheaper edge is the one taken
    for (const AssignmentEdge& e : edges)
      if (e.row == r && e.column == row_column[r]) cheapest = std::min(cheapest, e.cost);
    sum += cheapest;
  }
  return sum;
}

TEST(AssignmentTest, MatchesExhaustiveSearchOnSmallSparseGraphs) {
  std::mt19937_64 rng(7);
  int infeasible = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const std::uint32_t rows = 1 + rng() % 6, columns = rows + rng() % 3;
    std::vector<double> cost(std::size_t(rows) * columns, kNone);
    std::vector<AssignmentEdge> edges;
    for (std::uint32_t r = 0; r < rows; ++r)
      for (std::uint32_t c = 0; c < columns; ++c)
        if (rng() % 10 < 5) {
          cost[r * columns + c] = double(rng() % 1000) / 100;  // ties too
          edges.push_back({r, c, cost[r * columns + c]});
        }
    std::shuffle(edges.begin(), edges.end(), rng);
    std::vector<char> used(columns, 0);
    const double best = exhaustive(rows, columns, cost, 0, used);
    std::vector<std::uint32_t> row_column;
    const bool found = min_cost_assignment(rows, columns, edges, row_column);
    ASSERT_EQ(found, best != kNone) << "trial " << trial;
    if (!found) {
      ++infeasible;
      EXPECT_TRUE(row_column.empty());
      continue;
    }
    ASSERT_EQ(row_column.size(), rows);
    std::vector<std::uint32_t> sorted = row_column;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end()) << "a column taken twice";
    EXPECT_NEAR(total(edges, row_column), best, 1e-9) << "trial " << trial;
  }
  EXPECT_GT(infeasible, 10);  // both outcomes were exercised
  EXPECT_LT(infeasible, 300);
}

TEST(AssignmentTest, BeatsGreedyOnASpatialMatchingWithNearestCandidates) {
  // 2,000 points to 2,100 others in the unit square, each with its 12 nearest as candidates (squared
  // distance): the shape of the hand-over's matchings.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  const std::uint32_t rows = 2000, columns = 2100;
  std::vector<double> a(2 * rows), b(2 * columns);
  for (double& v : a) v = u(rng);
  for (double& v : b) v = u(rng);
  std::vector<AssignmentEdge> edges;
  for (std::uint32_t r = 0; r < rows; ++r) {
    std::vector<std::pair<double, std::uint32_t>> near;
    for (std::uint32_t c = 0; c < columns; ++c)
      near.push_back({std::pow(a[2 * r] - b[2 * c], 2) + std::pow(a[2 * r + 1] - b[2 * c + 1], 2), c});
    std::partial_sort(near.begin(), near.begin() + 12, near.end());
    for (int k = 0; k < 12; ++k) edges.push_back({r, near[k].second, near[k].first});
  }
  std::vector<std::uint32_t> row_column;
  ASSERT_TRUE(min_cost_assignment(rows, columns, edges, row_column));
  std::vector<char> used(columns, 0);
  double cost = 0;
  for (std::uint32_t r = 0; r < rows; ++r) {
    ASSERT_FALSE(used[row_column[r]]);
    used[row_column[r]] = 1;
    cost +=
        std::pow(a[2 * r] - b[2 * row_column[r]], 2) + std::pow(a[2 * r + 1] - b[2 * row_column[r] + 1], 2);
  }
  // Greedy: the globally shortest remaining pair first, any distance.
  std::vector<std::pair<double, std::pair<std::uint32_t, std::uint32_t>>> pairs;
  for (std::uint32_t r = 0; r < rows; ++r)
    for (std::uint32_t c = 0; c < columns; ++c)
      pairs.push_back({std::pow(a[2 * r] - b[2 * c], 2) + std::pow(a[2 * r + 1] - b[2 * c + 1], 2), {r, c}});
  std::sort(pairs.begin(), pairs.end());
  std::vector<char> row_done(rows, 0), column_done(columns, 0);
  double greedy = 0;
  for (const auto& [d, rc] : pairs)
    if (!row_done[rc.first] && !column_done[rc.second]) {
      row_done[rc.first] = column_done[rc.second] = 1;
      greedy += d;
    }
  EXPECT_LT(cost, greedy);
}

}  // namespace
}  // namespace kdm::gen
