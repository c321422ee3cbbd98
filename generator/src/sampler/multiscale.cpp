#include "sampler/multiscale.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numeric>

#include "platform/huge_pages.h"
#include "platform/parallel.h"
#include "sampler/chain.h"
#include "sampler/count_balance.h"
#include "sampler/count_fixing.h"
#include "sampler/setup.h"
#include "sampler/support_pieces.h"

namespace kdm::gen {
namespace {

constexpr std::uint64_t kInitStream = 0x494e4954;  // "INIT"
constexpr std::uint64_t kRefineStream = 0x524546;  // "REF"
/// Count balance compares counts first on a grid holding at least this many points per node on average,
constexpr double kBalancePointsPerNode = 8;
/// then on finer grids at the nodes that hold at least this many (blue-noise counts vary little, and the
/// steep parts of a density need the finer grids).
constexpr double kBalanceFinePointsPerNode = 2;
/// The largest grid a count balance solves on: the bias it corrects is large-scale, and the solve costs
/// about nodes^1.5.
constexpr double kBalanceMaxNodes = 16384;
/// Levels finer than a balance grid that its target is binned from.
constexpr int kBalanceSourceLevels = 2;

using Clock = std::chrono::steady_clock;
double seconds_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

template <int D>
Vec<D> node_centre(const Grid<D>& g, std::int64_t i) {
  Vec<D> x{};
  for (int k = 0; k < D; ++k) {
    x[k] = (i % g.dims[k]) + 0.5;
    i /= g.dims[k];
  }
  return x;
}

/// Splits remaining for a kernel placed where the coarsest density is rho: the smallest q with
/// rho / 2^(D q) <= 1 (at most max_splits), the number of refinements before its weight reaches one
/// (paper §3.3).
template <int D>
int splits_for(double rho, int max_splits) {
  int q = 0;
  while (q < max_splits && rho > std::ldexp(1.0, D * q) * (1 + 1e-6)) ++q;
  return q;
}

/// splits_for(), lowered until the kernel's weight 2^(D q) fits in `room` (what is left of n): where the
/// last few points belong on a dense spot, lighter kernels go there, not whole ones where ρ is nearly zero.
template <int D>
int splits_within(double rho, int max_splits, double room) {
  int q = splits_for<D>(rho, max_splits);
  while (q > 0 && std::ldexp(1.0, D * q) > room) --q;
  return q;
}

template <int D>
struct Driver {
  const SamplerOptions& options;
  ModelSetup<D>& setup;
  ChainParams params;
  SampleReport report;
  std::vector<Particle<D>> particles;
  std::vector<Particle<D>> fixed;  ///< constrained sampling: background kernels on the finest grid
  double total_sweeps = 0, done_sweeps = 0;
  int threads = 1;          ///< threads for the set-up of each level (sweeps take options.threads)
  double sigma_max;         ///< options.sigma_max, or the default for D
  FootprintCache<D> cache;  ///< lent to every level's chain

  Driver(const SamplerOptions& o, ModelSetup<D>& s)
      : options(o),
        setup(s),
        threads(thread_count(o.threads)),
        sigma_max(o.sigma_max > 0 ? o.sigma_max
                  : D == 2        ? 16
                                  : 4) {
    params.temperature = o.temperature * kModelTemperaturePerUser;
    params.step = o.step > 0 ? o.step : (D == 2 ? 0.35 : 0.1);
    params.metropolis = o.metropolis;
    params.box_muller = o.numerics == Numerics::kOriginal;
    params.four_lane_sums = o.numerics == Numerics::kOriginal;
    params.moving_cells = o.numerics == Numerics::kFast;  // kOriginal: a recipe bakes the same tiles
    params.vector_lanes = o.vector_lanes;
    params.cache_bytes = o.footprint_cache_bytes;
  }

  double total_weight() const {
    double w = 0;
    for (const auto& p : particles) w += p.weight();
    return w;
  }

  void initial_configuration(Chain<D>& chain) {
    const Grid<D>& g = chain.grid();
    const int max_splits = static_cast<int>(setup.levels.size()) - 1;
    std::vector<std::int64_t> order(static_cast<std::size_t>(g.size()));
    std::iota(order.begin(), order.end(), 0);
    Rng rng(options.seed, kInitStream);
    for (std::size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[rng.below(i)]);
    typename Chain<D>::Scratch scratch;
    const std::vector<float>& rho = chain.density().rho;
    const std::vector<float>& R = chain.residual();
    const double centre_factor = std::pow(1 - kernel_edge_value(), D);
    for (std::int64_t node : order) {
      if (!(rho[node] > 0)) continue;
      // Most nodes fail the pointwise test: adding the kernel's centre value does not lower |R| there.
      if (R[node] + 0.5 * rho[node] * centre_factor >= 0) continue;
      Particle<D> p;
      p.x = node_centre(g, node);
      p.splits = static_cast<std::uint8_t>(splits_for<D>(rho[node], max_splits));
      if (chain.energy_change_if_added(p, scratch) < 0) {
        chain.splat(p, 1.0f, scratch);
        particles.push_back(p);
      }
    }
  }

  /// Brings Σw to exactly n on the coarsest grid as far as whole kernels allow: removes the kernels whose
  /// removal raises E least per unit of weight, then adds kernels where that lowers E most per unit of
  /// weight. Per unit of weight, so that light kernels in sparse regions are not the cheapest to remove
  /// (that would empty the sparse end of a high-dynamic-range density).
  void fix_count_coarse(Chain<D>& chain) {
    const double n = static_cast<double>(options.n);
    typename Chain<D>::Scratch scratch;
    double w = total_weight();
    report.removed_for_exact_count += options.numerics == Numerics::kOriginal
                                          ? remove_surplus_as_first_versions(chain, particles, n, w)
                                          : remove_surplus(chain, particles, n, w);
    const Grid<D>& g = chain.grid();
    const int max_splits = static_cast<int>(setup.levels.size()) - 1;
    // kFast adds kernels of the weight their node asks for while one fits what is left of n, lighter ones
    // only for the last remainder, and one a node: lighter kernels among heavier ones (the excess of a
    // heavy kernel's removal made up at its own dense nodes) hid in their wide neighbours' footprints and
    // refined into clumps of stacked points. The first versions' rule otherwise (tile baking keeps its bits).
    // Nor, while a node elsewhere can take one, where a kernel's least weight (one point) passes the
    // node's mass 2^D-fold: once no node lacks mass, a kernel raises E least per unit weight where it is
    // widest, and a 1:10^6 ramp's faintest column took one a node (a row of points along its far wall).
    const bool fast = options.numerics == Numerics::kFast;
    std::vector<char> added(fast ? static_cast<std::size_t>(g.size()) : 0, 0);
    while (w < n) {
      double best_gain = std::numeric_limits<double>::infinity();
      Particle<D> best;
      std::int64_t best_node = -1;
      // 0: whole kernels where they fit their node's mass; 1: lighter ones there; 2: lighter ones anywhere
      for (int pass = fast ? 0 : 2; pass < 3 && best_node < 0; ++pass) {
        for (std::int64_t node = 0; node < g.size(); ++node) {
          const double rho = chain.density().rho[node];
          if (!(rho > 0) || (fast && added[static_cast<std::size_t>(node)])) continue;
          Particle<D> p;
          p.x = node_centre(g, node);
          p.splits = static_cast<std::uint8_t>(pass == 0 ? splits_for<D>(rho, max_splits)
                                                         : splits_within<D>(rho, max_splits, n - w));
          if (w + p.weight() > n || (pass < 2 && p.weight() > std::ldexp(rho, D))) continue;
          const double gain = chain.energy_change_if_added(p, scratch) / p.weight();
          if (gain < best_gain) best_gain = gain, best = p, best_node = node;
        }
      }
      if (best_node < 0) break;
      if (fast) added[static_cast<std::size_t>(best_node)] = 1;
      chain.splat(best, 1.0f, scratch);
      particles.push_back(best);
      w += best.weight();
      ++report.inserted_for_exact_count;
    }
  }

  /// After each refinement, adds kernels of the level's full weight while Σw + w <= n, each at the node
  /// with the largest absolute deficit ρ - A (where a kernel lowers E most; a relative deficit would favour
  /// sparse regions, whose wide frozen kernels leave large relative but small absolute gaps). The level's
  /// sweeps that follow relax them with everything else; by the finest level the remainder is exact.
  void fix_count_level(Chain<D>& chain, int level) {
    typename Chain<D>::Scratch scratch;
    const Grid<D>& g = chain.grid();
    const std::vector<float>& rho = chain.density().rho;
    double w = total_weight();
    const double n = static_cast<double>(options.n);
    while (w < n) {
      std::int64_t best = -1;
      float best_residual = 0;
      const std::vector<float>& R = chain.residual();
      for (std::int64_t node = 0; node < g.size(); ++node) {
        if (!(rho[node] > 0) || !(R[node] < best_residual)) continue;
        if (w + std::ldexp(1.0, D * splits_for<D>(rho[node], level)) > n) continue;
        best_residual = R[node];
        best = node;
      }
      if (best < 0) break;
      Particle<D> p;
      p.x = node_centre(g, best);
      p.splits = static_cast<std::uint8_t>(splits_for<D>(rho[best], level));
      chain.splat(p, 1.0f, scratch);
      particles.push_back(p);
      w += p.weight();
      ++report.inserted_for_exact_count;
    }
  }

  /// Corrects the refined configuration's large-scale counts before a level's sweeps (count_balance.h):
  /// first on the pyramid level that averages kBalancePointsPerNode or more, then on each finer one up to
  /// kBalanceMaxNodes where its nodes hold kBalanceFinePointsPerNode. On every level, so that kernels are
  /// balanced while they are still relaxed: the sparse regions' kernels freeze on coarse levels. A
  /// uniform density, whose kernels are all alike and never freeze, on the two finest levels only: that
  /// takes its large-scale counts from ±1-2% to ±0.2%, as every level does, at a fraction of the cost,
  /// and leaves no wide hole where the finest level alone left a few (docs/design.md §2.6). Not for
  /// constrained sampling (tile baking), whose coarse densities come from the fixed points.
  void balance_counts_at(int base) {
    if (!options.count_balance || (setup.uniform && base > 1) || !fixed.empty() || options.n <= 0) return;
    const double max_nodes = std::min(double(options.n) / kBalancePointsPerNode, kBalanceMaxNodes);
    const int levels = static_cast<int>(setup.levels.size());
    const DensityGrid<D>& here = setup.levels[base];
    int l = base + 1;  // the first grid: level l of the pyramid, or coarser still
    while ((l < levels ? double(setup.levels[l].grid.size()) : nodes_at(l)) > max_nodes) {
      bool halves = true;  // past the pyramid's coarsest level, while its dims halve evenly
      for (int k = 0; l >= levels - 1 && k < D; ++k)
        halves &= setup.levels.back().grid.dims[k] % (2 << (l - levels + 1)) == 0;
      if (!halves) break;
      ++l;
    }
    auto source_for = [&](int level) {  // a few levels finer: the targets follow ρ's shape within a node
      return std::min(std::max(base, level - kBalanceSourceLevels), levels - 1);
    };
    std::array<int, D> first{};
    int finer_from = l - 1;  // the pyramid levels finer than the first grid, for the passes below
    int s0 = source_for(l);
    if (nodes_at(l) <= 4 * max_nodes) {  // 2 points per node or more: counts worth comparing
      for (int k = 0; k < D; ++k) first[k] = here.grid.dims[k] >> (l - base);
    } else {
      // Level l's dims are odd (a 63² coarsest level at 4,096 points): halving stops far above
      // max_nodes, so the first grid is one of its own, a whole number of its nodes spanning the domain.
      // Not below 8 × 8 nodes: at 300 points (6 × 6) it balanced the counts but left the lowest
      // frequencies no better (power 0.0031 against 0.0025, 16 seeds).
      if (max_nodes < 64) return;
      const double f = std::pow(nodes_at(base) / max_nodes, 1.0 / D);  // finest nodes per coarse node
      for (int k = 0; k < D; ++k) first[k] = std::max(1, static_cast<int>(here.grid.dims[k] / f));
      finer_from = l;
      s0 = source_for(std::min(l, base + static_cast<int>(std::floor(std::log2(f)))));
    }
    CountBalanceSettings<D> settings;
    if (base > 0) settings.support = &setup.levels[0], settings.support_scale = std::ldexp(1.0, base);
    settings.frozen_below = std::pow(sigma_max, -D);  // σ = (ρ/w)^(-1/D) >= σmax
    settings.move_frozen = base == 0;
    settings.mass_per_point = setup.mass_per_point;
    const CountBalanceReport b =
        balance_counts<D>(particles, here, setup.levels[s0], 1 << (s0 - base), first, settings);
    if (base == 0) {
      report.count_mismatch_before = b.mismatch_before;
      report.count_mismatch_after = b.mismatch_after;
    }
    // Finer passes where the density gives their nodes enough points: the steep parts of a varying
    // density have structure the first grid cannot resolve.
    settings.min_target = kBalanceFinePointsPerNode;
    for (int f = finer_from; f > base && nodes_at(f) <= kBalanceMaxNodes; --f) {
      const int sf = source_for(f);
      std::array<int, D> dims{};
      for (int k = 0; k < D; ++k) dims[k] = here.grid.dims[k] >> (f - base);
      balance_counts<D>(particles, here, setup.levels[sf], 1 << (sf - base), dims, settings);
    }
  }

  /// Nodes of the pyramid's level l, continued past its coarsest level by halving.
  double nodes_at(int l) const {
    double nodes = 1;
    for (int k = 0; k < D; ++k) nodes *= std::ldexp(double(setup.levels[0].grid.dims[k]), -l);
    return nodes;
  }

  /// Maps the configuration of level l+1 to level l (paper eq. 13, square rule, randomly rotated).
  void refine(int fine_level) {
    const DensityGrid<D>& fine = setup.levels[fine_level];
    const std::int64_t n = static_cast<std::int64_t>(particles.size());
    std::vector<std::int64_t> first_child(particles.size() + 1, 0);
    for (std::int64_t j = 0; j < n; ++j)
      first_child[j + 1] = first_child[j] + (particles[j].splits ? 1 << D : 1);
    std::vector<Particle<D>> next =
        vector_on_huge_pages(static_cast<std::size_t>(first_child[n]), Particle<D>{});
    parallel_for(n, threads, true, [&](std::int64_t j) {
      const Particle<D>& p = particles[j];
      Particle<D>* out = next.data() + first_child[j];
      Vec<D> centre;
      for (int k = 0; k < D; ++k) centre[k] = 2 * p.x[k];
      if (p.splits == 0) {
        *out = p;
        out->fresh = p.fresh && !p.active;
        out->x = fine.at(centre) > 0 ? centre : relocate(fine, centre);
        return;
      }
      Particle<D> child;
      child.splits = static_cast<std::uint8_t>(p.splits - 1);
      const double rho = fine.at(centre);
      const double sigma =
          rho > 0 ? std::min(params.sigma_cap, std::pow(rho / child.weight(), -1.0 / D)) : 1.0;
      Rng rng(options.seed, kRefineStream, static_cast<std::uint64_t>(fine_level),
              static_cast<std::uint64_t>(j));
      for (const Vec<D>& z : square_rule(rng)) {
        for (int k = 0; k < D; ++k) child.x[k] = centre[k] + sigma * z[k];
        keep_inside(fine.grid, child.x);
        if (!(fine.at(child.x) > 0)) child.x = relocate(fine, child.x);
        *out++ = child;
      }
    });
    particles.swap(next);
  }

  /// A child must not land where the finer density is zero (a coarse level's support reaches one coarse
  /// node past a sharp edge, e.g. white paper next to ink): its kernel would be massless and could never
  /// move again. Moves it to the node of highest density on the nearest ring of nodes around `centre`
  /// that has any; keeps `centre` if the whole grid is empty nearby (cannot happen for a valid density).
  static Vec<D> inside_support(const DensityGrid<D>& fine, const Vec<D>& centre) {
    std::array<int, D> c0{};
    for (int k = 0; k < D; ++k) c0[k] = static_cast<int>(std::floor(centre[k]));
    int max_radius = 0;
    for (int k = 0; k < D; ++k) max_radius = std::max(max_radius, fine.grid.dims[k]);
    for (int radius = 0; radius <= max_radius; ++radius) {
      Vec<D> best = centre;
      double best_rho = 0;
      const int side = 2 * radius + 1;
      int cells = 1;
      for (int k = 0; k < D; ++k) cells *= side;
      for (int c = 0; c < cells; ++c) {
        Vec<D> x{};
        int rest = c, chebyshev = 0;
        for (int k = 0; k < D; ++k, rest /= side) {
          const int off = rest % side - radius;
          chebyshev = std::max(chebyshev, std::abs(off));
          x[k] = c0[k] + off + 0.5;
        }
        if (chebyshev != radius || !fine.grid.canonical(x)) continue;  // the ring only
        const double rho = fine.at(x);
        if (rho > best_rho) best_rho = rho, best = x;
      }
      if (best_rho > 0) return best;
    }
    return centre;
  }

  /// Where a kernel goes that would land on zero density: into the node inside_support() finds, a quarter
  /// node from its centre towards where it wanted to be, so kernels relocated to one node stay apart.
  static Vec<D> relocate(const DensityGrid<D>& fine, const Vec<D>& wanted) {
    Vec<D> x = inside_support(fine, wanted);
    double reach = 0;
    for (int k = 0; k < D; ++k) reach = std::max(reach, std::abs(wanted[k] - x[k]));
    if (reach > 0)
      for (int k = 0; k < D; ++k) x[k] += (wanted[k] - x[k]) * std::min(1.0, 0.25 / reach);
    return x;
  }

  /// The 2^D corners of a unit-radius square (cube), rotated at random so no axis is preferred.
  std::array<Vec<D>, (1 << D)> square_rule(Rng& rng) const {
    std::array<Vec<D>, (1 << D)> z{};
    const double r = 1.0 / std::sqrt(double(D));
    for (int c = 0; c < (1 << D); ++c)
      for (int k = 0; k < D; ++k) z[c][k] = ((c >> k) & 1) ? r : -r;
    if constexpr (D == 2) {
      const double a = 6.283185307179586 * rng.uniform(), ca = std::cos(a), sa = std::sin(a);
      for (auto& v : z) v = {ca * v[0] - sa * v[1], sa * v[0] + ca * v[1]};
    } else {
      // Uniform random rotation from a unit quaternion (Shoemake).
      const double u1 = rng.uniform(), u2 = 6.283185307179586 * rng.uniform(),
                   u3 = 6.283185307179586 * rng.uniform();
      const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
      const double qw = a * std::sin(u2), qx = a * std::cos(u2), qy = b * std::sin(u3), qz = b * std::cos(u3);
      const double m[3][3] = {
          {1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)},
          {2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)},
          {2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)}};
      for (auto& v : z) {
        Vec<D> t{};
        for (int i = 0; i < 3; ++i) t[i] = m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2];
        v = t;
      }
    }
    return z;
  }

  static void keep_inside(const Grid<D>& g, Vec<D>& x) {
    if (g.canonical(x)) return;
    for (int k = 0; k < D; ++k) {  // box: reflect at the walls
      const double m = g.dims[k];
      if (x[k] < 0) x[k] = std::min(-x[k], std::nextafter(m, 0.0));
      if (x[k] >= m) x[k] = std::max(0.0, 2 * m - x[k] - 1e-9);
    }
  }

  /// Constrained sampling on coarse levels: the fixed kernels' mass, box-summed like ρ, is taken out of
  /// each coarser density, so the new points start where the fixed ones leave room. The finest level
  /// keeps the true model (fixed kernels as background, full ρ), whose chain samples P(new | fixed).
  void prepare_fixed_points() {
    const DensityGrid<D>& finest = setup.levels.front();
    for (std::size_t j = 0; j < options.fixed_points.size() / D; ++j) {
      Particle<D> p;
      for (int k = 0; k < D; ++k) p.x[k] = options.fixed_points[j * D + k] * finest.grid.dims[k];
      finest.grid.canonical(p.x);
      p.active = false;
      fixed.push_back(p);
    }
    if (fixed.empty() || setup.levels.size() < 2) return;
    Chain<D> chain(finest, params);
    typename Chain<D>::Scratch scratch;
    for (const auto& p : fixed) chain.splat(p, 1.0f, scratch);
    std::vector<float> mass(chain.residual());
    for (std::size_t i = 0; i < mass.size(); ++i) mass[i] += finest.rho[i];  // A_fixed = R + ρ
    for (std::size_t l = 1; l < setup.levels.size(); ++l) {
      mass = box_sum_half<D>(setup.levels[l - 1].grid, mass);
      std::vector<float>& rho = setup.levels[l].rho;
      for (std::size_t i = 0; i < rho.size(); ++i) rho[i] = std::max(0.0f, rho[i] - mass[i]);
    }
  }

  /// Constrained sampling, finest level, before its sweeps. The coarse levels see the fixed points only
  /// as a deficit of ρ box-summed to their nodes, which a kernel standing for 2^D points or more cannot
  /// resolve, and the refinement (eq. 13) places its children blind to them: at 500 fixed + 1,500 new
  /// points, 8-12% of the children landed within a third of a spacing of a fixed point (uniform random
  /// points: 11%), against none of one another. Such a pair leaves its start slowly (after 30 sweeps new
  /// points still stood 0.02-0.47 spacings from fixed ones, 0.47-0.65 from one another; after 100 the two
  /// agree). So each new kernel within 2.5σ of a fixed point (0.87 of the hex spacing at a point's own
  /// density, an equilibrium set's mean nearest-neighbour distance) moves to the node of deepest deficit
  /// (most negative R) within 3σ that is 2.5σ from every fixed point, or if none is, σ√2 (where a split's
  /// children start from one another).
  /// Part of the initialisation, like the refinement: the sweeps that follow sample P(new | fixed).
  void separate_from_fixed(Chain<D>& chain) {
    const Grid<D>& g = chain.grid();
    // The fixed points by cell of a bucket grid, for the neighbour searches below.
    constexpr int kCell = 4;  // nodes
    std::array<int, D> cells{};
    std::int64_t ncells = 1;
    for (int k = 0; k < D; ++k) ncells *= cells[k] = (g.dims[k] + kCell - 1) / kCell;
    auto cell_of = [&](const Vec<D>& x) {
      std::array<int, D> c{};
      for (int k = 0; k < D; ++k) c[k] = std::min(cells[k] - 1, std::max(0, static_cast<int>(x[k] / kCell)));
      return c;
    };
    auto cell_index = [&](const std::array<int, D>& c) {
      std::int64_t i = 0, stride = 1;
      for (int k = 0; k < D; ++k) i += c[k] * stride, stride *= cells[k];
      return i;
    };
    std::vector<std::int64_t> first(static_cast<std::size_t>(ncells) + 1, 0);
    std::vector<std::size_t> members(fixed.size());
    for (const auto& f : fixed) ++first[cell_index(cell_of(f.x)) + 1];
    for (std::int64_t i = 0; i < ncells; ++i) first[i + 1] += first[i];
    std::vector<std::int64_t> next(first.begin(), first.end() - 1);
    for (std::size_t j = 0; j < fixed.size(); ++j) members[next[cell_index(cell_of(fixed[j].x))]++] = j;
    // Whether x lies within r of a fixed point (torus distances on a torus).
    auto near_fixed = [&](const Vec<D>& x, double r) {
      const std::array<int, D> c0 = cell_of(x);
      const int reach = static_cast<int>(std::ceil(r / kCell));
      std::array<int, D> off{};
      off.fill(-reach);
      while (true) {
        std::array<int, D> c{};
        bool inside = true;
        for (int k = 0; k < D; ++k) {
          c[k] = c0[k] + off[k];
          if (g.torus) c[k] = ((c[k] % cells[k]) + cells[k]) % cells[k];
          inside &= c[k] >= 0 && c[k] < cells[k];
        }
        const std::int64_t i = inside ? cell_index(c) : 0;
        for (std::int64_t m = inside ? first[i] : 0; inside && m < first[i + 1]; ++m) {
          double d2 = 0;
          for (int k = 0; k < D; ++k) {
            double d = std::fabs(x[k] - fixed[members[m]].x[k]);
            if (g.torus) d = std::min(d, g.dims[k] - d);
            d2 += d * d;
          }
          if (d2 < r * r) return true;
        }
        int k = 0;
        while (k < D && ++off[k] > reach) off[k++] = -reach;
        if (k == D) return false;
      }
    };
    const double kSiblings = std::sqrt(2.0);  // a split's children start σ√2 from one another
    typename Chain<D>::Scratch scratch;
    const std::vector<float>& rho = chain.density().rho;
    const std::vector<float>& R = chain.residual();
    for (auto& p : particles) {
      const double sigma = chain.sigma_at(p), r = 2.5 * sigma;
      if (!near_fixed(p.x, r)) continue;
      chain.splat(p, -1.0f, scratch);
      const int reach = static_cast<int>(std::ceil(3 * sigma));
      std::array<int, D> lo{}, off{};
      for (int k = 0; k < D; ++k) lo[k] = static_cast<int>(std::floor(p.x[k])) - reach;
      float clear_deficit = 0, any_deficit = 0;  // the deepest, 2.5σ and σ√2 from the fixed points
      Vec<D> clear_x = p.x, any_x = p.x;
      while (true) {
        Vec<D> x{};
        double d2 = 0;
        for (int k = 0; k < D; ++k) x[k] = lo[k] + off[k] + 0.5, d2 += (x[k] - p.x[k]) * (x[k] - p.x[k]);
        if (d2 <= 9 * sigma * sigma && g.canonical(x)) {
          std::int64_t node = 0, stride = 1;
          for (int k = 0; k < D; ++k) node += static_cast<std::int64_t>(x[k]) * stride, stride *= g.dims[k];
          if (rho[node] > 0 && R[node] < clear_deficit && !near_fixed(x, r))
            clear_deficit = R[node], clear_x = x;
          if (rho[node] > 0 && R[node] < any_deficit && !near_fixed(x, kSiblings * sigma))
            any_deficit = R[node], any_x = x;
        }
        int k = 0;
        while (k < D && ++off[k] > 2 * reach) off[k++] = 0;
        if (k == D) break;
      }
      p.x = clear_deficit < 0 ? clear_x : any_deficit < 0 ? any_x : p.x;
      chain.splat(p, 1.0f, scratch);
    }
  }

  void relax_level(int level, int sweeps) {
    const auto t0 = Clock::now();
    const bool relaxing = !options.initial_points.empty();
    const bool coarsest = level == static_cast<int>(setup.levels.size()) - 1 && !relaxing;
    if (!coarsest && !relaxing) {
      refine(level);
      balance_counts_at(level);
    }
    DensityGrid<D>& density = setup.levels[level];
    Chain<D> chain(density, params, &cache);
    typename Chain<D>::Scratch scratch;
    if (level == 0)
      for (const auto& p : fixed) chain.splat(p, 1.0f, scratch);
    if (coarsest) {
      initial_configuration(chain);
      if (options.n > 0) fix_count_coarse(chain);
    } else {
      chain.splat_all(particles, threads);
    }
    if (!coarsest && !relaxing && options.n > 0) fix_count_level(chain, level);
    // Pieces of the support that zero density parts: kernels cannot move between them, so whole ones are
    // moved for them (support_pieces.h). With the count balance, which the first versions lacked.
    if (!relaxing && options.n > 0 && options.count_balance && fixed.empty() &&
        options.numerics == Numerics::kFast)
      report.moved_between_pieces += balance_pieces<D>(chain, particles, support_pieces<D>(density));
    // kOriginal keeps its first start: a recipe bakes the same tiles in every version (the baker parts
    // close pairs itself, bake/close_pairs.h).
    if (level == 0 && !relaxing && !fixed.empty() && options.numerics == Numerics::kFast)
      separate_from_fixed(chain);

    // Freeze wide kernels; bound the rest (a support constraint that keeps footprints small). Kernels not
    // yet relaxed get twice the width: a split's children are crowded and would stay so if frozen at birth.
    double widest_active = 0;
    LevelReport lr;
    for (auto& p : particles) {
      const double sigma = chain.sigma_at(p);
      p.active = sigma < (p.fresh ? 2 : 1) * sigma_max;
      if (p.active) widest_active = std::max(widest_active, sigma), ++lr.active_points;
    }
    ChainParams level_params = params;
    level_params.sigma_bound = std::min(2 * sigma_max, 1.5 * std::max(widest_active, 1.0));
    level_params.max_step = level_params.sigma_bound;
    chain.set_params(level_params);

    ChainCounters counters;
    // Burn-in: the refined configuration has its split kernels crowded together; a few sweeps of pure
    // descent (T = 0) spread them before the MH chain takes over. Part of the initialisation, like the
    // refinement itself: the sweeps that follow sample P exactly from wherever this leaves them.
    ChainParams descent = level_params;
    descent.temperature = 0;
    ChainCounters burn_in;
    const auto t1 = Clock::now();
    chain.set_params(descent);
    chain.sweeps(particles, {options.seed, level, -1, -1}, options.burn_in_sweeps, options.threads, burn_in);
    chain.set_params(level_params);
    const auto t2 = Clock::now();
    chain.sweeps(particles, {options.seed, level, 0, 1}, sweeps, options.threads, counters, [&] {
      done_sweeps += double(lr.active_points) / std::max<double>(1, options.n);
      if (options.progress) options.progress(std::min(1.0, done_sweeps / std::max(1.0, total_sweeps)));
    });
    const auto t3 = Clock::now();
    lr.setup_seconds = seconds_between(t0, t1);
    lr.burn_in_seconds = seconds_between(t1, t2);
    lr.sweep_seconds = seconds_between(t2, t3);
    for (int k = 0; k < D; ++k) lr.grid[k] = density.grid.dims[k];
    lr.points = static_cast<std::int64_t>(particles.size());
    lr.sweeps = sweeps;
    lr.proposals = counters.proposals;
    lr.accepted = counters.accepted;
    report.proposals += counters.proposals;
    report.accepted += counters.accepted;
    report.levels.push_back(lr);
    if (level == 0)
      report.energy_per_point = chain.energy() / std::max<std::size_t>(1, particles.size() + fixed.size());
  }

  /// MH sweeps at level l (0 = finest). A pyramid of one level is both: it runs the larger count, so that
  /// `sweeps` asks for more there too (the baker's coarsest count is never below its `sweeps`).
  int sweeps_at(int l) const {
    const int levels = static_cast<int>(setup.levels.size());
    if (levels == 1) return std::max(options.sweeps, options.coarsest_sweeps);
    if (l == levels - 1) return options.coarsest_sweeps;
    return l == 0 ? options.sweeps : options.coarse_sweeps;
  }

  SampleResult run() {
    const auto t0 = Clock::now();
    const int levels = static_cast<int>(setup.levels.size());
    // Progress is measured in point-sweeps relative to n: level l holds about n / 2^(D l) points.
    for (int l = 0; l < levels; ++l)
      total_sweeps += (options.burn_in_sweeps + sweeps_at(l)) * std::ldexp(1.0, -D * l);
    // Room for the finest level's footprints from the start: each level would otherwise fault in new pages.
    if (std::size_t(options.n) * sizeof(CachedFootprint<D>) <= params.cache_bytes) cache.reserve(options.n);
    prepare_fixed_points();
    if (!options.initial_points.empty()) {  // relaxation: the finest level only, from the given points
      const Grid<D>& g = setup.levels.front().grid;
      for (std::size_t j = 0; j < options.initial_points.size() / D; ++j) {
        Particle<D> p;
        for (int k = 0; k < D; ++k) p.x[k] = options.initial_points[j * D + k] * g.dims[k];
        g.canonical(p.x);
        particles.push_back(p);
      }
      total_sweeps = options.burn_in_sweeps + options.sweeps;
      relax_level(0, options.sweeps);
    } else {
      for (int l = levels - 1; l >= 0; --l) relax_level(l, sweeps_at(l));
    }
    report.model_temperature = params.temperature;
    SampleResult result;
    result.dim = D;
    result.points.resize(particles.size() * D);
    const Grid<D>& g = setup.levels[0].grid;
    for (std::size_t j = 0; j < particles.size(); ++j) {
      for (int k = 0; k < D; ++k) {
        double u = particles[j].x[k] / g.dims[k];
        if (u >= 1) u = std::nextafter(1.0, 0.0);
        result.points[j * D + k] = u;
      }
    }
    report.seconds = seconds_between(t0, Clock::now());
    result.report = report;
    return result;
  }
};

}  // namespace

template <int D>
SampleResult run_multiscale(const SamplerOptions& options, ModelSetup<D>& setup) {
  Driver<D> driver(options, setup);
  return driver.run();
}

template SampleResult run_multiscale<2>(const SamplerOptions&, ModelSetup<2>&);
template SampleResult run_multiscale<3>(const SamplerOptions&, ModelSetup<3>&);

}  // namespace kdm::gen
