// Least-cost sparse assignment; see min_cost_assignment.h.
#include "bake/min_cost_assignment.h"

#include <functional>
#include <limits>
#include <queue>
#include <utility>

#include "kdm/runtime/check.h"

namespace kdm::gen {

namespace {

constexpr std::uint32_t kFree = std::numeric_limits<std::uint32_t>::max();
constexpr double kUnreached = std::numeric_limits<double>::infinity();

}  // namespace

bool min_cost_assignment(std::uint32_t rows, std::uint32_t columns, const std::vector<AssignmentEdge>& edges,
                         std::vector<std::uint32_t>& row_column) {
  row_column.clear();
  // Edges by row (compressed rows).
  std::vector<std::uint32_t> start(std::size_t(rows) + 1, 0);
  for (const AssignmentEdge& e : edges) {
    KDM_CHECK(e.row < rows && e.column < columns && e.cost >= 0);
    ++start[e.row + 1];
  }
  for (std::uint32_t r = 0; r < rows; ++r) start[r + 1] += start[r];
  std::vector<std::pair<std::uint32_t, double>> adjacent(edges.size());
  {
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (const AssignmentEdge& e : edges) adjacent[fill[e.row]++] = {e.column, e.cost};
  }

  // Reduced cost of row r taking column c: cost + row_potential[r] − column_potential[c] ≥ 0, and 0 on
  // every matched pair, so Dijkstra finds shortest augmenting paths.
  std::vector<double> row_potential(rows, 0), column_potential(columns, 0);
  std::vector<std::uint32_t> column_row(columns, kFree), assigned(rows, kFree);
  std::vector<double> distance(columns, kUnreached);
  std::vector<std::uint32_t> reached_from(columns, kFree);
  std::vector<char> settled(columns, 0);
  std::vector<std::uint32_t> touched, settled_columns;
  std::vector<std::pair<std::uint32_t, double>> expanded_rows;  // (row, its distance)
  using Entry = std::pair<double, std::uint32_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;

  for (std::uint32_t source = 0; source < rows; ++source) {
    auto expand = [&](std::uint32_t r, double d) {
      expanded_rows.push_back({r, d});
      for (std::uint32_t k = start[r]; k < start[r + 1]; ++k) {
        const auto [c, cost] = adjacent[k];
        if (settled[c]) continue;
        const double candidate = d + cost + row_potential[r] - column_potential[c];
        if (candidate < distance[c]) {
          if (distance[c] == kUnreached) touched.push_back(c);
          distance[c] = candidate;
          reached_from[c] = r;
          queue.push({candidate, c});
        }
      }
    };
    expand(source, 0);
    std::uint32_t end = kFree;
    double shortest = 0;
    while (!queue.empty()) {
      const auto [d, c] = queue.top();
      queue.pop();
      if (settled[c] || d > distance[c]) continue;
      settled[c] = 1;
      if (column_row[c] == kFree) {
        end = c;
        shortest = d;
        break;
      }
      settled_columns.push_back(c);
      expand(column_row[c], d);
    }
    if (end == kFree) return false;
    // Potentials: + min(distance, shortest), less the common shift `shortest`.
    for (const auto& [r, d] : expanded_rows) row_potential[r] += d - shortest;
    for (std::uint32_t c : settled_columns) column_potential[c] += distance[c] - shortest;
    for (std::uint32_t c = end;;) {  // augment along the path
      const std::uint32_t r = reached_from[c], previous = assigned[r];
      assigned[r] = c;
      column_row[c] = r;
      if (r == source) break;
      c = previous;
    }
    for (std::uint32_t c : touched) {
      distance[c] = kUnreached;
      settled[c] = 0;
    }
    touched.clear();
    settled_columns.clear();
    expanded_rows.clear();
    queue = {};
  }
  row_column = std::move(assigned);
  return true;
}

}  // namespace kdm::gen
