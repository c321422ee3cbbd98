// Periodogram P(k) = |Σ_j exp(−2πi k·x_j)|² / n on the integer grid (docs/design.md §6), evaluated as the
// complex matrix product S = E_xᵀ E_y where E_x(j, kx) = exp(−2πi kx x_j) for kx ∈ [0, kmax] and
// E_y(j, ky) = exp(−2πi ky y_j) for ky ∈ [−kmax, kmax]; P(−k) = P(k) fills the other half-plane.
// Points are processed in chunks (bounded memory) on a fixed number of accumulation lanes, so the
// summation order (and the result) does not depend on the number of threads.
#include "kdm/analysis/periodogram.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <limits>
#include <string>

#include "kdm/analysis/common.h"
#include "parallel.h"

namespace kdm::analysis {
namespace {

// Exponentials and the per-chunk products are single precision (twice the SIMD throughput); each chunk's
// product (≤ 256 terms of modulus 1, error ≲ 1e-5 absolute) is accumulated in double precision, so P has
// an absolute error ≲ 1e-8 · |S| / n — far below any statistic reported.
using MatF = Eigen::Matrix<std::complex<float>, Eigen::Dynamic, Eigen::Dynamic>;
using Mat = Eigen::Matrix<std::complex<double>, Eigen::Dynamic, Eigen::Dynamic>;
constexpr double kTwoPi = 6.283185307179586476925286766559;
constexpr std::ptrdiff_t kChunk = 256;  // points per matrix product
constexpr int kLanes = 4;               // independent partial sums (fixed: determinism)
constexpr int kRowBlock = 32;           // kx rows per product (the half-disc is covered by such strips)

// Column j of `e` (rows 0..kmax) gets exp(−2πi k v) for k = 0..kmax: a rotation recurrence, re-anchored
// with an exact sincos every 32 steps to keep the phase error ≲ 1e-14.
void fill_exponentials(MatF& e, Eigen::Index col, double v, int kmax, int row0, bool mirror) {
  const std::complex<double> step = std::polar(1.0, -kTwoPi * v);
  std::complex<double> z(1.0, 0.0);
  for (int k = 0; k <= kmax; ++k) {
    if (k % 32 == 0) z = std::polar(1.0, -kTwoPi * std::fmod(k * v, 1.0));
    const std::complex<float> zf(static_cast<float>(z.real()), static_cast<float>(z.imag()));
    e(row0 + k, col) = zf;
    if (mirror && k > 0) e(row0 - k, col) = std::conj(zf);
    z *= step;
  }
}

}  // namespace

double Periodogram::frequency(double k_norm) const {
  return n > 0 ? k_norm / std::sqrt(n) : 0.0;
}

int Periodogram::ring_max() const {
  const int r = static_cast<int>(std::floor(fmax * std::sqrt(n) + 1e-9));
  return std::max(0, std::min(r, kmax - 1));
}

namespace {

// Adds |S(k)|²/n of one set to `acc` ((2kmax+1)² grid). n_norm is the set's own point count.
void accumulate_set(const std::vector<double>& coords, int kmax, int threads, std::vector<double>& acc) {
  const std::ptrdiff_t n = static_cast<std::ptrdiff_t>(coords.size() / 2);
  const int kx_count = kmax + 1, ky_count = 2 * kmax + 1;
  const std::ptrdiff_t chunks = (n + kChunk - 1) / kChunk;
  const int lanes = static_cast<int>(std::min<std::ptrdiff_t>(kLanes, std::max<std::ptrdiff_t>(1, chunks)));
  // Only the half-disc |k| ≤ kmax is needed: rows kx of a block share the ky range of their smallest kx.
  std::vector<int> block_width;
  for (int kx0 = 0; kx0 <= kmax; kx0 += kRowBlock)
    block_width.push_back(static_cast<int>(std::floor(std::sqrt(double(kmax) * kmax - double(kx0) * kx0))));
  std::vector<Mat> partial(lanes, Mat::Zero(kx_count, ky_count));
  detail::parallel_for(lanes, threads, [&](std::ptrdiff_t lane, int) {
    MatF ex(kx_count, kChunk), ey(ky_count, kChunk), prod(kRowBlock, ky_count);
    for (std::ptrdiff_t c = lane; c < chunks; c += lanes) {
      const std::ptrdiff_t j0 = c * kChunk, m = std::min(kChunk, n - j0);
      for (std::ptrdiff_t j = 0; j < m; ++j) {
        fill_exponentials(ex, j, coords[2 * (j0 + j)], kmax, 0, false);
        fill_exponentials(ey, j, coords[2 * (j0 + j) + 1], kmax, kmax, true);
      }
      for (std::size_t b = 0; b < block_width.size(); ++b) {
        const int kx0 = static_cast<int>(b) * kRowBlock, rows = std::min(kRowBlock, kx_count - kx0);
        const int w = block_width[b], cols = 2 * w + 1;
        prod.topLeftCorner(rows, cols).noalias() =
            ex.block(kx0, 0, rows, m) * ey.block(kmax - w, 0, cols, m).transpose();
        partial[lane].block(kx0, kmax - w, rows, cols) +=
            prod.topLeftCorner(rows, cols).cast<std::complex<double>>();
      }
    }
  });
  for (int l = 1; l < lanes; ++l) partial[0] += partial[l];
  const Mat& s = partial[0];
  const int side = 2 * kmax + 1;
  const double inv_n = 1.0 / static_cast<double>(n);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int kx = 0; kx <= kmax; ++kx)
    for (int ky = -kmax; ky <= kmax; ++ky) {
      const bool inside = kx * kx + ky * ky <= kmax * kmax;
      const double p = inside ? std::norm(s(kx, ky + kmax)) * inv_n : nan;
      acc[static_cast<std::size_t>(ky + kmax) * side + (kx + kmax)] += p;
      if (kx > 0) acc[static_cast<std::size_t>(kmax - ky) * side + (kmax - kx)] += p;
    }
}

Periodogram make_grid(double mean_n, double fmax) {
  if (!(fmax > 0) || !std::isfinite(fmax)) throw InvalidInput("fmax must be a positive number");
  Periodogram p;
  p.n = mean_n;
  p.fmax = fmax;
  const double kmax = std::ceil(fmax * std::sqrt(mean_n)) + 1;  // checked before it becomes an int
  if (!(kmax <= 4096)) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "periodogram grid too large (fmax·sqrt(n) = %.6g > 4095): lower fmax to %.4g", kmax - 1,
                  std::floor(4095 / std::sqrt(mean_n) * 1e3) / 1e3);
    throw InvalidInput(text);
  }
  p.kmax = static_cast<int>(kmax);
  p.power.assign(static_cast<std::size_t>(p.side()) * p.side(), 0.0);
  return p;
}

}  // namespace

Periodogram periodogram(const std::vector<double>& coords, int dim, double fmax, int threads) {
  tools::PointSet s;
  s.dim = dim;
  s.coords = coords;
  return average_periodogram({s}, fmax, threads);
}

Periodogram average_periodogram(const std::vector<tools::PointSet>& sets, double fmax, int threads) {
  if (sets.empty()) throw InvalidInput("no point sets to analyse");
  double total = 0;
  std::size_t fewest = sets.front().size(), most = fewest;
  for (const tools::PointSet& s : sets) {
    if (s.dim != 2) throw InvalidInput("the periodogram is implemented for 2D sets only");
    validate_points(s.coords, s.dim);
    if (s.size() == 0) throw InvalidInput("empty point set");
    total += static_cast<double>(s.size());
    fewest = std::min(fewest, s.size()), most = std::max(most, s.size());
  }
  // Frequencies are in units of each set's √n: on one grid, sets of other sizes would mix frequencies
  // (at 10% apart in count, 5% apart in frequency).
  if (double(most) > 1.1 * double(fewest))
    throw InvalidInput("the spectrum pools sets of about one size: these hold " + std::to_string(fewest) +
                       " to " + std::to_string(most) + " points (more than 10% apart); analyse them apart");
  Periodogram p = make_grid(total / static_cast<double>(sets.size()), fmax);
  for (const tools::PointSet& s : sets) accumulate_set(s.coords, p.kmax, threads, p.power);
  for (double& v : p.power) v /= static_cast<double>(sets.size());
  p.sets = static_cast<int>(sets.size());
  return p;
}

double SpectrumStats::raps_at(double k_norm) const {
  const long r = std::lround(k_norm);
  if (r < 1 || r > static_cast<long>(raps.size())) return std::numeric_limits<double>::quiet_NaN();
  return raps[static_cast<std::size_t>(r - 1)];
}

SpectrumStats spectrum_stats(const Periodogram& p) {
  SpectrumStats st;
  const int rmax = p.ring_max();
  std::vector<double> sum(rmax + 1, 0.0), sum2(rmax + 1, 0.0);
  std::vector<std::size_t> count(rmax + 1, 0);
  const double k_low = 0.5 * std::sqrt(p.n);
  double low_sum = 0;
  std::size_t low_count = 0;
  for (int ky = -p.kmax; ky <= p.kmax; ++ky)
    for (int kx = -p.kmax; kx <= p.kmax; ++kx) {
      if (kx == 0 && ky == 0) continue;
      const double kn = std::hypot(kx, ky);
      const double v = p.at(kx, ky);
      if (kn < k_low) {
        low_sum += v;
        ++low_count;
      }
      const long r = std::lround(kn);
      if (r < 1 || r > rmax) continue;
      sum[r] += v;
      sum2[r] += v * v;
      ++count[r];
    }
  st.low_p = low_count ? low_sum / static_cast<double>(low_count) : std::numeric_limits<double>::quiet_NaN();
  bool below = true;
  double aniso_sum = 0;
  int aniso_rings = 0;
  for (int r = 1; r <= rmax; ++r) {
    const double mean = count[r] ? sum[r] / static_cast<double>(count[r]) : 0.0;
    const double f = p.frequency(r);
    st.ring_f.push_back(f);
    st.raps.push_back(mean);
    st.ring_size.push_back(count[r]);
    if (mean > st.peak) {
      st.peak = mean;
      st.peak_f = f;
    }
    below = below && mean < 0.1;
    if (below) st.nu_eff = f;
    if (f > 0.5 && f < 2.5 && count[r] > 1 && mean > 0) {
      const double c = static_cast<double>(count[r]);
      const double var = std::max(0.0, (sum2[r] - c * mean * mean) / (c - 1.0));
      if (var > 0) {
        aniso_sum += 10.0 * std::log10(var / (mean * mean));
        ++aniso_rings;
      }
    }
  }
  st.anisotropy_db = aniso_rings ? aniso_sum / aniso_rings : std::numeric_limits<double>::quiet_NaN();
  return st;
}

}  // namespace kdm::analysis
