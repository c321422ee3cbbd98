// The KDM kernel (paper eq. 1–2): w σ^-d Φ(|x - x_j| / σ) with Φ(r) = exp(-(2r/3)^2) and
// σ = (ρ(x_j) / w)^(-1/d), so its amplitude is ρ(x_j) and its mass w·∫Φ.
//
// We use the separable form Φ(r) = Π_k φ(r_k), φ(t) = exp(-(t/1.5)^2), and cut each factor off smoothly
// at |t| = kCut·σ (φ minus its value there, clamped at 0). The product is radially symmetric to within
// the 1% cut level, exact to evaluate on any grid, and lets a footprint be built from d short 1D arrays.
// Walls fold those arrays: a torus wraps indices, a box reflects them, so mass is conserved either way.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <new>
#include <type_traits>
#include <vector>

#include "sampler/grid.h"

namespace kdm::gen {

inline constexpr double kKernelWidth = 1.5;  // Φ(r) = exp(-(r / 1.5)^2), paper §3
inline constexpr double kCut = 3.2;          // footprint half-width in units of σ

/// φ's value at the cut, subtracted so the truncated kernel is continuous.
inline double kernel_edge_value() {
  static const double value = std::exp(-(kCut / kKernelWidth) * (kCut / kKernelWidth));
  return value;
}

/// ∫ of the truncated 1D factor over t in units of σ; the kernel's mass is w·J^d.
double truncated_factor_integral();

/// The nodes [lo, hi] a kernel centred at x (grid units) with scale sigma reaches along one axis,
/// before wrapping or folding.
inline void axis_reach(double x, double sigma, std::int64_t& lo, std::int64_t& hi) {
  const double reach = kCut * sigma;
  lo = static_cast<std::int64_t>(ceil_small(x - 0.5 - reach));
  hi = static_cast<std::int64_t>(floor_small(x - 0.5 + reach));
}

inline int round_up4(int n) {
  return (n + 3) & ~3;
}

/// The axis factor for one σ as a function of where x lies in its cell (u = x - floor(x)): a piecewise
/// cubic Hermite interpolant in u, exact values and derivatives at the piece ends, for the nodes within
/// kHalf of x. Models with one σ everywhere (constant density) use it as their kernel: within 1e-8 of the
/// Gaussian factor, C1 in x, and a few multiply-adds per node instead of an exp.
namespace wide {
/// The instruction sets of lanes_wide.h's passes, narrowest first.
enum class Isa : std::uint8_t { kNone, kAvx2, kAvx512 };
}  // namespace wide

struct KernelTable {
  static constexpr int kHalf = 16, kLanes = 2 * kHalf + 4, kPieces = 16, kCoefs = 7;
  double sigma = 0;
  wide::Isa isa =
      wide::Isa::kNone;     ///< evaluate 8, 12 or 16 lanes at a time with it (lanes_wide.h; the same bits)
  std::vector<float> coef;  ///< [piece][value c0..c3, derivative e0..e2][lane = j + kHalf]
  /// Rebuilds the table if it is not for `s`.
  void prepare(double s);
};

/// The truncated factor φ and its derivative with respect to x at the unwrapped nodes first, first+1, ...
/// (count rounded up to whole lane vectors: v and dv need that room), zero outside [lo, hi]. This is the
/// one definition of the kernel's values: every footprint, whatever its shape, is built from it. With a
/// `table` (prepared for sigma) the factor is the table's interpolant where it reaches, else exp(-t^2).
void axis_lanes(double x, double sigma, std::int64_t first, int count, std::int64_t lo, std::int64_t hi,
                bool with_derivative, float* v, float* dv, const KernelTable* table,
                wide::Isa isa = wide::Isa::kNone);

/// Allocates whole cache lines (64-byte aligned, sizes rounded up to 64 bytes), so a thread's scratch
/// buffers never share a line with memory another thread writes. With glibc's 16-byte chunks, the small
/// footprint buffers of the calling thread sat next to other threads' data, and every update on both
/// threads was slower (docs/design.md §2.9).
template <class T>
struct LineAllocator {
  using value_type = T;
  LineAllocator() = default;
  template <class U>
  LineAllocator(const LineAllocator<U>&) {}
  static std::size_t bytes(std::size_t n) { return (n * sizeof(T) + 63) / 64 * 64; }
  T* allocate(std::size_t n) { return static_cast<T*>(::operator new (bytes(n), std::align_val_t{64})); }
  void deallocate(T* p, std::size_t) { ::operator delete (p, std::align_val_t{64}); }
  template <class U>
  bool operator==(const LineAllocator<U>&) const {
    return true;
  }
};
template <class T>
using LineVector = std::vector<T, LineAllocator<T>>;

/// One axis of a footprint: grid indices and the factor (and its derivative w.r.t. the kernel centre).
struct AxisFactor {
  LineVector<int> index;
  LineVector<float> value;
  LineVector<float> deriv;
  int count = 0;
  /// The indices as runs of consecutive nodes (usually one, two where a torus wraps), so inner loops
  /// run over contiguous memory: run k covers index[run_offset[k] .. +run_length[k]).
  LineVector<int> run_offset, run_length;
  void build_runs() {
    run_offset.clear();
    run_length.clear();
    for (int k = 0; k < count; ++k) {
      if (k == 0 || index[k] != index[k - 1] + 1) {
        run_offset.push_back(k);
        run_length.push_back(0);
      }
      ++run_length.back();
    }
  }
  LineVector<float> fold_value, fold_deriv;  // scratch for folding
  LineVector<int> fold_touched;
};

/// Fills `a` for a kernel centred at `x` (grid units) with scale `sigma` on an axis of `m` nodes; `runs`
/// also fills its runs (only axis 0 is walked by runs).
void build_axis(AxisFactor& a, double x, double sigma, int m, bool torus, bool with_derivative,
                const KernelTable* table, bool runs, wide::Isa isa = wide::Isa::kNone);

/// Widest axis-0 window (nodes) of a contiguous footprint; wider kernels take the general path.
inline constexpr int kMaxWindow = 64;

/// A kernel's footprint on a grid: amplitude times the product of the axis factors.
template <int D>
struct Footprint {
  std::array<AxisFactor, D> axes;  ///< axes[0] is filled only when !contiguous
  double amplitude = 0;
  /// Usually axis 0 neither wraps nor folds: its factor is then kept as one window of `width` nodes (a
  /// multiple of 4, zero-padded) from `start`, so each row is whole lane vectors over contiguous memory.
  /// The padding lies within 3 nodes of the footprint; it is read and rewritten unchanged.
  bool contiguous = false;
  int start = 0, width = 0;
  alignas(16) std::array<float, kMaxWindow> row_value{}, row_deriv{};

  /// `table`: when not null, the model's kernel is KernelTable's interpolant (a model-wide choice, never per
  /// kernel); it is prepared for `sigma` here. One table serves both footprints of an update: two would
  /// fill the L1 cache between them.
  /// `isa`: where no table serves, the widest vectors to compute the factors with (the same bits).
  void build(const Grid<D>& grid, const Vec<D>& x, double sigma, double amp, bool with_derivative,
             KernelTable* table, wide::Isa isa = wide::Isa::kNone) {
    amplitude = amp;
    const KernelTable* tab = nullptr;
    if (table) {
      table->prepare(sigma);
      tab = table;
    }
    for (int k = 1; k < D; ++k)
      build_axis(axes[k], x[k], sigma, grid.dims[k], grid.torus, with_derivative, tab, false, isa);
    std::int64_t lo, hi;
    axis_reach(x[0], sigma, lo, hi);
    const int m = grid.dims[0];
    const std::int64_t len = hi - lo + 1;
    contiguous = false;
    if (lo >= 0 && hi < m && len <= kMaxWindow - 3) {
      width = round_up4(static_cast<int>(len));
      start = static_cast<int>(lo + width <= m ? lo : hi + 1 - width);
      contiguous = start >= 0;
    }
    if (contiguous) {
      axis_lanes(x[0], sigma, start, width, lo, hi, with_derivative, row_value.data(), row_deriv.data(), tab,
                 isa);
    } else {
      build_axis(axes[0], x[0], sigma, m, grid.torus, with_derivative, tab, true, isa);
    }
  }

  /// Calls row(base, P, Pd) for every row along axis 0: `base` is the flat index of the row's axis-0
  /// origin, P the product of amplitude and the outer factors, Pd[k] (k >= 1) the same with factor k
  /// replaced by its derivative.
  template <class RowFn>
  void for_each_row(const Grid<D>& grid, RowFn&& row) const {
    if constexpr (D == 2) {
      const std::int64_t s1 = grid.dims[0];
      const AxisFactor& ay = axes[1];
      for (int b = 0; b < ay.count; ++b) {
        const double p = amplitude * ay.value[b];
        std::array<double, D> pd{};
        pd[1] = amplitude * ay.deriv[b];
        row(ay.index[b] * s1, p, pd);
      }
    } else {
      static_assert(D == 3, "kdm supports dimensions 2 and 3");
      const std::int64_t s1 = grid.dims[0], s2 = std::int64_t(grid.dims[0]) * grid.dims[1];
      const AxisFactor &ay = axes[1], &az = axes[2];
      for (int c = 0; c < az.count; ++c) {
        for (int b = 0; b < ay.count; ++b) {
          const double p = amplitude * ay.value[b] * az.value[c];
          std::array<double, D> pd{};
          pd[1] = amplitude * ay.deriv[b] * az.value[c];
          pd[2] = amplitude * ay.value[b] * az.deriv[c];
          row(az.index[c] * s2 + ay.index[b] * s1, p, pd);
        }
      }
    }
  }
};

/// A small footprint kept with its particle between sweeps: a particle's next update starts where this
/// one ended, so its footprint there need not be built again (docs/design.md §2.9). Used only for the
/// exact position, σ and amplitude it was built from, so results do not change.
template <int D>
struct CachedFootprint {
  static constexpr int kLanes = 12;  ///< the common footprint at the peak density fits in 12 lanes per axis
  Vec<D> x{};
  double sigma = -1, amplitude = 0;
  std::int32_t start = 0, width = 0;
  std::array<std::int32_t, D> count{};  ///< per axis k >= 1
  alignas(16) std::array<float, kLanes> row_value{}, row_deriv{};
  std::array<std::array<float, kLanes>, D - 1> value{}, deriv{};
  std::array<std::array<std::int32_t, kLanes>, D - 1> index{};

  bool holds(const Vec<D>& at, double s, double amp) const {
    return s == sigma && amp == amplitude && at == x;
  }
  /// Keeps `fp` (built at `at` with scale `s`, with its derivative) if it is small enough; else forgets.
  void keep(const Footprint<D>& fp, const Vec<D>& at, double s) {
    sigma = -1;
    if (!fp.contiguous || fp.width > kLanes) return;
    for (int k = 1; k < D; ++k)
      if (fp.axes[k].count > kLanes) return;
    x = at;
    sigma = s;
    amplitude = fp.amplitude;
    start = fp.start;
    width = fp.width;
    std::memcpy(row_value.data(), fp.row_value.data(), kLanes * sizeof(fp.row_value[0]));
    std::memcpy(row_deriv.data(), fp.row_deriv.data(), kLanes * sizeof(fp.row_deriv[0]));
    for (int k = 1; k < D; ++k) {
      const AxisFactor& a = fp.axes[k];
      count[k] = a.count;
      // Whole arrays: fixed-size copies are a few vector moves (build_axis keeps at least kLanes).
      std::memcpy(value[k - 1].data(), a.value.data(), kLanes * sizeof(a.value[0]));
      std::memcpy(deriv[k - 1].data(), a.deriv.data(), kLanes * sizeof(a.deriv[0]));
      std::memcpy(index[k - 1].data(), a.index.data(), kLanes * sizeof(a.index[0]));
    }
  }
  /// Writes the kept footprint into `fp` (whose axis arrays are resized if needed).
  void load(Footprint<D>& fp) const {
    fp.amplitude = amplitude;
    fp.contiguous = true;
    fp.start = start;
    fp.width = width;
    std::memcpy(fp.row_value.data(), row_value.data(), kLanes * sizeof(row_value[0]));
    std::memcpy(fp.row_deriv.data(), row_deriv.data(), kLanes * sizeof(row_deriv[0]));
    for (int k = 1; k < D; ++k) {
      AxisFactor& a = fp.axes[k];
      if (static_cast<int>(a.value.size()) < kLanes) {
        a.index.resize(kLanes);
        a.value.resize(kLanes);
        a.deriv.resize(kLanes);
      }
      a.count = count[k];
      std::memcpy(a.value.data(), value[k - 1].data(), kLanes * sizeof(value[k - 1][0]));
      std::memcpy(a.deriv.data(), deriv[k - 1].data(), kLanes * sizeof(deriv[k - 1][0]));
      std::memcpy(a.index.data(), index[k - 1].data(), kLanes * sizeof(index[k - 1][0]));
    }
  }
};

/// One CachedFootprint per particle. The storage is kept while it is large enough (the sampler lends one
/// cache to every level's chain) and set up on all threads, each faulting in its own share of the pages.
template <int D>
class FootprintCache {
 public:
  std::size_t size() const { return size_; }
  CachedFootprint<D>& operator[](std::size_t j) { return entries_.get()[j]; }
  const CachedFootprint<D>& operator[](std::size_t j) const { return entries_.get()[j]; }
  /// n entries holding nothing, set up on up to `threads` threads. Not thread-safe.
  void reset(std::size_t n, int threads);
  /// Room for n entries without setting them up (size() becomes 0 if it grows). Not thread-safe.
  void reserve(std::size_t n);

 private:
  struct Release {
    void operator()(CachedFootprint<D>* p) const {
      ::operator delete (p, std::align_val_t{alignof(CachedFootprint<D>)});
    }
  };
  static_assert(std::is_trivially_destructible_v<CachedFootprint<D>>);
  std::unique_ptr<CachedFootprint<D>, Release> entries_;
  std::size_t size_ = 0, capacity_ = 0;
};

extern template class FootprintCache<2>;
extern template class FootprintCache<3>;

}  // namespace kdm::gen
