// Internal: a uniform cell list over the unit square/cube (counting sort of points into G^dim cells),
// shared by the nearest-neighbour search and the pair-correlation function.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace kdm::analysis::detail {

struct CellGrid {
  int dim = 2;
  int g = 1;                       // cells per axis
  double h = 1;                    // cell side = 1/g
  std::vector<std::size_t> start;  // start[c]..start[c+1]: entries of cell c in `order`
  std::vector<std::size_t> order;  // point indices sorted by cell

  int axis_cell(double v) const { return std::min(g - 1, std::max(0, static_cast<int>(v * g))); }
  std::size_t cell_of(const double* p) const {
    std::size_t c = 0;
    for (int a = dim - 1; a >= 0; --a) c = c * g + axis_cell(p[a]);
    return c;
  }

  /// Builds the grid with about `per_cell` points per cell (at most `max_cells_per_axis` per axis).
  CellGrid(const std::vector<double>& coords, int dim_, double per_cell, int max_cells_per_axis) : dim(dim_) {
    const std::size_t n = coords.size() / dim;
    const double cells = std::max(1.0, static_cast<double>(n) / per_cell);
    g = std::clamp(static_cast<int>(std::floor(std::pow(cells, 1.0 / dim))), 1, max_cells_per_axis);
    h = 1.0 / g;
    std::size_t total = 1;
    for (int a = 0; a < dim; ++a) total *= static_cast<std::size_t>(g);
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
    for (int a = dim - 1; a >= 0; --a) idx = idx * g + c[a];
    return idx;
  }
};

}  // namespace kdm::analysis::detail
