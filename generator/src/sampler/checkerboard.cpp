#include "sampler/checkerboard.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "kdm/runtime/check.h"
#include "platform/huge_pages.h"
#include "platform/parallel.h"

namespace kdm::gen {

template <int D>
void Checkerboard<D>::layout(const Grid<D>& g, double reach) {
  total_cells_ = 1;
  offset_ = {};
  torus_ = g.torus;
  for (int k = 0; k < D; ++k) {
    extent_[k] = g.dims[k];
    // Wider cells where the grid has room for at least 8 along the axis: each colour then touches less
    // of the grid through its cells' borders (the residual is streamed once per colour).
    int c = static_cast<int>(std::min(1e9, std::floor(g.dims[k] / std::max(2 * reach, 64.0))));
    if (c < 8) c = static_cast<int>(std::min(1e9, std::floor(g.dims[k] / (2 * reach))));
    if (c < 1) c = 1;
    if (g.torus && c > 1 && (c & 1)) --c;  // an odd count would put two cells of one colour side by side
    ncell_[k] = c;
    width_[k] = double(g.dims[k]) / c;
    total_cells_ *= c;
  }
  for (auto& cells : cells_by_colour_) cells.clear();
  for (int c = 0; c < total_cells_; ++c) {
    int colour = 0, rest = c;
    for (int k = 0; k < D; ++k) {
      colour |= ((rest % ncell_[k]) & 1) << k;
      rest /= ncell_[k];
    }
    cells_by_colour_[colour].push_back(c);
  }
}

template <int D>
int Checkerboard<D>::cell_of(const Vec<D>& x) const {
  int id = 0, mul = 1;
  for (int k = 0; k < D; ++k) {
    double u = x[k] - offset_[k];
    if (torus_ && u < 0) u += extent_[k];  // the cell the offset moves across the torus's seam
    const int c = std::clamp(static_cast<int>(u / width_[k]), 0, ncell_[k] - 1);
    id += c * mul;
    mul *= ncell_[k];
  }
  return id;
}

template <int D>
int Checkerboard<D>::place_runs(int runs, std::size_t stride) {
  const std::size_t cells = static_cast<std::size_t>(total_cells_);
  first_in_cell_.resize(cells + 1);
  int placed = 0;
  for (std::size_t c = 0; c < cells; ++c) {
    first_in_cell_[c] = placed;
    for (int run = 0; run < runs; ++run) {
      const int count = run_slots_[stride * run + c];
      run_slots_[stride * run + c] = placed;
      placed += count;
    }
  }
  first_in_cell_[cells] = placed;
  return placed;
}

namespace {

// Each run's counters on cache lines of their own: shared lines made the sort of a 1,024-point level
// ten times slower on two threads than on one.
std::size_t run_stride(int cells) {
  return (static_cast<std::size_t>(cells) + 15) / 16 * 16 + 16;
}

// [lo, hi) of run `run` of `runs` over n items.
void run_range(std::int64_t n, int run, int runs, std::int64_t& lo, std::int64_t& hi) {
  lo = n * run / runs;
  hi = n * (run + 1) / runs;
}

}  // namespace

template <int D>
void Checkerboard<D>::sort(const std::vector<Particle<D>>& particles, int threads,
                           std::vector<Particle<D>>& sorted) {
  // A counting sort in three passes, the first and last over `runs` contiguous runs of particles at once.
  // Each run counts its particles per cell; a run's particles of cell c go after those of earlier runs,
  // which is the serial order exactly.
  const std::int64_t n = static_cast<std::int64_t>(particles.size());
  const int runs = std::max(1, threads);
  const std::size_t stride = run_stride(total_cells_);
  resize_on_huge_pages(cell_, particles.size());
  run_slots_.assign(stride * runs, 0);
  // Small levels sort faster on one thread than the team takes to start.
  const bool parallel = runs > 1 && n >= kParallelFrom;
  for_each_part(runs, parallel, [&](int run, int) {
    std::int64_t lo, hi;
    run_range(n, run, runs, lo, hi);
    int* count = run_slots_.data() + stride * run;
    for (std::int64_t j = lo; j < hi; ++j) {
      const int c = particles[j].active ? cell_of(particles[j].x) : -1;
      cell_[j] = c;
      if (c >= 0) ++count[c];
    }
  });
  const int placed = place_runs(runs, stride);
  resize_on_huge_pages(order_, static_cast<std::size_t>(placed));
  resize_on_huge_pages(sorted, static_cast<std::size_t>(placed));
  for_each_part(runs, parallel, [&](int run, int) {
    std::int64_t lo, hi;
    run_range(n, run, runs, lo, hi);
    int* slot = run_slots_.data() + stride * run;
    for (std::int64_t j = lo; j < hi; ++j) {
      const int c = cell_[j];
      if (c < 0) continue;
      const int update = slot[c]++;
      order_[update] = static_cast<int>(j), sorted[update] = particles[j];
    }
  });
}

template <int D>
void Checkerboard<D>::resort(std::vector<Particle<D>>& sorted, int threads) {
  // The counting sort of sort(), over the current order instead of particle index. A cell then receives
  // its particles ordered by (old cell, index): a few runs each in index order (the cells move between
  // sweeps, so a cell may take a share of each neighbour's), which a sort per cell puts in index order.
  KDM_CHECK(sorted.size() == order_.size());
  const std::int64_t n = static_cast<std::int64_t>(sorted.size());
  const int runs = std::max(1, threads);
  const std::size_t stride = run_stride(total_cells_);
  resize_on_huge_pages(cell_, sorted.size());
  run_slots_.assign(stride * runs, 0);
  resize_on_huge_pages(spare_order_, sorted.size());
  resize_on_huge_pages(spare_sorted_, sorted.size());
  const bool parallel = runs > 1 && n >= kParallelFrom;
  for_each_part(runs, parallel, [&](int run, int) {
    std::int64_t lo, hi;
    run_range(n, run, runs, lo, hi);
    int* count = run_slots_.data() + stride * run;
    for (std::int64_t t = lo; t < hi; ++t) ++count[cell_[t] = cell_of(sorted[t].x)];
  });
  place_runs(runs, stride);
  for_each_part(runs, parallel, [&](int run, int) {
    std::int64_t lo, hi;
    run_range(n, run, runs, lo, hi);
    int* slot = run_slots_.data() + stride * run;
    for (std::int64_t t = lo; t < hi; ++t) {
      const int to = slot[cell_[t]]++;
      spare_order_[to] = order_[t], spare_sorted_[to] = sorted[t];
    }
  });
  order_.swap(spare_order_);
  sorted.swap(spare_sorted_);
  for_each_part(runs, parallel, [&](int run, int) {
    std::int64_t lo, hi;
    run_range(total_cells_, run, runs, lo, hi);
    std::vector<std::pair<int, Particle<D>>> cell;
    for (std::int64_t c = lo; c < hi; ++c) {
      const int first = first_in_cell_[c], end = first_in_cell_[c + 1];
      int t = first + 1;
      while (t < end && order_[t - 1] < order_[t]) ++t;
      if (t >= end) continue;
      cell.clear();
      for (int u = first; u < end; ++u) cell.emplace_back(order_[u], sorted[u]);
      std::sort(cell.begin(), cell.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
      for (int u = first; u < end; ++u) order_[u] = cell[u - first].first, sorted[u] = cell[u - first].second;
    }
  });
}

template class Checkerboard<2>;
template class Checkerboard<3>;

}  // namespace kdm::gen
