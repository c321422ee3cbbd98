// A random grid of cuts through a query's region, for the tests that a region's parts give its points.
#pragma once

#include <algorithm>
#include <random>
#include <vector>

#include "kdm/runtime/query.h"

namespace kdm::testing {

/// The parts of `whole`'s region cut at `cuts` random places along each axis (through tiles and points'
/// neighbourhoods alike), each the query `whole` over one cell of the grid, rows of x within y.
inline std::vector<QueryParams> random_grid_parts(const QueryParams& whole, int cuts, std::mt19937& rng) {
  std::vector<double> xs = {whole.x0, whole.x1}, ys = {whole.y0, whole.y1};
  for (int i = 0; i < cuts; ++i) {
    xs.push_back(whole.x0 + (whole.x1 - whole.x0) * std::uniform_real_distribution<>(0, 1)(rng));
    ys.push_back(whole.y0 + (whole.y1 - whole.y0) * std::uniform_real_distribution<>(0, 1)(rng));
  }
  std::sort(xs.begin(), xs.end());
  std::sort(ys.begin(), ys.end());
  std::vector<QueryParams> parts;
  for (std::size_t i = 0; i + 1 < xs.size(); ++i)
    for (std::size_t j = 0; j + 1 < ys.size(); ++j) {
      QueryParams part = whole;
      part.x0 = xs[i], part.x1 = xs[i + 1], part.y0 = ys[j], part.y1 = ys[j + 1];
      parts.push_back(part);
    }
  return parts;
}

}  // namespace kdm::testing
