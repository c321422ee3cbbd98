// Algorithm 1 of Fattal 2011: single-level MH-corrected Langevin relaxation, one point at a time.
// Proposal (eq. 5): x' = x - (Δt_j / 2T) ∇E + sqrt(Δt_j) ξ with Δt_j = T σ(x) Δt and the gradient of
// eq. 7 (σ held fixed). Acceptance: the Metropolis–Hastings ratio of eq. 6 with the exact energy change
// over the union of the old and new footprints. Eq. 6 assumes Δt_j is the same both ways; with a
// spatially varying σ it is not, so we use the full ratio of the two Gaussian proposal densities
// (which reduces to eq. 6 when σ(x) = σ(x')). Each accepted or rejected step leaves P ∝ exp(-E/T) invariant.
//
// Points whose footprints cannot overlap are updated concurrently (a checkerboard of cells wider than
// two footprints plus a step); the order of updates and every random number depend only on the seed,
// so the result is the same for any thread count.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "kdm/runtime/check.h"
#include "sampler/checkerboard.h"
#include "sampler/grid.h"
#include "sampler/kernel.h"
#include "sampler/lanes_wide.h"
#include "sampler/particle.h"
#include "sampler/rng.h"

namespace kdm::gen {

struct ChainParams {
  double temperature = 0.11;  ///< T of eq. 4 (model units); 0 = deterministic descent
  double step = 1.0;          ///< Δt of eq. 5
  bool metropolis = true;
  double sigma_cap =
      128;  ///< kernels never wider than this (grid units); only far-below-peak densities hit it
  double sigma_bound = 1e30;    ///< proposals where σ would exceed this are rejected (a support constraint)
  double max_step = 1e30;       ///< proposals moving farther than this along any axis are rejected
  bool box_muller = false;      ///< normal deviates by Rng::normal_box_muller() instead of the ziggurat
  bool four_lane_sums = false;  ///< Numerics::kOriginal's sums (lanes.h) instead of per-lane sums
  /// Sweeps keep each point in its checkerboard cell and move the cells every sweep (Chain::sweeps), so
  /// that no cell border biases the density; false: Numerics::kOriginal's fixed cells, which points cross.
  bool moving_cells = true;
  int vector_lanes = 16;  ///< the widest passes (lanes_wide.h) the CPU has, up to this many lanes
  std::size_t cache_bytes = std::size_t(256) << 20;  ///< budget of the footprint cache (CachedFootprint)
};

struct ChainCounters {
  std::uint64_t proposals = 0;
  std::uint64_t accepted = 0;
};

template <int D>
class Chain {
 public:
  struct alignas(64) Scratch {  // whole cache lines: each thread writes its own on every update
    Footprint<D> old_fp, new_fp;
    KernelTable table;        ///< the tabulated kernel of uniform models, shared by old_fp and new_fp
    LineVector<float> saved;  ///< R under old_fp before its removal, restored exactly on rejection
    double memo_rho = -1, memo_w = -1, memo_sigma = 0;  ///< the last sigma_for(), usually asked again
  };

  /// `density` must outlive the chain, and so must `cache` if given: sweeps() then keeps its footprints
  /// there (emptied at the first sweep) instead of in storage of its own, so that a caller running one
  /// chain after another sets up that storage once.
  Chain(const DensityGrid<D>& density, const ChainParams& params, FootprintCache<D>* cache = nullptr);
  Chain(const Chain&) = delete;  // cache_ may point into the chain itself
  Chain& operator=(const Chain&) = delete;

  const Grid<D>& grid() const { return density_->grid; }
  const DensityGrid<D>& density() const { return *density_; }
  const ChainParams& params() const { return params_; }
  void set_params(const ChainParams& params) {
    params_ = params;
    isa_ = wide::widest(params.vector_lanes);
  }
  std::vector<float>& residual() { return residual_; }

  /// σ of a kernel with weight w at density rho (grid units).
  double sigma_for(double rho, double w) const;
  /// ρ at x as the model sees it: the density grid's interpolation, or its value when it is constant.
  double rho_at(const Vec<D>& x) const { return uniform_ ? uniform_rho_ : density_->at(x); }
  double sigma_at(const Particle<D>& p) const { return sigma_for(rho_at(p.x), p.weight()); }

  /// R = A - ρ with no kernels.
  void clear_kernels();
  /// Adds (sign = +1) or removes (sign = -1) p's kernel.
  void splat(const Particle<D>& p, float sign, Scratch& scratch);
  /// Adds every kernel of `particles`: the same bits as splat() on each in turn. Uses up to `threads`
  /// threads (each adds the rows in its own band of the grid along the last axis, so every node
  /// still sums the same terms in the same order). Not thread-safe.
  void splat_all(const std::vector<Particle<D>>& particles, int threads);
  /// Σ |R| over the grid: the energy of eq. 3 with γ = 1.
  double energy() const;
  /// Energy change if p's kernel were added (p not yet in R).
  double energy_change_if_added(const Particle<D>& p, Scratch& scratch) const;
  /// Energy change if p's kernel (in R) were removed. Leaves R as it was, bit for bit.
  double energy_change_if_removed(const Particle<D>& p, Scratch& scratch);

  /// ∇E with respect to p's centre by eq. 7 (σ held fixed); p's kernel must be in R. R is unchanged.
  Vec<D> gradient(const Particle<D>& p, Scratch& scratch);

  /// One MH-corrected Langevin update of p (whose kernel is in R). `rng` drives only this update.
  /// `cached` (optional) is p's own footprint cache: read when it holds p's footprint, and left holding
  /// the footprint at p's position afterwards. `cell` (sweeps() only; -1: none): proposals leaving that cell
  /// of the sweep's checkerboard are rejected. Returns true when the proposal was accepted.
  bool update(Particle<D>& p, Rng& rng, Scratch& scratch, CachedFootprint<D>* cached = nullptr,
              int cell = -1);

  /// Where a run of sweeps takes its random numbers: sweep s draws from the stream of (seed, level,
  /// first_index + s * index_step).
  struct SweepKeys {
    std::uint64_t seed = 0;
    int level = 0, first_index = 0, index_step = 1;
  };
  /// `count` sweeps over the active particles, each in the deterministic checkerboard order, on up to
  /// `threads` threads (the result does not depend on how many), calling after_sweep (if set)
  /// after each. `particles` is read before the first and written after the last. Not thread-safe.
  void sweeps(std::vector<Particle<D>>& particles, const SweepKeys& keys, int count, int threads,
              ChainCounters& counters, const std::function<void()>& after_sweep = {});

 private:
  // Removes the kernel of `fp` from R, returning Σ(|R_before| - |R_after|) and the gradient of eq. 7;
  // keeps R_before in `saved` for restore().
  double remove_with_gradient(const Footprint<D>& fp, Vec<D>& gradient, LineVector<float>& saved);
  void restore(const Footprint<D>& fp, const LineVector<float>& saved);
  // For a kernel `fp` not in R: Σ(|R + K| - |R|) and the gradient at the new configuration.
  double added_change_with_gradient(const Footprint<D>& fp, Vec<D>& gradient) const;
  void add(const Footprint<D>& fp, float sign);
  void prefetch(const Particle<D>& p, Scratch& scratch) const;
  // One sweep over local_ in board_'s order.
  void sweep(std::uint64_t seed, int level, int sweep_index, int nthreads, bool caching,
             ChainCounters& counters);
  // The block of R that a cell's updates touch: the cell and a margin of kCellBlockMargin nodes (a
  // footprint's reach at the peak density, its lane padding and a step). sweep() fetches the next cell's
  // block a slice per update, so a cell does not start by missing the cache on every row it touches first
  // (docs/design.md §2.9).
  struct CellBlock {
    std::array<std::int64_t, D> lo{}, hi{}, at{};  // the block, and the row of the next line (at[0] unused)
    std::int64_t lines_per_row = 0, column = 0;    // lines in a row; the next line's place in its row
    std::int64_t left = 0, per_update = 0;         // lines not yet fetched; lines to fetch per update
    const float* row = nullptr;                    // the next line's row, at lo[0]

    std::int64_t row_offset(const Grid<D>& g) const {
      std::int64_t offset = lo[0], stride = 1;
      for (int k = 1; k < D; ++k) offset += at[k] * (stride *= g.dims[k - 1]);
      return offset;
    }
    // The next line's address; moves on to the line after it.
    const float* next(const Grid<D>& g, const float* R) {
      KDM_CHECK(left > 0);
      const float* line = row + std::min(column * 16, hi[0] - lo[0]);
      --left;
      if (++column == lines_per_row) {
        column = 0;
        for (int k = 1; k < D && ++at[k] > hi[k]; ++k) at[k] = lo[k];
        if (left > 0) row = R + row_offset(g);  // past the last row the offset may leave the grid
      }
      return line;
    }
  };
  static constexpr int kCellBlockMargin = 8;  // not critical (docs/design.md §2.9)
  CellBlock cell_block(int cell, int updates) const;
  KernelTable* table(Scratch& scratch) const {
    scratch.table.isa = isa_;
    return uniform_ ? &scratch.table : nullptr;
  }
  double sigma_for(double rho, double w, Scratch& scratch) const {
    if (rho != scratch.memo_rho || w != scratch.memo_w)
      scratch.memo_rho = rho, scratch.memo_w = w, scratch.memo_sigma = sigma_for(rho, w);
    return scratch.memo_sigma;
  }

  const DensityGrid<D>* density_;
  ChainParams params_;
  std::vector<float> residual_;
  std::vector<Particle<D>> local_;  // sweeps(): the active particles in update order
  std::vector<Scratch> scratch_;    // sweeps(): one per thread, kept for its kernel tables
  Checkerboard<D> board_;           // sweeps(): the cells and the update order
  CellRuns runs_;                   // sweeps(): a colour's cells shared out among threads
  FootprintCache<D> own_cache_;
  FootprintCache<D>* cache_;          // sweeps(): each particle's footprint, by particle index
  bool cache_emptied_ = false;        // cache_ has been emptied for this chain
  bool uniform_ = false;              // every node has the same ρ: skip the interpolation
  wide::Isa isa_ = wide::Isa::kNone;  // the wide passes' instruction set, where a footprint fits them
  double uniform_rho_ = 0;
};

extern template class Chain<2>;
extern template class Chain<3>;

}  // namespace kdm::gen
