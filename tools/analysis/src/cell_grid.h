// Internal: a uniform cell list over the unit square/cube, or a rectangle/box of given sides (counting sort
// of points into cells), shared by the nearest-neighbour search and the pair-correlation function.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "kdm/analysis/common.h"

namespace kdm::analysis::detail {

struct CellGrid {
  int dim = 2;
  int g[3] = {1, 1, 1};            // cells per axis
  double h = 1;                    // shortest cell side in the domain's lengths (1/g on the unit square)
  std::vector<std::size_t> start;  // start[c]..start[c+1]: entries of cell c in `order`
  std::vector<std::size_t> order;  // point indices sorted by cell

  int axis_cell(double v, int a) const { return std::min(g[a] - 1, std::max(0, static_cast<int>(v * g[a]))); }
  std::size_t cell_of(const double* p) const {
    std::size_t c = 0;
    for (int a = dim - 1; a >= 0; --a) c = c * g[a] + axis_cell(p[a], a);
    return c;
  }

  /// Builds the grid with about `per_cell` points per cell over a domain of sides `sides` (cells about
  /// square in its lengths), at most `max_cells[a]` along axis a.
  CellGrid(const std::vector<double>& coords, int dim_, double per_cell, const int* max_cells,
           const Sides& sides)
      : dim(dim_) {
    const std::size_t n = coords.size() / dim;
    const double cells = std::max(1.0, static_cast<double>(n) / per_cell);
    const double across = std::floor(std::pow(cells, 1.0 / dim));
    std::size_t total = 1;
    h = HUGE_VAL;
    for (int a = 0; a < dim; ++a) {
      // A unit side keeps the unit square's cells (and their bits) exactly.
      const double along = sides[a] == 1 ? across : std::floor(std::pow(cells, 1.0 / dim) * sides[a]);
      g[a] = std::clamp(static_cast<int>(std::min(along, 1e9)), 1, max_cells[a]);
      h = std::min(h, sides[a] == 1 ? 1.0 / g[a] : sides[a] / g[a]);
      total *= static_cast<std::size_t>(g[a]);
    }
    start.assign(total + 1, 0);
    std::vector<std::size_t> cell(n);
    for (std::size_t i = 0; i < n; ++i) {
      cell[i] = cell_of(&coords[i * dim]);
      ++start[cell[i] + 1];
    }
    for (std::size_t c = 0; c < total; ++c) start[c + 1] += start[c];
    order.resize(n);
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) order[fill[cell[i]]++] = i;
  }

  /// Linear cell index of integer cell coordinates (already wrapped/clipped to [0, g)).
  std::size_t linear(const int* c) const {
    std::size_t idx = 0;
    for (int a = dim - 1; a >= 0; --a) idx = idx * g[a] + c[a];
    return idx;
  }
};

}  // namespace kdm::analysis::detail
