// Nearest-neighbour distances with a uniform cell list (expanding Chebyshev rings of cells around each
// point, stopped once no unvisited cell can hold a closer point), and their summary statistics
// δmin / δavg / NN1% / histogram as defined in docs/design.md §6 (normalised by d_hex or the FCC spacing).
#include "kdm/analysis/nearest_neighbour.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "cell_grid.h"
#include "coincident.h"
#include "kdm/analysis/common.h"
#include "parallel.h"

namespace kdm::analysis {

NearestNeighbours nearest_neighbours(const std::vector<double>& coords, int dim, bool torus, int threads,
                                     const Sides& sides) {
  validate_points(coords, dim);
  const std::size_t n = coords.size() / dim;
  if (n < 2) throw InvalidInput("nearest-neighbour statistics need at least 2 points");
  const int max_cells[3] = {dim == 2 ? 2048 : 160, dim == 2 ? 2048 : 160, 160};
  const detail::CellGrid grid(coords, dim, 2.0, max_cells, sides);
  // A point that stands on another has it as its nearest (the smallest such index, as the search's ties
  // pick): no search, which within a large group would compare every pair.
  const std::vector<std::size_t> partner = detail::distinct_positions(coords, dim).partner;
  NearestNeighbours out;
  out.dim = dim;
  out.distance.assign(n, 0.0);
  out.index.assign(n, 0);
  out.offset.assign(n * dim, 0.0);
  const std::ptrdiff_t chunk = 256;
  const std::ptrdiff_t chunks = (static_cast<std::ptrdiff_t>(n) + chunk - 1) / chunk;
  detail::parallel_for(chunks, threads, [&](std::ptrdiff_t ci, int) {
    const std::size_t i0 = static_cast<std::size_t>(ci * chunk);
    const std::size_t i1 = std::min(n, i0 + static_cast<std::size_t>(chunk));
    for (std::size_t i = i0; i < i1; ++i) {
      if (partner[i] != n) {
        out.index[i] = partner[i];  // distance and offset 0, as assigned
        continue;
      }
      const double* p = &coords[i * dim];
      int home[3] = {0, 0, 0};
      for (int a = 0; a < dim; ++a) home[a] = grid.axis_cell(p[a], a);
      double best = std::numeric_limits<double>::infinity();
      std::size_t best_j = i;
      auto visit = [&](const int* off) {
        int c[3] = {0, 0, 0};
        for (int a = 0; a < dim; ++a) {
          int v = home[a] + off[a];
          const int g = grid.g[a];
          if (torus) {
            v %= g;
            if (v < 0) v += g;
          } else if (v < 0 || v >= g) {
            return;
          }
          c[a] = v;
        }
        const std::size_t cell = grid.linear(c);
        for (std::size_t e = grid.start[cell]; e < grid.start[cell + 1]; ++e) {
          const std::size_t j = grid.order[e];
          if (j == i) continue;
          double d2 = 0;
          for (int a = 0; a < dim; ++a) {
            const double d = axis_delta(p[a], coords[j * dim + a], torus, sides[a]);
            d2 += d * d;
          }
          if (d2 < best || (d2 == best && j < best_j)) {
            best = d2;
            best_j = j;
          }
        }
      };
      for (int r = 0;; ++r) {
        const int rz = dim == 3 ? r : 0;
        for (int dz = -rz; dz <= rz; ++dz)
          for (int dy = -r; dy <= r; ++dy)
            for (int dx = -r; dx <= r; ++dx) {
              if (std::max({std::abs(dx), std::abs(dy), std::abs(dz)}) != r) continue;
              const int off[3] = {dx, dy, dz};
              visit(off);
            }
        const double reach = r * grid.h;
        const int g = *std::max_element(grid.g, grid.g + dim);
        const bool covered = torus ? 2 * r + 1 >= g : r >= g;
        if (covered || best <= reach * reach) break;
      }
      out.distance[i] = std::sqrt(best);
      out.index[i] = best_j;
      for (int a = 0; a < dim; ++a)
        out.offset[i * dim + a] = axis_delta(p[a], coords[best_j * dim + a], torus, sides[a]);
    }
  });
  return out;
}

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const double m = static_cast<double>(values.size());
  std::size_t rank = static_cast<std::size_t>(std::ceil(std::clamp(q, 0.0, 1.0) * m));
  rank = std::clamp<std::size_t>(rank, 1, values.size());
  std::nth_element(values.begin(), values.begin() + (rank - 1), values.end());
  return values[rank - 1];
}

NNStats summarise_nn(const std::vector<double>& distances, double spacing, int bins, double hist_max) {
  NNStats s;
  s.count = distances.size();
  s.spacing = spacing;
  s.hist_max = hist_max;
  s.histogram.assign(static_cast<std::size_t>(std::max(1, bins)), 0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (distances.empty()) {
    s.dmin = s.davg = s.nn1 = s.dmax = nan;
    return s;
  }
  double lo = std::numeric_limits<double>::infinity(), hi = 0, sum = 0;
  for (double d : distances) {
    const double v = d / spacing;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    sum += v;
    const double b = v / hist_max * static_cast<double>(s.histogram.size());
    const std::size_t bin = b >= static_cast<double>(s.histogram.size())
                                ? s.histogram.size() - 1
                                : static_cast<std::size_t>(std::max(0.0, b));
    ++s.histogram[bin];
    s.overflow += v >= hist_max;
  }
  s.dmin = lo;
  s.dmax = hi;
  s.davg = sum / static_cast<double>(distances.size());
  s.nn1 = quantile(distances, 0.01) / spacing;
  return s;
}

NNStats nn_stats(const std::vector<double>& coords, int dim, bool torus, int threads, const Sides& sides) {
  const NearestNeighbours nn = nearest_neighbours(coords, dim, torus, threads, sides);
  return summarise_nn(nn.distance, reference_spacing(dim, nn.distance.size()));
}

}  // namespace kdm::analysis
