// The schedule of a parallel sweep of Algorithm 1 (Fattal 2011, §3.2): points whose kernel footprints
// cannot overlap are updated concurrently. The grid is cut into cells at least two footprint reaches wide
// and the cells coloured like a checkerboard (2^D colours), so two cells of one colour never touch the
// same node of R. A sweep takes the colours in turn and, within a colour, each cell's points in ascending
// index order: every update then sees the same R whatever thread runs it, and the result is the same for
// any thread count.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "sampler/grid.h"
#include "sampler/particle.h"

namespace kdm::gen {

template <int D>
class Checkerboard {
 public:
  /// Lays out cells for kernels that reach at most `reach` nodes (footprint, lane padding and step) from
  /// their centre. Depends on the grid and the reach only.
  void layout(const Grid<D>& g, double reach);

  /// Moves every cell boundary by `offset[k]` nodes along axis k (0 <= offset[k] < cell_width()[k]; layout()
  /// sets 0). On a torus the cells wrap; in a box the first cell grows by the offset and the last one
  /// shrinks, which keeps every two cells of one colour a whole cell apart. A sweep draws a new offset
  /// independent of the points (Chain::sweeps), so no boundary stays in one place.
  void set_offset(const Vec<D>& offset) { offset_ = offset; }
  const Vec<D>& offset() const { return offset_; }

  /// The cell holding x (canonical), for the layout and offset in force.
  int cell_of(const Vec<D>& x) const;

  /// Sorts the active particles by cell, ascending index within each cell, and copies them in that order
  /// into `sorted` (resized to fit). Uses up to `threads` threads; the order does not depend on how
  /// many. Not thread-safe (call from one thread).
  void sort(const std::vector<Particle<D>>& particles, int threads, std::vector<Particle<D>>& sorted);
  /// Sorts `sorted` again after its particles have moved: `sorted` must be the last sort's result (in
  /// order()'s order, possibly with new positions). Gives the same order() and `sorted` as sort() on the
  /// particles in index order, but splits the work by stretches of the current order, i.e. by bands of the
  /// grid, so each thread moves the particles its own cells hold (sorting by particle index, each thread
  /// wrote half of every cell's particles, and the sweep then fetched them from the other core). Uses up to
  /// `threads` threads; not thread-safe.
  void resort(std::vector<Particle<D>>& sorted, int threads);

  int cell_count() const { return total_cells_; }
  const std::array<int, D>& cells_per_axis() const { return ncell_; }
  const std::array<double, D>& cell_width() const { return width_; }  ///< grid units
  const std::vector<int>& cells_of_colour(int colour) const { return cells_by_colour_[colour]; }
  /// Updates [first(c), first(c + 1)) of order() belong to cell c.
  int first(int cell) const { return first_in_cell_[cell]; }
  int updates_in(int cell) const { return first_in_cell_[cell + 1] - first_in_cell_[cell]; }
  /// Particle index of each update, cell by cell.
  const std::vector<int>& order() const { return order_; }

 private:
  // Turns each run's counts per cell (in run_slots_) into its first place in each cell, runs in order
  // within a cell; sets first_in_cell_. Returns the number of places.
  int place_runs(int runs, std::size_t stride);
  static constexpr std::int64_t kParallelFrom = 4096;  // particles; fewer sort faster on one thread

  std::array<int, D> ncell_{};
  std::array<double, D> width_{};
  Vec<D> offset_{};
  std::array<double, D> extent_{};  // the grid's side along each axis
  bool torus_ = true;
  int total_cells_ = 0;
  std::array<std::vector<int>, (1 << D)> cells_by_colour_;
  std::vector<int> first_in_cell_, order_;
  std::vector<int> cell_;         // sort(), resort(): each particle's (entry's) cell, -1 if inactive
  std::vector<int> run_slots_;    // sort(), resort(): per run and cell, the next free place in order_
  std::vector<int> spare_order_;  // resort(): the new order, swapped in
  std::vector<Particle<D>> spare_sorted_;  // resort(): the new `sorted`, swapped in
};

/// A colour's cells shared out among threads. Run r of `runs` is a stretch of the colour's cells in
/// storage order holding about 1/runs of its updates: the same band of the grid in every colour and sweep,
/// so the rows of R a thread touches stay in its core's cache (cells dealt out one by one doubled the cost
/// of the first pass over R on two threads). A thread takes its own run's cells from the front, then
/// helps with the others' from the back, so a slow core or a crowded band does not hold up the colour.
/// Which thread updates a cell never changes the result.
class CellRuns {
 public:
  /// Cuts cells 0 .. cell_count - 1 into `runs` runs; updates_in(i) is cell i's number of updates.
  /// Not thread-safe.
  template <typename Updates>
  void share(int cell_count, int runs, Updates updates_in) {
    if (runs_ < runs) spans_.reset(new Span[runs]);
    runs_ = runs;
    std::int64_t total = 0, seen = 0;
    for (int i = 0; i < cell_count; ++i) total += updates_in(i);
    std::uint32_t start = 0;
    for (int i = 0, r = 0; r < runs; ++r) {
      for (; i < cell_count && (r == runs - 1 || seen * runs < total * (r + 1)); ++i) seen += updates_in(i);
      spans_[r].bits.store(start | std::uint64_t(i) << 32, std::memory_order_relaxed);
      start = static_cast<std::uint32_t>(i);
    }
  }
  /// Claims a cell of run `run`: the first left if `own`, else the last. Returns its index (as given to
  /// share()), or -1 when the run has none left; `next` is the cell the owner will likely take after it
  /// (-1 if none). Thread-safe.
  int claim(int run, bool own, int& next) {
    std::atomic<std::uint64_t>& bits = spans_[run].bits;
    std::uint64_t span = bits.load(std::memory_order_relaxed);
    for (;;) {
      const std::uint32_t front = static_cast<std::uint32_t>(span),
                          back = static_cast<std::uint32_t>(span >> 32);
      if (front >= back) return next = -1;
      const std::uint64_t rest = own ? span + 1 : span - (std::uint64_t(1) << 32);
      if (bits.compare_exchange_weak(span, rest, std::memory_order_acq_rel, std::memory_order_relaxed)) {
        next = own && front + 1 < back ? static_cast<int>(front + 1) : -1;
        return static_cast<int>(own ? front : back - 1);
      }
    }
  }

 private:
  struct alignas(64) Span {
    std::atomic<std::uint64_t> bits{0};  // [front, back) of the run's cells left: front | back << 32
  };
  std::unique_ptr<Span[]> spans_;
  int runs_ = 0;
};

extern template class Checkerboard<2>;
extern template class Checkerboard<3>;

}  // namespace kdm::gen
