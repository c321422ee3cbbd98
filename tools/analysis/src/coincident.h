// Internal: points at exactly the same position, found once by sorting, so that the cell-list searches
// need not compare every pair of a group (a stuck generator's or rounded coordinates' thousands of points
// in one cell cost time as the square of the group otherwise).
#pragma once

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <vector>

namespace kdm::analysis::detail {

/// The set's distinct positions, each with how many points stand there.
struct DistinctPositions {
  std::vector<double> coords;        // dim values per distinct position, in order of first appearance
  std::vector<double> multiplicity;  // points at each
  /// partner[i]: the smallest index of another point at point i's position, or n if it stands alone.
  std::vector<std::size_t> partner;
  bool any_coincident = false;
};

inline DistinctPositions distinct_positions(const std::vector<double>& coords, int dim) {
  const std::size_t n = coords.size() / static_cast<std::size_t>(dim);
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  const auto at = [&](std::size_t i, int a) { return coords[i * static_cast<std::size_t>(dim) + a]; };
  const auto same = [&](std::size_t i, std::size_t j) {
    for (int a = 0; a < dim; ++a)
      if (at(i, a) != at(j, a)) return false;
    return true;
  };
  // By position, then index: a group's members end up together, its smallest index first.
  std::sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) {
    for (int a = 0; a < dim; ++a)
      if (at(i, a) != at(j, a)) return at(i, a) < at(j, a);
    return i < j;
  });
  DistinctPositions out;
  out.partner.assign(n, n);
  std::vector<std::size_t> group_of(n);  // the smallest index of each point's group
  for (std::size_t s = 0; s < n;) {
    std::size_t e = s + 1;
    while (e < n && same(order[s], order[e])) ++e;
    if (e - s > 1) {
      out.any_coincident = true;
      for (std::size_t k = s; k < e; ++k) out.partner[order[k]] = k == s ? order[s + 1] : order[s];
    }
    for (std::size_t k = s; k < e; ++k) group_of[order[k]] = order[s];
    s = e;
  }
  if (!out.any_coincident) return out;
  std::vector<std::size_t> slot(n, n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t first = group_of[i];
    if (slot[first] == n) {
      slot[first] = out.multiplicity.size();
      out.multiplicity.push_back(0);
      for (int a = 0; a < dim; ++a) out.coords.push_back(at(i, a));
    }
    out.multiplicity[slot[first]] += 1;
  }
  return out;
}

}  // namespace kdm::analysis::detail
