// Point sets with known statistics for the analysis tests (fixed seeds).
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "point_io.h"

namespace kdm::analysis::testing {

/// n uniform random points in [0,1)^dim (binomial process).
inline tools::PointSet uniform_set(std::size_t n, unsigned seed, int dim = 2) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  tools::PointSet s;
  s.dim = dim;
  s.coords.resize(n * dim);
  for (double& v : s.coords) v = u(rng);
  return s;
}

/// One point uniform in each cell of an m×m grid.
inline tools::PointSet jittered_grid(int m, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  tools::PointSet s;
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) {
      s.coords.push_back((i + u(rng)) / m);
      s.coords.push_back((j + u(rng)) / m);
    }
  return s;
}

/// A near-hexagonal lattice that tiles the unit torus: `rows` (even) rows of `cols` points, odd rows shifted
/// by half a column. Basis a1 = (1/cols, 0), a2 = (1/(2 cols), 1/rows).
inline tools::PointSet torus_hex_lattice(int cols, int rows) {
  tools::PointSet s;
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < cols; ++i) {
      s.coords.push_back((i + 0.5 * (j % 2)) / cols);
      s.coords.push_back(static_cast<double>(j) / rows);
    }
  return s;
}

}  // namespace kdm::analysis::testing
