// Pair-correlation function g(r): histogram of pair distances (cell list, neighbours within r_max) divided by
// the count a uniform random set would give, n(n−1)·|shell|; in the box each pair is weighted by the
// translation edge correction 1/Π(1−|Δ_a|), whose expectation restores the unbounded-domain count.
#include "kdm/analysis/pair_correlation.h"

#include <algorithm>
#include <cmath>

#include "cell_grid.h"
#include "coincident.h"
#include "kdm/analysis/common.h"
#include "parallel.h"

namespace kdm::analysis {
namespace {

constexpr double kPi = 3.14159265358979323846;

double ball_volume(int dim, double r) {
  return dim == 2 ? kPi * r * r : 4.0 / 3.0 * kPi * r * r * r;
}

// Adds the weighted pair histogram of one set (distances in unit lengths, bins of width `width`). Points at
// one position are counted as one with their multiplicity, so a group costs what one point does.
void pair_histogram(const std::vector<double>& points, int dim, bool torus, const Sides& sides, double r_abs,
                    int bins, int threads, std::vector<double>& hist) {
  const detail::DistinctPositions distinct = detail::distinct_positions(points, dim);
  const std::vector<double>& coords = distinct.any_coincident ? distinct.coords : points;
  const auto weight = [&](std::size_t i) { return distinct.any_coincident ? distinct.multiplicity[i] : 1.0; };
  const std::size_t n = coords.size() / dim;
  int max_cells[3];  // cell sides ≥ r_abs: neighbours lie in the 3^dim surrounding cells
  for (int a = 0; a < 3; ++a)
    max_cells[a] =
        std::min(std::max(1, static_cast<int>(std::floor(sides[a] / r_abs))), dim == 2 ? 4096 : 256);
  const detail::CellGrid grid(coords, dim, 1.0, max_cells, sides);
  const double width = r_abs / bins;
  const int workers = detail::worker_count(threads, static_cast<std::ptrdiff_t>(n));
  std::vector<std::vector<double>> local(workers, std::vector<double>(bins, 0.0));
  const std::ptrdiff_t chunk = 256, chunks = (static_cast<std::ptrdiff_t>(n) + chunk - 1) / chunk;
  detail::parallel_for(chunks, workers, [&](std::ptrdiff_t ci, int w) {
    std::vector<double>& h = local[w];
    std::vector<std::size_t> cells;
    for (std::size_t i = ci * chunk; i < std::min(n, static_cast<std::size_t>((ci + 1) * chunk)); ++i) {
      const double* p = &coords[i * dim];
      const double w = weight(i);
      h[0] += w * (w - 1);  // the ordered pairs of the points standing at p, at distance 0
      int home[3] = {0, 0, 0};
      for (int a = 0; a < dim; ++a) home[a] = grid.axis_cell(p[a], a);
      cells.clear();
      const int rz = dim == 3 ? 1 : 0;
      for (int dz = -rz; dz <= rz; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int off[3] = {dx, dy, dz};
            int c[3] = {0, 0, 0};
            bool inside = true;
            for (int a = 0; a < dim; ++a) {
              int v = home[a] + off[a];
              const int g = grid.g[a];
              if (torus)
                v = ((v % g) + g) % g;
              else if (v < 0 || v >= g)
                inside = false;
              c[a] = v;
            }
            if (inside) cells.push_back(grid.linear(c));
          }
      std::sort(cells.begin(), cells.end());  // small grids wrap onto the same cell: visit it once
      cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
      for (std::size_t cell : cells)
        for (std::size_t e = grid.start[cell]; e < grid.start[cell + 1]; ++e) {
          const std::size_t j = grid.order[e];
          if (j == i) continue;
          double d2 = 0, cover = 1;
          for (int a = 0; a < dim; ++a) {
            const double d = axis_delta(p[a], coords[j * dim + a], torus);  // normalised
            const double along = sides[a] == 1 ? d : d * sides[a];
            d2 += along * along;
            cover *= 1.0 - std::abs(d);  // the share of the box a translate by d keeps, in any lengths
          }
          const double d = std::sqrt(d2);
          if (d >= r_abs) continue;
          const int b = std::min(bins - 1, static_cast<int>(d / width));
          h[b] += w * weight(j) * (torus ? 1.0 : 1.0 / cover);
        }
    }
  });
  for (const auto& h : local)
    for (int b = 0; b < bins; ++b) hist[b] += h[b];
}

}  // namespace

PairCorrelation pair_correlation(const std::vector<tools::PointSet>& sets, bool torus, double r_max, int bins,
                                 int threads, const Sides& sides) {
  if (sets.empty()) throw InvalidInput("no point sets to analyse");
  if (bins < 1 || !(r_max > 0)) throw InvalidInput("pair correlation needs bins >= 1 and r_max > 0");
  const int dim = sets[0].dim;
  double total = 0;
  for (const tools::PointSet& s : sets) {
    if (s.dim != dim) throw InvalidInput("point sets mix dimensions");
    validate_points(s.coords, s.dim);
    if (s.size() < 2) throw InvalidInput("pair correlation needs at least 2 points per set");
    total += static_cast<double>(s.size());
  }
  PairCorrelation out;
  out.spacing = reference_spacing(dim, static_cast<std::size_t>(std::llround(total / sets.size())));
  const double shortest = *std::min_element(sides.begin(), sides.begin() + dim);
  out.r_max = std::min(r_max, 0.5 * shortest / out.spacing);
  const double r_abs = out.r_max * out.spacing;
  std::vector<double> hist(bins, 0.0), expected(bins, 0.0);
  for (const tools::PointSet& s : sets) {
    pair_histogram(s.coords, dim, torus, sides, r_abs, bins, threads, hist);
    const double pairs = static_cast<double>(s.size()) * static_cast<double>(s.size() - 1);
    for (int b = 0; b < bins; ++b)
      expected[b] += pairs * (ball_volume(dim, r_abs * (b + 1) / bins) - ball_volume(dim, r_abs * b / bins));
  }
  for (int b = 0; b < bins; ++b) {
    out.r.push_back(out.r_max * (b + 0.5) / bins);
    out.g.push_back(hist[b] / expected[b]);
  }
  return out;
}

}  // namespace kdm::analysis
