// Periodogram and radial statistics pinned to closed forms: a single point (P ≡ 1), white noise
// (E P = 1), a jittered grid (E P = 1 − sinc²(kx/m) sinc²(ky/m)), a torus-periodic near-hex lattice (P = n
// exactly on the reciprocal lattice, 0 elsewhere), plus determinism across thread counts.
#include <gtest/gtest.h>

#include <cmath>

#include "kdm/analysis/common.h"
#include "kdm/analysis/periodogram.h"
#include "kdm/analysis/plots.h"
#include "test_sets.h"

namespace kdm::analysis {
namespace {

using testing::jittered_grid;
using testing::torus_hex_lattice;
using testing::uniform_set;

constexpr double kPi = 3.14159265358979323846;

double sinc(double x) {
  return x == 0 ? 1.0 : std::sin(kPi * x) / (kPi * x);
}

TEST(Periodogram, SinglePointIsFlat) {
  const Periodogram p = periodogram({0.3141, 0.2718}, 2, 20.0);  // n = 1: |exp(·)|² = 1 for every k
  for (int ky = -p.kmax; ky <= p.kmax; ++ky)
    for (int kx = -p.kmax; kx <= p.kmax; ++kx) {
      if (kx * kx + ky * ky > p.kmax * p.kmax) {
        ASSERT_TRUE(std::isnan(p.at(kx, ky)));  // outside the computed disc
        continue;
      }
      ASSERT_NEAR(p.at(kx, ky), 1.0, 1e-6) << kx << "," << ky;
    }
}

// The non-uniform FFT against the direct sum, at low and at the largest frequencies, where dividing out
// the Gaussian magnifies its error most. Its error is about 1e-10 relative (measured 4e-11 on 50,000
// points); 1e-8 would still catch any mistake in the spreading or the deconvolution.
TEST(Periodogram, MatchesDirectSum) {
  for (const std::size_t n : {std::size_t(300), std::size_t(20000)}) {
    const tools::PointSet s = uniform_set(n, 3);
    const Periodogram p = periodogram(s.coords, 2, n == 300 ? 1.0 : 2.5);
    const int edge = static_cast<int>(p.kmax / std::sqrt(2.0));
    for (const auto& k : std::vector<std::pair<int, int>>{{1, 0},
                                                          {0, -3},
                                                          {5, 7},
                                                          {-9, 4},
                                                          {-p.kmax * 7 / 10, p.kmax * 7 / 10},
                                                          {0, -p.kmax},
                                                          {p.kmax, 0},
                                                          {edge, -edge},
                                                          {-1, p.kmax - 1}}) {
      double re = 0, im = 0;
      for (std::size_t j = 0; j < s.size(); ++j) {
        const double phase = -2 * kPi * (k.first * s.coords[2 * j] + k.second * s.coords[2 * j + 1]);
        re += std::cos(phase), im += std::sin(phase);
      }
      const double direct = (re * re + im * im) / double(n);
      EXPECT_NEAR(p.at(k.first, k.second), direct, 1e-8 * (1 + direct))
          << n << " points, k = " << k.first << "," << k.second;
    }
  }
}

// lowP's frequencies (f < 0.5) are computed whatever fmax asks for: a spectrum to f = 0.3 has the same
// lowP as one to 2.5 (its rings stop at 0.3).
TEST(Periodogram, LowPowerIsMeasuredWhateverTheLimit) {
  const tools::PointSet s = uniform_set(1000, 5);
  const SpectrumStats low = spectrum_stats(periodogram(s.coords, 2, 0.3)),
                      full = spectrum_stats(periodogram(s.coords, 2, 2.5));
  ASSERT_TRUE(std::isfinite(low.low_p));
  EXPECT_NEAR(low.low_p, full.low_p, 1e-9 * full.low_p);
  EXPECT_EQ(low.raps.size(), 9u);  // rings 1 .. floor(0.3 · √1000)
}

TEST(Periodogram, IndependentOfThreadCount) {
  const tools::PointSet s = uniform_set(3000, 4);
  const Periodogram a = periodogram(s.coords, 2, 1.5, 1), b = periodogram(s.coords, 2, 1.5, 2);
  ASSERT_EQ(a.power.size(), b.power.size());
  for (std::size_t i = 0; i < a.power.size(); ++i)
    ASSERT_TRUE(a.power[i] == b.power[i] || (std::isnan(a.power[i]) && std::isnan(b.power[i]))) << i;
}

TEST(Periodogram, WhiteNoiseIsOne) {
  // For n i.i.d. uniform points on the torus and integer k ≠ 0, E|S(k)|² = n exactly, so E P(k) = 1, and P(k)
  // is close to exponential (S is a sum of n random unit phasors → complex Gaussian), sd = mean = 1.
  // P(k) = P(−k), so a mean over K grid values of M sets averages K·M/2 independent values: sd =
  // sqrt(2/(K·M)). We allow 5 sd.
  std::vector<tools::PointSet> sets;
  for (unsigned seed = 0; seed < 4; ++seed) sets.push_back(uniform_set(4096, 100 + seed));
  const Periodogram p = average_periodogram(sets, 2.5);
  const SpectrumStats st = spectrum_stats(p);
  std::size_t low_count = 0;  // number of k with 0 < |k| < 0.5·√n
  for (int ky = -p.kmax; ky <= p.kmax; ++ky)
    for (int kx = -p.kmax; kx <= p.kmax; ++kx)
      if ((kx || ky) && std::hypot(kx, ky) < 0.5 * std::sqrt(p.n)) ++low_count;
  EXPECT_NEAR(st.low_p, 1.0, 5 * std::sqrt(2.0 / (low_count * 4.0)));
  ASSERT_EQ(st.raps.size(), 160u);  // rings up to 2.5·64
  double sum = 0, weight = 0;
  for (std::size_t r = 0; r < st.raps.size(); ++r) {
    const double sd = std::sqrt(2.0 / (st.ring_size[r] * 4.0));
    EXPECT_NEAR(st.raps[r], 1.0, 5 * sd) << "ring " << r + 1;
    sum += st.raps[r] * st.ring_size[r];
    weight += st.ring_size[r];
  }
  EXPECT_NEAR(sum / weight, 1.0, 5 * std::sqrt(2.0 / (weight * 4.0)));
  EXPECT_EQ(st.nu_eff, 0.0);  // the first ring is not below 0.1
  // Anisotropy: per ring var/mean² of the 4-set average ≈ 1/4 → about −6 dB, on every ring of many k (one
  // above f = 0.5 holds at least 200, half of them independent: the ratio's sd is under 0.2 of it, and
  // 3 dB is a factor 2); the figure is their mean over 0.5 < f < 2.5.
  EXPECT_NEAR(st.anisotropy_db, 10 * std::log10(1.0 / 4), 0.5);
  ASSERT_EQ(st.ring_anisotropy_db.size(), st.raps.size());
  double in_range = 0;
  int rings = 0;
  for (std::size_t r = 0; r < st.raps.size(); ++r)
    if (st.ring_f[r] > 0.5 && st.ring_f[r] < 2.5) {
      EXPECT_NEAR(st.ring_anisotropy_db[r], 10 * std::log10(1.0 / 4), 3.0) << "ring " << r + 1;
      in_range += st.ring_anisotropy_db[r], ++rings;
    }
  EXPECT_NEAR(in_range / rings, st.anisotropy_db, 1e-12);
}

TEST(Periodogram, JitteredGridMatchesSincFormula) {
  // One point uniform in each of m² cells: E P(k) = 1 − sinc²(kx/m)·sinc²(ky/m) for every integer k ≠ 0
  // (E|S|² = n + |φ|²(|Σ_cells e^{−2πik·c}|² − n) with φ the jitter's characteristic function; the cell sum
  // is m² on the lattice, where φ = 0, and 0 elsewhere). P is again ~exponential: sd(P) ≈ E P.
  const int m = 48, sets_n = 6;
  std::vector<tools::PointSet> sets;
  for (int s = 0; s < sets_n; ++s) sets.push_back(jittered_grid(m, 200 + s));
  const Periodogram p = average_periodogram(sets, 2.0);
  const SpectrumStats st = spectrum_stats(p);
  // Compare band means (many k) with their expectations; var of a band mean = 2 Σ (E P)² / (M K²).
  double low_band_mean = -1;
  const double bands[][2] = {{0.0, 0.5}, {0.5, 1.0}, {1.0, 1.5}, {1.5, 2.0}};
  for (const auto& band : bands) {
    double sum = 0, expect = 0, var = 0;
    std::size_t count = 0;
    for (int ky = -p.kmax; ky <= p.kmax; ++ky)
      for (int kx = -p.kmax; kx <= p.kmax; ++kx) {
        const double f = p.frequency(std::hypot(kx, ky));
        if ((kx == 0 && ky == 0) || f <= band[0] || f >= band[1]) continue;
        const double e = 1 - std::pow(sinc(double(kx) / m) * sinc(double(ky) / m), 2);
        sum += p.at(kx, ky), expect += e, var += e * e, ++count;
      }
    const double sd = std::sqrt(2 * var / sets_n) / count;
    if (band[0] == 0.0) low_band_mean = sum / count;
    EXPECT_NEAR(sum / count, expect / count, 5 * sd) << "band " << band[0] << ".." << band[1];
  }
  // lowP is by definition the mean over the first band; and stratification puts it well below white noise.
  EXPECT_NEAR(st.low_p, low_band_mean, 1e-12);
  EXPECT_LT(st.low_p, 0.4);
}

TEST(Periodogram, TorusHexLatticePeaksAtReciprocalLattice) {
  // Lattice basis a1 = (1/c, 0), a2 = (1/(2c), 1/r): S(k) = n where k·a1, k·a2 ∈ ℤ, i.e. k = (c·p, r·(q −
  // p/2)), and S(k) = 0 elsewhere; so P = n on the reciprocal lattice and 0 off it.
  const int c = 26, r = 30;
  const tools::PointSet s = torus_hex_lattice(c, r);
  const double n = static_cast<double>(s.size());
  const Periodogram p = periodogram(s.coords, 2, 2.5);
  int peaks = 0;
  for (int ky = -p.kmax; ky <= p.kmax; ++ky)
    for (int kx = -p.kmax; kx <= p.kmax; ++kx) {
      if ((kx == 0 && ky == 0) || kx * kx + ky * ky > p.kmax * p.kmax) continue;
      const bool on = kx % c == 0 && (2 * ky + r * (kx / c)) % (2 * r) == 0;
      if (on) {
        ++peaks;
        ASSERT_NEAR(p.at(kx, ky), n, 1e-4 * n) << kx << "," << ky;
      } else {
        ASSERT_LT(p.at(kx, ky), 1e-6) << kx << "," << ky;
      }
    }
  EXPECT_GT(peaks, 6);
  const SpectrumStats st = spectrum_stats(p);
  // First reciprocal shell: (0, ±30) and (±26, ±15) → |k| = 30 and 30.02, ring 30.
  EXPECT_NEAR(st.peak_f, 30.0 / std::sqrt(n), 1e-12);
  EXPECT_NEAR(st.nu_eff, 29.0 / std::sqrt(n), 1e-12);  // every ring below 30 is exactly 0
  EXPECT_NEAR(st.low_p, 0.0, 1e-6);
  // All of ring 30's power lies on its six lattice frequencies: var/mean² = K/6 − 1 of its K (about 190)
  // bins, some 15 dB, where an isotropic set's one ring reads about 0 dB.
  const double ring30 = st.ring_anisotropy_db[29];
  EXPECT_NEAR(ring30, 10 * std::log10(st.ring_size[29] / 6.0 - 1), 0.1);
  EXPECT_GT(ring30, 10);
}

// raps.png's value labels stay apart at any peak: at a peak of 100 (a lattice) a fixed step of 2 stacked
// 56 labels into a black column beside the axis: ink in all 374 rows of the label column.
TEST(Periodogram, RapsLabelsStayApartAtAnyPeak) {
  for (const double peak : {1.5, 12.0, 100.0, 3000.0}) {
    SpectrumStats st;
    for (int r = 1; r <= 50; ++r) st.ring_f.push_back(r / 20.0), st.raps.push_back(r == 25 ? peak : 1.0);
    const tools::RgbImage im = plot_raps(st, 2.5);
    int inked = 0, rows = 0;
    for (int y = 56; y < im.height - 70; ++y, ++rows)  // the plot's height; labels end 10 px left of it
      for (int x = 0; x < 70; ++x)
        if (im.pixels[(static_cast<std::size_t>(y) * im.width + x) * 3] < 128) {
          ++inked;
          break;
        }
    EXPECT_GT(inked, 0) << peak;
    EXPECT_LT(inked, rows / 2) << "peak " << peak << ": " << inked << " of " << rows << " rows";
  }
}

TEST(Periodogram, RejectsBadInput) {
  EXPECT_THROW(periodogram({}, 2, 1.0), InvalidInput);
  EXPECT_THROW(periodogram({0.1, 0.2, 0.3}, 3, 1.0), InvalidInput);
  EXPECT_THROW(periodogram({0.1, 0.2}, 2, 0.0), InvalidInput);
  EXPECT_THROW(periodogram({0.1, 1.2}, 2, 1.0), InvalidInput);
  EXPECT_THROW(average_periodogram({}, 1.0), InvalidInput);
  // Sets pooled on one frequency axis must be of about one size: 11 and 10 points pool, 12 and 10 not.
  const auto grid = [](int n) {
    tools::PointSet s;
    s.dim = 2;
    for (int i = 0; i < n; ++i) s.coords.insert(s.coords.end(), {(i + 0.5) / n, std::fmod(0.618 * i, 1.0)});
    return s;
  };
  EXPECT_NO_THROW(average_periodogram({grid(11), grid(10)}, 1.0));
  EXPECT_THROW(average_periodogram({grid(12), grid(10)}, 1.0), InvalidInput);
  // Too fine a grid, not an overflow.
  EXPECT_THROW(periodogram({0.1, 0.2, 0.5, 0.5}, 2, 1e300), InvalidInput);
}

}  // namespace
}  // namespace kdm::analysis
