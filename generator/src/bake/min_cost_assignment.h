// Least-cost assignment on a sparse bipartite graph by successive shortest augmenting paths
// (R. Jonker, A. Volgenant, "A shortest augmenting path algorithm for dense and sparse linear assignment
// problems", Computing 38, 1987), Dijkstra on reduced costs with node potentials.
//
// The hand-over between depths matches every point of a parent patch to one sub-point (docs/design.md §3):
// the least total squared distance keeps glides short, and each point has only its few dozen nearest
// sub-points as candidates, so the graph is sparse. A row's search stops at the first free column it
// reaches; rows placed in order of a spatial sweep mostly find one a step away.
//
// Thread safety: a pure function.
#pragma once

#include <cstdint>
#include <vector>

namespace kdm::gen {

/// One candidate pairing: `row` may take `column` at `cost` (finite, ≥ 0).
struct AssignmentEdge {
  std::uint32_t row = 0, column = 0;
  double cost = 0;
};

/// Assigns every row in [0, rows) to a distinct column in [0, columns) through `edges`, at the least total
/// cost. On success returns true and fills `row_column` (rows values); returns false (row_column emptied)
/// if no assignment covers every row. Edges naming a row or column out of range are a bug (CHECK).
bool min_cost_assignment(std::uint32_t rows, std::uint32_t columns, const std::vector<AssignmentEdge>& edges,
                         std::vector<std::uint32_t>& row_column);

}  // namespace kdm::gen
