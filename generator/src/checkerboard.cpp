#include "checkerboard.h"

#include <algorithm>
#include <cmath>

#include "parallel.h"

namespace kdm::gen {

template <int D>
void Checkerboard<D>::layout(const Grid<D>& g, double reach) {
  total_cells_ = 1;
  for (int k = 0; k < D; ++k) {
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
    const int c = std::clamp(static_cast<int>(x[k] / width_[k]), 0, ncell_[k] - 1);
    id += c * mul;
    mul *= ncell_[k];
  }
  return id;
}

template <int D>
void Checkerboard<D>::sort(const std::vector<Particle<D>>& particles, int threads,
                           std::vector<Particle<D>>& sorted) {
  // A counting sort in three passes, the first and last over `runs` contiguous runs of particles at once.
  // Each run counts its particles per cell; a run's particles of cell c go after those of earlier runs,
  // which is the serial order exactly.
  const std::int64_t n = static_cast<std::int64_t>(particles.size());
  const int runs = std::max(1, threads);
  const std::size_t cells = static_cast<std::size_t>(total_cells_);
  // Each run's counters on cache lines of their own: shared lines made the sort of a 1,024-point level
  // ten times slower on two threads than on one.
  const std::size_t stride = (cells + 15) / 16 * 16 + 16;
  cell_of_particle_.resize(particles.size());
  update_of_particle_.resize(particles.size());
  run_slots_.assign(stride * runs, 0);
  auto run_range = [&](int run, std::int64_t& lo, std::int64_t& hi) {
    lo = n * run / runs;
    hi = n * (run + 1) / runs;
  };
  // Small levels sort faster on one thread than the team takes to start.
  const bool parallel = runs > 1 && n >= kParallelFrom;
  for_each_part(runs, parallel, [&](int run, int) {
    std::int64_t lo, hi;
    run_range(run, lo, hi);
    int* count = run_slots_.data() + stride * run;
    for (std::int64_t j = lo; j < hi; ++j) {
      const int c = particles[j].active ? cell_of(particles[j].x) : -1;
      cell_of_particle_[j] = c;
      if (c >= 0) ++count[c];
    }
  });
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
  order_.resize(static_cast<std::size_t>(placed));
  sorted.resize(static_cast<std::size_t>(placed));
  for_each_part(runs, parallel, [&](int run, int) {
    std::int64_t lo, hi;
    run_range(run, lo, hi);
    int* slot = run_slots_.data() + stride * run;
    for (std::int64_t j = lo; j < hi; ++j) {
      const int c = cell_of_particle_[j];
      const int update = c >= 0 ? slot[c]++ : -1;
      if (update >= 0) order_[update] = static_cast<int>(j), sorted[update] = particles[j];
      update_of_particle_[j] = update;
    }
  });
}

template class Checkerboard<2>;
template class Checkerboard<3>;

}  // namespace kdm::gen
