#include "sampler/chain.h"

#include "platform/huge_pages.h"
#include "platform/parallel.h"
#include "sampler/lanes.h"

#include <algorithm>
#include <cmath>
#include <type_traits>

namespace kdm::gen {
namespace {

// The sign in eq. 7's gradient. Where R is exactly ±0 any value in [-1, 1] is a subgradient; copysign
// matches the lane passes' sign flip.
inline float sign_of(float r) {
  return std::copysign(1.0f, r);
}

/// The general passes (footprints whose rows wrap around a torus or fold at a box's walls, as runs):
/// eq. 7's gradient and the change in Σ|R| of taking fp's kernel out of R (kRemove: R changes and its old
/// values go to `saved`) or of putting it in (R unchanged). The lane passes compute the same per node.
template <bool kRemove, int D>
double measure_runs(std::conditional_t<kRemove, float*, const float*> R, const Grid<D>& grid,
                    const Footprint<D>& fp, Vec<D>& gradient, float* saved) {
  const AxisFactor& ax = fp.axes[0];
  double change = 0;
  gradient.fill(0);
  fp.for_each_row(grid, [&](std::int64_t base, double p, const std::array<double, D>& pd) {
    const float pf = static_cast<float>(p);
    float sx = 0, sg = 0, e = 0;
    for (std::size_t run = 0; run < ax.run_offset.size(); ++run) {
      const int off = ax.run_offset[run], len = ax.run_length[run];
      auto* __restrict row = R + base + ax.index[off];
      const float* __restrict v = ax.value.data() + off;
      const float* __restrict dv = ax.deriv.data() + off;
      for (int a = 0; a < len; ++a) {
        const float r = row[a];
        const float rn = kRemove ? r - pf * v[a] : r + pf * v[a];
        const float with = kRemove ? r : rn, without = kRemove ? rn : r;  // R with and without the kernel
        const float s = sign_of(with);
        sx += s * dv[a];
        sg += s * v[a];
        e += std::fabs(with) - std::fabs(without);
        if constexpr (kRemove) {
          *saved++ = r;
          row[a] = rn;
        }
      }
    }
    change += e;
    gradient[0] += p * sx;
    for (int k = 1; k < D; ++k) gradient[k] += pd[k] * sg;
  });
  return change;
}

}  // namespace

template <int D>
Chain<D>::Chain(const DensityGrid<D>& density, const ChainParams& params, FootprintCache<D>* cache)
    : density_(&density),
      params_(params),
      residual_(vector_on_huge_pages<float>(density.rho.size(), 0.0f)),
      cache_(cache ? cache : &own_cache_) {
  const std::vector<float>& rho = density.rho;
  uniform_ = !rho.empty() && std::all_of(rho.begin(), rho.end(), [&](float r) { return r == rho[0]; });
  uniform_rho_ = uniform_ ? rho[0] : 0.0;
  set_params(params);
  clear_kernels();
}

template <int D>
double Chain<D>::sigma_for(double rho, double w) const {
  if (!(rho > 0)) return params_.sigma_cap;
  const double sigma = D == 2 ? 1.0 / std::sqrt(rho / w) : 1.0 / std::cbrt(rho / w);
  return std::min(params_.sigma_cap, sigma);
}

template <int D>
void Chain<D>::clear_kernels() {
  for (std::size_t i = 0; i < residual_.size(); ++i) residual_[i] = -density_->rho[i];
}

template <int D>
std::size_t footprint_nodes(const Footprint<D>& fp) {
  std::size_t n = fp.contiguous ? fp.width : fp.axes[0].count;
  for (int k = 1; k < D; ++k) n *= fp.axes[k].count;
  return n;
}

// Each pass below has lane-vector forms for contiguous footprints (lanes.h, and lanes_wide.h where the CPU
// has AVX-512) and a general form over index runs. All evaluate every node the same way: R ± p·v in float,
// the sign of R with the kernel in it for the gradient. Windows of 8, 12 or 16 nodes keep their sums per
// lane (unless four_lane_sums), which the four- and sixteen-lane passes add up alike.

template <int D>
void Chain<D>::add(const Footprint<D>& fp, float sign) {
  float* R = residual_.data();
  if (isa_ != wide::Isa::kNone && wide::fits(fp)) return wide::add<D>(isa_, R, grid(), fp, sign);
  if (fp.contiguous) {
    lanes::by_width(fp.width, [&](auto n) { lanes::add<decltype(n)::value>(R, grid(), fp, sign); });
    return;
  }
  const AxisFactor& ax = fp.axes[0];
  fp.for_each_row(grid(), [&](std::int64_t base, double p, const std::array<double, D>&) {
    const float pf = sign * static_cast<float>(p);
    for (std::size_t run = 0; run < ax.run_offset.size(); ++run) {
      const int off = ax.run_offset[run], len = ax.run_length[run];
      float* __restrict row = R + base + ax.index[off];
      const float* __restrict v = ax.value.data() + off;
      for (int a = 0; a < len; ++a) row[a] += pf * v[a];
    }
  });
}

template <int D>
void Chain<D>::splat(const Particle<D>& p, float sign, Scratch& scratch) {
  const double rho = rho_at(p.x);
  if (!(rho > 0)) return;
  scratch.old_fp.build(grid(), p.x, sigma_for(rho, p.weight()), rho, false, table(scratch), isa_);
  add(scratch.old_fp, sign);
}

template <int D>
void Chain<D>::splat_all(const std::vector<Particle<D>>& particles, int threads) {
  const int bands = std::max(1, threads);
  if (static_cast<int>(scratch_.size()) < bands) scratch_.resize(bands);
  const int m = grid().dims[D - 1];
  const std::int64_t n = static_cast<std::int64_t>(particles.size());
  for_each_part(bands, n > 1, [&](int band, int thread) {
    Scratch& s = scratch_[thread];
    const int first_row = static_cast<int>(std::int64_t(m) * band / bands);
    const int end_row = static_cast<int>(std::int64_t(m) * (band + 1) / bands);
    for (const Particle<D>& p : particles) {
      const double rho = rho_at(p.x);
      if (!(rho > 0)) continue;
      const double sigma = sigma_for(rho, p.weight(), s);
      std::int64_t lo, hi;
      axis_reach(p.x[D - 1], sigma, lo, hi);
      // Rows past an edge wrap or fold: such kernels are built and their rows sorted out below.
      if (lo >= 0 && hi < m && (hi < first_row || lo >= end_row)) continue;
      s.old_fp.build(grid(), p.x, sigma, rho, false, table(s), isa_);
      if (bands > 1) {
        AxisFactor& outer = s.old_fp.axes[D - 1];
        int kept = 0;
        for (int i = 0; i < outer.count; ++i) {
          if (outer.index[i] < first_row || outer.index[i] >= end_row) continue;
          outer.index[kept] = outer.index[i];
          outer.value[kept] = outer.value[i];
          outer.deriv[kept] = outer.deriv[i];
          ++kept;
        }
        outer.count = kept;
        if (kept == 0) continue;
      }
      add(s.old_fp, 1.0f);
    }
  });
}

template <int D>
double Chain<D>::energy() const {
  double e = 0;
  for (float r : residual_) e += std::fabs(r);
  return e;
}

template <int D>
double Chain<D>::energy_change_if_added(const Particle<D>& p, Scratch& scratch) const {
  const double rho = rho_at(p.x);
  if (!(rho > 0)) return 0;
  scratch.new_fp.build(grid(), p.x, sigma_for(rho, p.weight()), rho, false, table(scratch), isa_);
  Vec<D> unused{};
  return added_change_with_gradient(scratch.new_fp, unused);
}

template <int D>
double Chain<D>::energy_change_if_removed(const Particle<D>& p, Scratch& scratch) {
  const double rho = rho_at(p.x);
  if (!(rho > 0)) return 0;
  scratch.old_fp.build(grid(), p.x, sigma_for(rho, p.weight()), rho, false, table(scratch), isa_);
  Vec<D> unused{};
  const double lowered = remove_with_gradient(scratch.old_fp, unused, scratch.saved);
  restore(scratch.old_fp, scratch.saved);
  return -lowered;
}

template <int D>
double Chain<D>::remove_with_gradient(const Footprint<D>& fp, Vec<D>& gradient, LineVector<float>& saved) {
  float* R = residual_.data();
  if (saved.size() < footprint_nodes(fp)) saved.resize(footprint_nodes(fp));
  float* out = saved.data();
  if (fp.contiguous) {
    if (isa_ != wide::Isa::kNone && !params_.four_lane_sums && wide::fits(fp))
      return wide::remove<D>(isa_, R, grid(), fp, gradient, out);
    return lanes::by_width(fp.width, [&](auto n) {
      constexpr int N = decltype(n)::value;
      if constexpr (N > 0) {
        if (!params_.four_lane_sums) return lanes::measure_per_lane<N, true>(R, grid(), fp, gradient, out);
      }
      return lanes::measure<N, true>(R, grid(), fp, gradient, out);
    });
  }
  return measure_runs<true, D>(R, grid(), fp, gradient, out);
}

template <int D>
void Chain<D>::restore(const Footprint<D>& fp, const LineVector<float>& saved) {
  float* R = residual_.data();
  const float* in = saved.data();
  if (isa_ != wide::Isa::kNone && wide::fits(fp)) return wide::restore<D>(isa_, R, grid(), fp, in);
  if (fp.contiguous) {
    lanes::by_width(fp.width, [&](auto n) { lanes::restore<decltype(n)::value>(R, grid(), fp, in); });
    return;
  }
  const AxisFactor& ax = fp.axes[0];
  fp.for_each_row(grid(), [&](std::int64_t base, double, const std::array<double, D>&) {
    for (std::size_t run = 0; run < ax.run_offset.size(); ++run) {
      const int off = ax.run_offset[run], len = ax.run_length[run];
      std::copy(in, in + len, R + base + ax.index[off]);
      in += len;
    }
  });
}

template <int D>
double Chain<D>::added_change_with_gradient(const Footprint<D>& fp, Vec<D>& gradient) const {
  const float* R = residual_.data();
  if (fp.contiguous) {
    if (isa_ != wide::Isa::kNone && !params_.four_lane_sums && wide::fits(fp))
      return wide::added<D>(isa_, R, grid(), fp, gradient);
    return lanes::by_width(fp.width, [&](auto n) {
      constexpr int N = decltype(n)::value;
      if constexpr (N > 0) {
        if (!params_.four_lane_sums)
          return lanes::measure_per_lane<N, false>(R, grid(), fp, gradient, nullptr);
      }
      return lanes::measure<N, false>(R, grid(), fp, gradient, nullptr);
    });
  }
  return measure_runs<false, D>(R, grid(), fp, gradient, nullptr);
}

template <int D>
Vec<D> Chain<D>::gradient(const Particle<D>& p, Scratch& scratch) {
  Vec<D> g{};
  const double rho = rho_at(p.x);
  if (!(rho > 0)) return g;
  scratch.old_fp.build(grid(), p.x, sigma_for(rho, p.weight()), rho, true, table(scratch), isa_);
  remove_with_gradient(scratch.old_fp, g, scratch.saved);
  restore(scratch.old_fp, scratch.saved);
  return g;
}

template <int D>
bool Chain<D>::update(Particle<D>& p, Rng& rng, Scratch& scratch, CachedFootprint<D>* cached, int cell) {
  const double w = p.weight();
  const double rho_old = rho_at(p.x);
  if (!(rho_old > 0)) return false;  // a massless kernel has nothing to relax
  const double T = params_.temperature;
  // The noise does not depend on the gradient: drawn first, its work overlaps the remove pass.
  Vec<D> noise{};
  if (T > 0)
    for (int k = 0; k < D; ++k) noise[k] = params_.box_muller ? rng.normal_box_muller() : rng.normal();
  const double sigma_old = sigma_for(rho_old, w, scratch);
  const bool was_cached = cached && cached->holds(p.x, sigma_old, rho_old);
  if (was_cached)
    cached->load(scratch.old_fp);
  else
    scratch.old_fp.build(grid(), p.x, sigma_old, rho_old, true, table(scratch), isa_);
  Vec<D> grad_old;
  const double removed = remove_with_gradient(scratch.old_fp, grad_old, scratch.saved);

  // Eq. 5 with Δt_j = T σ Δt / w: drift -(σ Δt / 2w) ∇E, noise variance T σ Δt / w. A kernel of weight w
  // carries w times the energy, so dividing by w keeps its step the size of a unit kernel's (as the
  // reference implementation does); P ∝ exp(-E/T) is unchanged, only the proposal scale.
  const double dt = params_.step / w;
  const double var_old = T * sigma_old * dt;
  const double noise_scale = T > 0 ? std::sqrt(var_old) : 0.0;
  Vec<D> drift_old, step;
  bool too_far = false;
  for (int k = 0; k < D; ++k) {
    drift_old[k] = -0.5 * sigma_old * dt * grad_old[k];
    step[k] = drift_old[k] + noise_scale * noise[k];
    too_far |= !(std::fabs(step[k]) <= params_.max_step);
  }
  auto reject = [&] {
    restore(scratch.old_fp, scratch.saved);
    if (cached && !was_cached) cached->keep(scratch.old_fp, p.x, sigma_old);
    return false;
  };
  if (too_far) return reject();
  Vec<D> x_new;
  for (int k = 0; k < D; ++k) x_new[k] = p.x[k] + step[k];
  if (!grid().canonical(x_new)) return reject();
  // A point stays in its checkerboard cell for the sweep (a support constraint, symmetric like the others):
  // the sweep's order, cell by cell, is then the same for every state it can reach, so each update's
  // invariance of P carries over to the sweep. Let points cross and the order depends on where they are:
  // the cells updated first lost points near their borders to the cells updated after (5% of the density
  // within a node of each border, at 256 points; docs/design.md §2.2).
  if (cell >= 0 && board_.cell_of(x_new) != cell) return reject();
  const double rho_new = rho_at(x_new);
  if (!(rho_new > 0)) return reject();
  const double sigma_new = sigma_for(rho_new, w, scratch);
  if (sigma_new > params_.sigma_bound) return reject();
  // With the derivative even when the test does not need it: the footprint may be cached for later.
  scratch.new_fp.build(grid(), x_new, sigma_new, rho_new, true, table(scratch), isa_);
  Vec<D> grad_new;
  const double dE = added_change_with_gradient(scratch.new_fp, grad_new) - removed;

  bool accept;
  if (T <= 0) {
    accept = dE <= 0;
  } else if (!params_.metropolis) {
    accept = true;
  } else {
    // log q(x'|x) and log q(x|x') of the two Gaussian proposals, up to the shared (2π)^(d/2).
    const double var_new = T * sigma_new * dt;
    double forward = 0, reverse = sigma_new == sigma_old ? 0.0 : 0.5 * D * std::log(var_new / var_old);
    for (int k = 0; k < D; ++k) {
      const double drift_new = -0.5 * sigma_new * dt * grad_new[k];
      const double f = step[k] - drift_old[k], r = -step[k] - drift_new;
      forward += f * f / (2 * var_old);
      reverse += r * r / (2 * var_new);
    }
    const double log_alpha = -dE / T - reverse + forward;
    accept = log_alpha >= 0 || rng.uniform() < std::exp(log_alpha);
  }
  if (!accept) return reject();
  add(scratch.new_fp, 1.0f);
  p.x = x_new;
  if (cached) cached->keep(scratch.new_fp, x_new, sigma_new);
  return true;
}

template <int D>
void Chain<D>::sweeps(std::vector<Particle<D>>& particles, const SweepKeys& keys, int count, int threads,
                      ChainCounters& counters, const std::function<void()>& after_sweep) {
  if (count <= 0) return;
  // Cells at least two footprints plus a step wide. The 3 is a footprint's lane padding (kernel.h).
  const double reach = std::ceil(kCut * std::min(params_.sigma_bound, params_.sigma_cap)) + 1 + 3 +
                       std::ceil(std::min(params_.max_step, 1e9));
  board_.layout(grid(), reach);
  const int nthreads = thread_count(threads);
  if (static_cast<int>(scratch_.size()) < nthreads) scratch_.resize(nthreads);
  // The footprint cache costs ~300 bytes per point: past its budget (by default about 900,000 points)
  // updates build both footprints instead, which gives the same bits.
  const bool caching = particles.size() * sizeof(CachedFootprint<D>) <= params_.cache_bytes;
  if (caching && (!cache_emptied_ || cache_->size() != particles.size())) {
    cache_->reset(particles.size(), nthreads);
    cache_emptied_ = true;
  }
  // The sweeps run on a copy in cell order, so consecutive updates read consecutive particles, and it
  // stays in that order between sweeps (resort()), so each thread keeps its band's particles.
  // Every sweep moves the cells by an offset drawn from its keys alone, never from the points: points do
  // not cross cell borders within a sweep (update()), and borders that never moved would be walls.
  auto place_cells = [&](int s) {
    if (!params_.moving_cells) return;
    const std::uint64_t sweep_index = static_cast<std::uint64_t>(keys.first_index + s * keys.index_step);
    Rng rng(keys.seed, 0x43454C4C53ull /* "CELLS" */, static_cast<std::uint64_t>(keys.level), sweep_index, 0);
    Vec<D> offset{};
    for (int k = 0; k < D; ++k)
      offset[k] = board_.cells_per_axis()[k] > 1 ? rng.uniform() * board_.cell_width()[k] : 0.0;
    board_.set_offset(offset);
  };
  place_cells(0);
  board_.sort(particles, nthreads, local_);
  for (int s = 0; s < count; ++s) {
    if (s > 0) {
      place_cells(s);
      board_.resort(local_, nthreads);
    }
    sweep(keys.seed, keys.level, keys.first_index + s * keys.index_step, nthreads, caching, counters);
    if (after_sweep) after_sweep();
  }
  const std::vector<int>& order = board_.order();
  const std::int64_t updates = static_cast<std::int64_t>(order.size());
  parallel_for(updates, nthreads, updates >= 4096, [&](std::int64_t t) { particles[order[t]] = local_[t]; });
}

template <int D>
void Chain<D>::sweep(std::uint64_t seed, int level, int sweep_index, int nthreads, bool caching,
                     ChainCounters& counters) {
  const std::vector<int>& order = board_.order();
  std::vector<std::uint64_t> accepted_in_cell(board_.cell_count(), 0);
  const bool confined = params_.moving_cells && board_.cell_count() > 1;  // one cell: no border to cross
  FootprintCache<D>& cache = *cache_;
  // Every update's stream shares the key of (seed, level, sweep); the point index completes it.
  const std::uint64_t sweep_key =
      Rng::keyed(seed, 0x5357454550ull /* "SWEEP" */, static_cast<std::uint64_t>(level),
                 static_cast<std::uint64_t>(sweep_index));
  for (int colour = 0; colour < (1 << D); ++colour) {
    const std::vector<int>& cells = board_.cells_of_colour(colour);
    const int count = static_cast<int>(cells.size());
    runs_.share(count, nthreads, [&](int i) { return board_.updates_in(cells[i]); });
    auto update_cell = [&](int ci, int next_ci, Scratch& s) {
      const int c = cells[ci];
      const int end = board_.first(c + 1);
      // The next update's rows: in this cell, else the next cell's first.
      const int next_cell_first = next_ci >= 0 ? board_.first(cells[next_ci]) : -1;
      CellBlock block = next_ci >= 0 ? cell_block(cells[next_ci], board_.updates_in(c)) : CellBlock{};
      std::uint64_t acc = 0;
      for (int t = board_.first(c); t < end; ++t) {
        // This update's share of the next cell's block. Here, not in a function of its own: GCC drops
        // calls to a function that does nothing but prefetch.
        for (std::int64_t k = 0; k < block.per_update && block.left > 0; ++k)
          __builtin_prefetch(block.next(grid(), residual_.data()), 1);
        const int next = t + 1 < end ? t + 1 : next_cell_first;
        // prefetch() below reads ρ where the next particle sits; fetch it for the one after, one update
        // early.
        if (!uniform_ && t + 2 < end) density_->prefetch(local_[t + 2].x);
        if (next >= 0 && next < static_cast<int>(local_.size())) {
          prefetch(local_[next], s);
          if (caching) {
            const char* entry = reinterpret_cast<const char*>(&cache[order[next]]);
            for (std::size_t b = 0; b < sizeof(CachedFootprint<D>); b += 64) __builtin_prefetch(entry + b);
          }
        }
        const int j = order[t];
        Rng rng = Rng::from_key(sweep_key, static_cast<std::uint64_t>(j));
        acc += update(local_[t], rng, s, caching ? &cache[j] : nullptr, confined ? c : -1) ? 1 : 0;
      }
      accepted_in_cell[c] = acc;
    };
    run_team(nthreads, count > 1, [&](int thread, int team) {
      Scratch& s = scratch_[thread];
      int ci, next;
      for (int run = thread; run < nthreads; run += team)
        while ((ci = runs_.claim(run, true, next)) >= 0) update_cell(ci, next, s);
      for (int k = 1; k < nthreads; ++k)  // also covers the runs of threads a smaller team lacks
        while ((ci = runs_.claim((thread + k) % nthreads, false, next)) >= 0) update_cell(ci, -1, s);
    });
  }
  counters.proposals += order.size();
  for (std::uint64_t a : accepted_in_cell) counters.accepted += a;
}

template <int D>
typename Chain<D>::CellBlock Chain<D>::cell_block(int cell, int updates) const {
  const Grid<D>& g = grid();
  const std::array<int, D>& ncell = board_.cells_per_axis();
  const std::array<double, D>& width = board_.cell_width();
  const Vec<D>& offset = board_.offset();
  CellBlock b;
  for (int k = 0, rest = cell; k < D; ++k) {
    const int at = rest % ncell[k];
    rest /= ncell[k];
    // The cell's nodes (a box's first cell starts at its wall), those past a torus's seam left out: a
    // prefetch, so fetching less changes no result.
    const double start = at == 0 && !g.torus ? 0.0 : at * width[k] + offset[k];
    b.lo[k] = std::clamp<std::int64_t>(static_cast<std::int64_t>(start) - kCellBlockMargin, 0, g.dims[k] - 1);
    b.hi[k] = std::clamp<std::int64_t>(
        static_cast<std::int64_t>((at + 1) * width[k] + offset[k]) + kCellBlockMargin, b.lo[k],
        g.dims[k] - 1);
    b.at[k] = b.lo[k];
  }
  b.lines_per_row = (b.hi[0] - b.lo[0] + 1 + 15) / 16 + 1;  // 16 floats a line; the ends may straddle lines
  std::int64_t lines = b.lines_per_row;
  for (int k = 1; k < D; ++k) lines *= b.hi[k] - b.lo[k] + 1;
  b.left = lines;
  b.per_update = updates > 0 ? (lines + updates - 1) / updates : 0;
  b.row = residual_.data() + b.row_offset(g);
  return b;
}

template <int D>
void Chain<D>::prefetch(const Particle<D>& p, Scratch& scratch) const {
  // A footprint's rows are ~10 scattered cache lines that the hardware cannot predict; fetching them one
  // update ahead hides most of their latency.
  const Grid<D>& g = grid();
  const double sigma = sigma_for(rho_at(p.x), p.weight(), scratch);
  std::array<std::int64_t, D> lo{}, hi{};
  for (int k = 0; k < D; ++k) axis_reach(p.x[k], sigma, lo[k], hi[k]);
  const std::int64_t x0 = std::clamp<std::int64_t>(lo[0], 0, g.dims[0] - 1),
                     x1 = std::clamp<std::int64_t>(hi[0], 0, g.dims[0] - 1);
  const float* R = residual_.data();
  // Each row's window spans at most a few lines: prefetch its first and last node and every 16th between.
  auto row = [&](std::int64_t base) {
    __builtin_prefetch(R + base + x0, 1);
    for (std::int64_t i = x0 + 16; i < x1; i += 16) __builtin_prefetch(R + base + i, 1);
    __builtin_prefetch(R + base + x1, 1);
  };
  // Rows wrap at most once: the support is smaller than half the grid.
  auto first_row = [&](std::int64_t i, int m) {
    return std::clamp<std::int64_t>(i < 0 ? i + m : i, 0, m - 1);
  };
  const std::int64_t m1 = g.dims[1], s1 = g.dims[0];
  if constexpr (D == 2) {
    std::int64_t y = first_row(lo[1], g.dims[1]);
    for (std::int64_t n = lo[1]; n <= hi[1]; ++n) {
      row(y * s1);
      if (++y == m1) y = 0;
    }
  } else {
    const std::int64_t m2 = g.dims[2];
    std::int64_t z = first_row(lo[2], g.dims[2]);
    for (std::int64_t nz = lo[2]; nz <= hi[2]; ++nz) {
      std::int64_t y = first_row(lo[1], g.dims[1]);
      for (std::int64_t n = lo[1]; n <= hi[1]; ++n) {
        row((z * m1 + y) * s1);
        if (++y == m1) y = 0;
      }
      if (++z == m2) z = 0;
    }
  }
}

template class Chain<2>;
template class Chain<3>;

}  // namespace kdm::gen
