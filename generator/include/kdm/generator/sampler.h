// The full KDM sampler: Fattal, "Blue-Noise Point Sampling using Kernel Density Model", SIGGRAPH 2011
// (ACM TOG 30(4):48). Algorithm 1 (MH-corrected Langevin, one point at a time) inside Algorithm 2
// (coarse-to-fine over a pyramid of computational grids, with kernel weights for low densities).
//
// Thread safety: sample() is reentrant; concurrent calls share nothing. Each call may use up to
// `threads` worker threads of its own.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace kdm::gen {

/// Bad user input (options, densities, images): the message names the problem in one line.
struct InvalidArgument : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

/// Torus: periodic in every axis (tiles). Box: a bounded rectangle with reflecting walls, so kernels
/// keep their full mass inside the domain and points reach the edge at the target density on average:
/// along a wall they stand in a row about half a spacing in, with an empty strip a quarter spacing wide
/// before it and a ripple of density behind (docs/design.md §2.3, measured there).
enum class Domain { kTorus, kBox };

/// Relative target density at normalised position u in [0, 1)^dim. Must return a finite value >= 0. It is
/// read at the computational grid's nodes only (a few per point spacing): a bad value there is refused
/// with its position, one on a strip narrower than a node falls between them unseen.
/// Called only during the setup of sample(), from one thread at a time unless Density::thread_safe. An
/// exception it throws ends sample() with that exception.
using DensityFunction = std::function<double(const double* u)>;

/// The same density at `count` positions in one call: u holds them one after another, dim coordinates each
/// (x, y[, z] of the first, then the second's: no third one in 2D), and out receives their `count` values,
/// each what DensityFunction gives at that position. For a density whose calls cost more than its arithmetic
/// (one in another language): see Density::batch.
using DensityBatchFunction = std::function<void(const double* u, std::size_t count, double* out)>;

/// The most positions sample() passes to Density::batch in one call.
inline constexpr std::size_t kDensityBatch = std::size_t(1) << 16;

/// A density given as `width`×`height` values, row 0 at the bottom (u_y near 0): kdm's one row
/// convention, the runtime's too (kdm::DensityImageView); picture files, stored top row first, are
/// flipped once when they are read.
struct DensityImage {
  int width = 0, height = 0;
  std::vector<float> values;  ///< finite and >= 0, row by row
};

/// A 3D density given as `width`×`height`×`depth` values, in DensityImage's convention along a third axis:
/// x fastest, then y (row 0 at the bottom, u_y near 0), then z (slice 0 at u_z near 0), so value (x, y, z)
/// is values[(z · height + y) · width + x], centred at ((x + ½) / width, (y + ½) / height, (z + ½) / depth).
struct DensityVolume {
  int width = 0, height = 0, depth = 0;
  std::vector<float> values;  ///< finite and >= 0, slice by slice, each row by row
};

/// The range a density function's peak must lie in: the sampler keeps densities as floats. Densities
/// outside it are refused; only the shape matters, so scale them by a constant.
inline constexpr double kMinDensityPeak = 1e-30, kMaxDensityValue = 1e30;

/// The target density. Only its shape matters: the sampler scales it to the requested point count. Its
/// peak must lie within kMinDensityPeak ... kMaxDensityValue.
struct Density {
  DensityFunction function;  ///< empty means constant
  /// Optional, with `function` (sample() refuses it alone): the same density on many positions a call.
  /// When set, sample() reads its grids through it instead of calling `function` at each node: a run of
  /// whole nodes (every subsample of each) at a time, up to kDensityBatch positions a call, in storage
  /// order, from one thread whatever thread_safe says. Its values are checked as `function`'s are (the
  /// first bad one refused with its position) and give the same points bit for bit as `function` giving
  /// the same values. sample_classes() (multiclass.h) reads class means and summed densities through it
  /// too, and calls `function` once per point to check each point's class at the end.
  DensityBatchFunction batch;
  /// For densities sampled from an image: its size in pixels per axis. When the computational grid is
  /// coarser than this, each grid node averages several samples so no image detail aliases. 0: unknown;
  /// negative values are refused.
  int native_resolution[3] = {0, 0, 0};
  /// `function` may be called from several threads at once: the set-up then samples it on up to
  /// SamplerOptions::threads threads (the result is the same), on grids of 65,536 nodes or more (from a
  /// few thousand points in 2D; smaller ones are sampled on one thread). from_values() sets it.
  bool thread_safe = false;
  /// Set by from_values() to the values `function` interpolates: sample() then reads them itself, with
  /// the same result as calling `function` at each node but without a call per node. Leave it empty for a
  /// density of your own; if you change `function`, reset it.
  std::shared_ptr<const DensityImage> image;
  /// Set by from_volume() to the values `function` interpolates: a 3D density, which sample() refuses with
  /// dim 2. sample() calls `function` at each node (on several threads, as thread_safe is set): with a
  /// 64³ volume that is a few per cent of a 3D run (docs/design.md §2.1). If you change `function`, reset it.
  std::shared_ptr<const DensityVolume> volume;

  /// The uniform density (no function): 1 everywhere.
  static Density constant() { return {}; }
  /// A uniform density of `value` (finite, >= 0, else InvalidArgument): alone only its shape matters, as
  /// constant()'s; in sample_classes() (multiclass.h) the classes' values set their shares of the points.
  static Density constant(double value);
  /// A 2D density from `width`×`height` values (row 0 at the bottom, i.e. at u_y near 0), bilinearly
  /// interpolated. Values must be finite and >= 0, and not all zero. Throws InvalidArgument otherwise.
  /// 2D only: sample() refuses it with dim 3.
  static Density from_values(int width, int height, std::vector<float> values);
  /// A 3D density from `width`×`height`×`depth` values laid out as DensityVolume says (x fastest, row 0 at
  /// the bottom, slice 0 at u_z near 0), trilinearly interpolated between voxel centres and clamped at the
  /// faces. Sets native_resolution to the three sizes, so a grid coarser than the volume averages several
  /// samples per node. Sizes must be > 0 with a product that fits in memory's index range, and values
  /// finite, >= 0 and not all zero; throws InvalidArgument otherwise. 3D only: sample() refuses it with
  /// dim 2. The sides of the domain are SamplerOptions::extent's, whatever the volume's shape.
  static Density from_volume(int width, int height, int depth, std::vector<float> values);
};

/// The sampler's arithmetic (see SamplerOptions::numerics). Each gives the same bits on every machine and
/// for every thread count; the two differ from each other in their random stream and last bits, so the same
/// seed gives different point sets.
enum class Numerics {
  /// The default and the fastest: Langevin noise from a ziggurat, and energy and gradient sums kept per
  /// vector lane, so the update passes run sixteen lanes wide on CPUs with AVX-512 with the same result.
  /// Its sweeps keep points in moving cells (no density bias at cell borders) and constrained runs start
  /// new points clear of the fixed ones (docs/design.md §2.7, §2.8).
  kFast,
  /// kdm's first versions: Box–Muller noise, four-lane sums, fixed cells that points cross (a few percent
  /// more density on one side of each cell border, within half a grid node) and the first start of
  /// constrained runs. Tile baking (bake.h) and `kdm verify` keep it, so a recipe bakes the same tiles in
  /// every version.
  kOriginal,
};

/// What sample() draws: the count, domain, temperature, seed and sweep schedule.
struct SamplerOptions {
  int dim = 2;                     ///< 2 or 3
  Domain domain = Domain::kTorus;  ///< periodic, or a box with walls
  double extent[3] = {1, 1,
                      1};  ///< relative side lengths (aspect ratio); normalised output is still [0,1)^dim
  /// Exact number of points to return (> 0), at most 2^31 and as many as a finest grid of
  /// max_grid_nodes holds (about 9 million in 2D, InvalidArgument past it). Set to 0 to use `resolution`.
  std::int64_t n = 4096;
  /// Used when n == 0: finest grid nodes along the shortest axis; the count then follows from the model
  /// as in the paper: for a uniform density about 0.074 · resolution² points in 2D and 0.027 ·
  /// resolution³ in 3D at the default peak_density, in proportion to it.
  int resolution = 0;
  /// User-facing temperature (>= 0). 0.5 is the reference implementation's default look; 0 is a
  /// deterministic energy descent. The model temperature of eq. 4 is temperature * kModelTemperaturePerUser.
  double temperature = 0.5;
  std::uint64_t seed = 1;  ///< any value; the same options and seed give the same points
  /// 0 = default_thread_count(), else 1 to kMaxThreads. The output does not depend on this.
  int threads = 0;
  /// MH-Langevin sweeps on the finest level. The paper uses 15 (unadjusted); with the MH test 30 reach
  /// the reference implementation's statistics (docs/design.md §2).
  int sweeps = 30;
  /// MH-Langevin sweeps on each level between the coarsest and the finest: the paper's 15. The finest
  /// level's sweeps set the local statistics; more here cost time and change nothing measurable.
  int coarse_sweeps = 15;
  /// Sweeps on the coarsest grid, where points start far from equilibrium (tile baking keeps 60). This
  /// level is too small to cut into cells for two threads, so its sweeps run on one.
  int coarsest_sweeps = 30;  ///< a pyramid of one level runs max(sweeps, coarsest_sweeps)
  /// Deterministic descent sweeps (T = 0) right after each refinement, before the MH sweeps: they spread
  /// the crowded children of split kernels. Initialisation only; the MH sweeps then sample P.
  int burn_in_sweeps = 3;
  /// Δt of eq. 5 (Δt_j = T σ_j Δt / w), model units; 0 = automatic: 0.35 in 2D, 0.1 in 3D, where the chain
  /// relaxes fastest per sweep (docs/design.md §2.2).
  double step = 0;
  bool metropolis = true;  ///< false = unadjusted Langevin (biased; for experiments only)
  Numerics numerics = Numerics::kFast;
  /// The widest vectors the update passes may use: 16 lanes (AVX-512, where the CPU has it), 8 (AVX2),
  /// 4 (SSE2, every x86-64). The output does not depend on it (the passes give the same bits at every
  /// width); lower values are for testing that and for measuring. Other values are refused.
  int vector_lanes = 16;
  /// Memory for keeping each point's kernel footprint between sweeps (about 300 bytes per point in 2D):
  /// an update then builds one footprint, not two (docs/design.md §2.9). Levels with more points than fit
  /// skip it. The output does not depend on it.
  std::size_t footprint_cache_bytes = std::size_t(256) << 20;
  /// Before a level's sweeps, move the points so that their counts on coarse grids match the density.
  /// Without it sparse regions get too few points, the more so the wider the density's range, and even a
  /// uniform density's counts drift by 1-2% across the domain (7% along a 3:1 box) that the finest sweeps
  /// cannot carry back (docs/design.md §2.6). Off to measure that, and where a run must give the first
  /// versions' bits (tile baking and its verification).
  bool count_balance = true;
  double peak_density = 0.43;  ///< ρ at the densest grid node, in (0, 1] (the paper requires ρ <= 1)
  /// Kernels at least this wide (grid units) are frozen (paper: σmax); 0: 16 in 2D, 4 in 3D, where a
  /// footprint grows as σ³ (docs/design.md §2.4).
  double sigma_max = 0;
  int coarsest_grid = 32;  ///< nodes along the shortest axis of the coarsest grid (paper: 32)
  std::int64_t max_grid_nodes = std::int64_t(1) << 27;  ///< refuse larger finest grids (memory guard)
  /// Constrained sampling: points already placed (normalised coordinates, dim per point). Their kernels are
  /// background that never moves; the chain samples the n new points from P(new | fixed). The result
  /// holds only the new points. The density is scaled for n + fixed count points in all.
  std::vector<double> fixed_points;
  /// Relaxation instead of sampling: when not empty, the free points start here (normalised coordinates,
  /// dim per point; n is taken as their count) and only `burn_in_sweeps` descent and `sweeps` MH sweeps run
  /// on the finest grid, with no multi-scale. The result keeps their order. For checking that a point set
  /// already is an equilibrium sample (it then neither drifts nor drops in energy).
  std::vector<double> initial_points;
  /// Called with (fraction done in [0,1]) between sweeps, and with 1 once the points are done. Optional.
  /// An exception it throws ends sample() with that exception: a way to cancel a long run.
  std::function<void(double)> progress;
};

/// How the user-facing temperature maps to T of eq. 4: the reference implementation multiplies the
/// kernel derivative by 4 where d/dx of Φ(r) = exp(-(2r/3)^2) gives 8/9, so its T = 0.5 is T = 0.5 / 4.5
/// in the units of eq. 3–4. We keep its scale so that `temperature 0.5` looks like the paper's figures.
inline constexpr double kModelTemperaturePerUser = 1.0 / 4.5;
/// The highest temperature SamplerOptions takes. Points are white noise by about 300 (at 4,096 points:
/// lowP 0.91 at 100, 1.00 at 300); past 1,000 the MH test refuses nearly every move (acceptance 4% at
/// 1,000, 1.5% at 3,000) and the points keep their starting places, a set more ordered again.
inline constexpr double kMaxTemperature = 1000;

/// One level of the multi-scale run (docs/design.md §2.4).
struct LevelReport {
  int grid[3] = {0, 0, 0};         ///< grid nodes per axis
  std::int64_t points = 0;         ///< points present at this level
  std::int64_t active_points = 0;  ///< points relaxed at this level (σ < sigma_max)
  int sweeps = 0;                  ///< MH-Langevin sweeps run
  std::uint64_t proposals = 0;     ///< moves proposed
  std::uint64_t accepted = 0;      ///< moves the MH test accepted
  /// Wall seconds: refinement, splats, initial configuration and count fixing; the descent (burn-in)
  /// sweeps; the MH sweeps. For finding where a run's time goes (`kdm sample --timing`).
  double setup_seconds = 0, burn_in_seconds = 0, sweep_seconds = 0;
};

/// How a sample() run went.
struct SampleReport {
  std::vector<LevelReport> levels;  ///< coarsest first
  std::uint64_t proposals = 0;      ///< over all levels
  std::uint64_t accepted = 0;       ///< over all levels
  double acceptance_rate() const { return proposals ? double(accepted) / double(proposals) : 0.0; }
  double model_temperature = 0;  ///< the temperature of eq. 4 (temperature · kModelTemperaturePerUser)
  double energy_per_point = 0;   ///< E / n at the end, finest grid
  std::int64_t inserted_for_exact_count = 0;  ///< points added so that exactly n come out
  std::int64_t removed_for_exact_count = 0;   ///< points removed so that exactly n come out
  /// Kernels moved from one piece of the density's support to another (pieces that zero density parts),
  /// so that each piece gets its share: over all levels.
  std::int64_t moved_between_pieces = 0;
  /// Varying densities: Σ|count − target| / n on a coarse grid before and after the refined points'
  /// large-scale counts were balanced for the finest sweeps (0 when no balance ran).
  double count_mismatch_before = 0, count_mismatch_after = 0;
  double model_seconds = 0;  ///< building the density pyramid (before the levels run)
  int threads = 1;           ///< threads the run used (SamplerOptions::threads, or default_thread_count())
  double seconds = 0;        ///< the whole call, model_seconds included
};

/// sample()'s points and report.
struct SampleResult {
  int dim = 2;                 ///< as SamplerOptions::dim
  std::vector<double> points;  ///< n * dim coordinates, normalised to [0, 1) on every axis
  SampleReport report;
  std::size_t size() const { return points.size() / static_cast<std::size_t>(dim); }
};

/// The threads sample() and bake_tileset() use when given 0: the first number in OMP_NUM_THREADS if it is
/// set (build tools set it to share the machine), else the CPUs this process may run on (its affinity
/// mask, as `taskset` or a container sets it), capped by its cgroup's CPU quota (a CI runner's share).
/// At least 1, at most kMaxThreads. Worked out once per process. Waiting threads spin for at most 50 µs and
/// then sleep, so a run on a busy machine does not burn the cores its own threads are waiting for.
int default_thread_count();

/// The most threads sample() and bake_tileset() take: more than the cores of today's largest machines,
/// yet few enough that a typo cannot exhaust memory or time (each has its own stack and scratch).
inline constexpr int kMaxThreads = 256;

/// Draws one point set from the KDM model. Throws InvalidArgument on bad options or density.
SampleResult sample(const SamplerOptions& options, const Density& density = Density::constant());

/// The most sets one sample_sets() call takes, and the most points (sets × n) it returns in all: 2^27
/// points are 2 GiB of coordinates in 2D, 3 GiB in 3D. Ask for more in several calls.
inline constexpr std::int64_t kMaxSampleSets = std::int64_t(1) << 20;
inline constexpr std::int64_t kMaxSampleSetPoints = std::int64_t(1) << 27;

/// Many independent point sets of one kind at once, for Monte Carlo work that wants a small set per pixel
/// or per frame: set k is bit for bit what sample() returns for `options` with seed `seeds[k]`, for every
/// thread count. The sets run in parallel, one per thread of up to options.threads (0:
/// default_thread_count()), each on one thread (a set of up to a few thousand points runs its sweeps on one
/// thread anyway), so on c cores a batch of small sets runs about c times as many sets per second as sample()
/// calls do; when there are fewer sets than threads each set shares out the rest. The model (the density
/// sampled on the grids, which does not depend on the seed) is built once for all sets: a density function is
/// called as for one sample() call, from the calling thread, not once per set. options.n must be > 0 (with a
/// `resolution` the count could differ between sets); options.seed is not used. options.progress, if set, is
/// called from the calling thread only, with the fraction of all sets done; an exception it throws ends the
/// call with that exception once the running sets stop at their next sweep. Each report's model_seconds is
/// the shared model's build, which its `seconds` leaves out. Throws InvalidArgument as sample() does, and for
/// no seeds, more than kMaxSampleSets of them, or more than kMaxSampleSetPoints points in all.
std::vector<SampleResult> sample_sets(const SamplerOptions& options, const Density& density,
                                      const std::vector<std::uint64_t>& seeds);

/// sample_sets() writing into caller-owned memory: set k's n · dim coordinates (as SampleResult::points)
/// go to points[k · n · dim ...], so `points` must hold seeds.size() · n · dim doubles (n: options.n, or
/// the count of initial_points). Returns each set's report. Throws as sample_sets() does, before writing.
std::vector<SampleReport> sample_sets(const SamplerOptions& options, const Density& density,
                                      const std::vector<std::uint64_t>& seeds, double* points);

/// E / n of `points` (normalised coordinates) under the model sample() would use for the same count,
/// domain and density: the energy of eq. 3 on the finest grid. Lets any point set (tiles, other
/// samplers) be compared with full-sampler runs on one scale. Throws InvalidArgument on bad input.
double energy_per_point(const SamplerOptions& options, const Density& density,
                        const std::vector<double>& points);

}  // namespace kdm::gen
