// The periodogram of 2D point sets and its radial statistics (docs/design.md §6):
//   P(k) = |Σ_j exp(−2πi k·x_j)|² / n on integer k, normalised frequency f = |k| / sqrt(n),
//   RAPS = mean of P over rings of width one integer step in |k| (ring r holds r − ½ ≤ |k| < r + ½, f =
//   r/√n), lowP = mean P over 0 < f < 0.5, peak height/position of RAPS, ν_eff = largest f with RAPS < 0.1 on
//   every ring in (0, f], anisotropy (dB) = mean over rings 0.5 < f < 2.5 of 10·log10(var/mean²).
// P is exact for periodic (torus) sets; for box sets it includes the square window's leakage. A set drawn in
// a rectangle of sides lx × ly (unit area) is measured on its reciprocal lattice k = (kx/lx, ky/ly): |k| and
// f = |k|/√n keep their meaning, rings hold about as many k as on the square.
// S(k) is a non-uniform FFT (Gaussian gridding; relative error about 1e-10).
#pragma once

#include <cstddef>
#include <vector>

#include "kdm/analysis/common.h"
#include "point_io.h"

namespace kdm::analysis {

/// A (set-averaged) periodogram on the integer grid kx ∈ [−kx_max, kx_max], ky ∈ [−ky_max, ky_max]: the
/// frequency (kx/lx, ky/ly); on the unit square kx_max = ky_max = kmax and lx = ly = 1.
struct Periodogram {
  int kmax = 0;           ///< largest |k| computed (frequencies of the domain of unit area)
  int kx_max = 0;         ///< grid half-width along x (integer steps: ceil(kmax · lx))
  int ky_max = 0;         ///< grid half-width along y
  double lx = 1, ly = 1;  ///< the domain's sides (unit area; common.h's Sides)
  double n = 0;           ///< points per set (mean over the sets) — defines f = |k| / sqrt(n)
  int sets = 0;           ///< number of sets averaged
  double fmax = 0;        ///< requested normalised frequency limit; rings are complete up to it
  /// width() · height() values, row-major: index (ky+ky_max)·width() + (kx+kx_max). Only the disc |k| ≤
  /// kmax is computed; the corners outside it hold NaN.
  std::vector<double> power;
  int width() const { return 2 * kx_max + 1; }
  int height() const { return 2 * ky_max + 1; }
  double at(int kx, int ky) const {
    return power[static_cast<std::size_t>(ky + ky_max) * width() + static_cast<std::size_t>(kx + kx_max)];
  }
  double frequency(double k_norm) const;  ///< |k| → f = |k| / sqrt(n)
  int ring_max() const;                   ///< last complete ring: floor(fmax · sqrt(n)), ≤ kmax − 1
};

/// Periodogram of one 2D set up to normalised frequency `fmax`, and 0.5 at least, lowP's (kmax =
/// ceil(max(fmax, 0.5)·√n) + 1). `coords`
/// interleaved x y in [0,1]². `threads`: 0 = gen::default_thread_count(). `sides`: the domain's (common.h;
/// the unit square's by default). Cost O(n + kmax² log kmax), memory about 200 · kmax² bytes. Throws
/// InvalidInput for dim ≠ 2, empty or invalid input. Thread-safe (no shared state); the result does not
/// depend on the thread count (fixed summation order). A time for scale: docs/design.md §6.
Periodogram periodogram(const std::vector<double>& coords, int dim, double fmax, int threads = 0,
                        const Sides& sides = kUnitSides);

/// Mean periodogram of several 2D sets (all on the grid of the mean point count) in a domain of `sides`.
/// Throws InvalidInput for an empty list, 3D sets, invalid points or counts more than 10% apart.
/// Thread-safe.
Periodogram average_periodogram(const std::vector<tools::PointSet>& sets, double fmax, int threads = 0,
                                const Sides& sides = kUnitSides);

/// Radial statistics of a periodogram (see the file comment for definitions).
struct SpectrumStats {
  std::vector<double> ring_f;          ///< f of rings r = 1..ring_max (index r−1)
  std::vector<double> raps;            ///< RAPS of those rings
  std::vector<std::size_t> ring_size;  ///< number of integer k in each ring
  /// 10·log10(var/mean²) of each ring (NaN for a ring of one k, zero power or a constant one); an isotropic
  /// spectrum reads about 0 dB for one set (−10·log10(m) for m), a lattice far above at its peak.
  std::vector<double> ring_anisotropy_db;
  double low_p = 0;  ///< mean P over all k with 0 < f < 0.5; NaN where none lies there (4 points or fewer)
  double peak = 0, peak_f = 0;  ///< max RAPS and its f
  double nu_eff = 0;            ///< 0 when the first ring already has RAPS ≥ 0.1
  double anisotropy_db = 0;     ///< mean over rings 0.5 < f < 2.5 (and ≤ fmax) of 10·log10(var/mean²)
  double raps_at(double k_norm) const;  ///< RAPS of the ring holding |k| (NaN outside 1..ring_max)
};

/// Computes SpectrumStats from `p`. Thread-safe (pure).
SpectrumStats spectrum_stats(const Periodogram& p);

}  // namespace kdm::analysis
