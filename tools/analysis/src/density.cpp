// Density accuracy: window counts against expected counts of a target density. The density is sampled at
// raster-cell midpoints (piecewise-constant model), a summed-area table gives window masses, and windows
// come from recursive equal-mass splits along the longer side, kept only while both halves still expect
// ≥ min_expected points. z = (count − μ)/√μ per window (Poisson scaling; binomial variance μ(1 − μ/n) ≈ μ).
#include "kdm/analysis/density.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "kdm/analysis/common.h"

namespace kdm::analysis {
namespace {

struct Window {
  int x0, y0, x1, y1;  // raster cells [x0, x1) × [y0, y1)
};

struct Sat {
  int r;                  // raster cells along x
  std::vector<double> s;  // (ry+1)(r+1) prefix sums
  double mass(int x0, int y0, int x1, int y1) const {
    auto at = [&](int x, int y) { return s[static_cast<std::size_t>(y) * (r + 1) + x]; };
    return at(x1, y1) - at(x0, y1) - at(x1, y0) + at(x0, y0);
  }
};

void split(const Sat& sat, const Window& w, double scale, double min_expected, std::vector<Window>& out) {
  const double mass = sat.mass(w.x0, w.y0, w.x1, w.y1) * scale;
  const bool along_x = (w.x1 - w.x0) >= (w.y1 - w.y0);
  const int lo = along_x ? w.x0 : w.y0, hi = along_x ? w.x1 : w.y1;
  if (hi - lo >= 2 && mass >= 2 * min_expected) {
    int best = -1;
    double best_gap = 0;
    for (int c = lo + 1; c < hi; ++c) {  // window sides are short: a linear scan is cheap
      const double left = (along_x ? sat.mass(w.x0, w.y0, c, w.y1) : sat.mass(w.x0, w.y0, w.x1, c)) * scale;
      const double gap = std::abs(left - 0.5 * mass);
      if (left >= min_expected && mass - left >= min_expected && (best < 0 || gap < best_gap)) {
        best = c;
        best_gap = gap;
      }
    }
    if (best >= 0) {
      Window a = w, b = w;
      if (along_x)
        a.x1 = b.x0 = best;
      else
        a.y1 = b.y0 = best;
      split(sat, a, scale, min_expected, out);
      split(sat, b, scale, min_expected, out);
      return;
    }
  }
  out.push_back(w);
}

}  // namespace

DensityAccuracy density_accuracy(const std::vector<double>& coords, int dim, const DensityFunction& density,
                                 const DensityOptions& options) {
  if (dim != 2) throw InvalidInput("density accuracy is implemented for 2D sets only");
  validate_points(coords, dim);
  if (!density) throw InvalidInput("no target density given");
  if (!(options.min_expected > 0)) throw InvalidInput("min_expected must be positive");
  if (options.bands < 1) throw InvalidInput("density bands must be at least 1");
  const std::size_t n = coords.size() / 2;
  const double total = options.expected_total > 0 ? options.expected_total : static_cast<double>(n);
  int r = options.raster;
  if (r <= 0) {
    const double side = std::sqrt(options.min_expected / std::max(1.0, total));
    r = std::clamp(static_cast<int>(std::ceil(8.0 / side)), 256, 4096);
  }
  // A rectangle's raster has cells square in its lengths (r along a unit side), so windows split along
  // its longer sides are about square there too.
  const double lx = options.sides[0], ly = options.sides[1];
  if (!(lx > 0 && ly > 0 && std::isfinite(lx) && std::isfinite(ly)))
    throw InvalidInput("the domain's sides must be positive finite numbers");
  const int rx = lx == 1 ? r : std::clamp(static_cast<int>(std::lround(r * lx)), 1, 1 << 16);
  const int ry = ly == 1 ? r : std::clamp(static_cast<int>(std::lround(r * ly)), 1, 1 << 16);
  Sat sat{rx, std::vector<double>(static_cast<std::size_t>(rx + 1) * (ry + 1), 0.0)};
  // Each cell's value as the density gave it: from the table's differences a zero cell came out as
  // rounding residue (7e-15 of the peak), which set the bands' log range.
  std::vector<double> cell_rho(static_cast<std::size_t>(rx) * ry);
  for (int y = 0; y < ry; ++y)
    for (int x = 0; x < rx; ++x) {
      const double v = density((x + 0.5) / rx, (y + 0.5) / ry);
      if (!std::isfinite(v) || v < 0) throw InvalidInput("target density is negative or not finite");
      cell_rho[static_cast<std::size_t>(y) * rx + x] = v;
      const std::size_t i = static_cast<std::size_t>(y + 1) * (rx + 1) + (x + 1);
      sat.s[i] = v + sat.s[i - 1] + sat.s[i - (rx + 1)] - sat.s[i - (rx + 1) - 1];
    }
  const double integral = sat.mass(0, 0, rx, ry);
  if (!(integral > 0)) throw InvalidInput("target density is zero everywhere");
  const double scale = total / integral;  // raster mass → expected count
  double rho_min = std::numeric_limits<double>::infinity(), rho_max = 0;
  for (double v : cell_rho)
    if (v > 0) rho_min = std::min(rho_min, v), rho_max = std::max(rho_max, v);
  const int band_count = rho_max > rho_min * 1.01 ? options.bands : 1;
  const double log_span = std::log(rho_max / rho_min);
  auto band_of = [&](double v) {  // v > 0
    const int b = static_cast<int>(std::floor(std::log(v / rho_min) / log_span * band_count));
    return std::clamp(b, 0, band_count - 1);
  };
  std::vector<int> cell_band(cell_rho.size(), -1);
  DensityAccuracy out;
  out.bands.resize(static_cast<std::size_t>(band_count));
  for (int b = 0; b < band_count; ++b) {
    DensityBand& band = out.bands[static_cast<std::size_t>(b)];
    band.lo = band_count == 1 ? rho_min / rho_max : std::exp(log_span * (double(b) / band_count - 1));
    band.hi = band_count == 1 ? 1.0 : std::exp(log_span * (double(b + 1) / band_count - 1));
  }
  for (std::size_t i = 0; i < cell_rho.size(); ++i)
    if (cell_rho[i] > 0) {
      cell_band[i] = band_of(cell_rho[i]);
      out.bands[static_cast<std::size_t>(cell_band[i])].expected += cell_rho[i] * scale;
    }
  std::vector<Window> windows;
  split(sat, Window{0, 0, rx, ry}, scale, options.min_expected, windows);
  std::vector<int> label(static_cast<std::size_t>(rx) * ry, 0);
  for (std::size_t k = 0; k < windows.size(); ++k)
    for (int y = windows[k].y0; y < windows[k].y1; ++y)
      for (int x = windows[k].x0; x < windows[k].x1; ++x)
        label[static_cast<std::size_t>(y) * rx + x] = int(k);
  std::vector<double> counts(windows.size(), 0.0);
  out.points = n;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = coords[2 * i], y = coords[2 * i + 1];
    const int cx = std::min(rx - 1, static_cast<int>(x * rx)),
              cy = std::min(ry - 1, static_cast<int>(y * ry));
    if (density(x, y) == 0) {  // counted apart: such points are misplaced, not part of any window's count
      ++out.zero_density;
      continue;
    }
    const std::size_t cell = static_cast<std::size_t>(cy) * rx + cx;
    counts[label[cell]] += 1;
    if (cell_band[cell] >= 0) out.bands[static_cast<std::size_t>(cell_band[cell])].count += 1;
  }
  double sum_z2 = 0, sum_count = 0, sum_mu = 0;
  for (std::size_t k = 0; k < windows.size(); ++k) {
    const Window& w = windows[k];
    const double mu = sat.mass(w.x0, w.y0, w.x1, w.y1) * scale;
    if (!(mu > 0)) continue;
    const double z = (counts[k] - mu) / std::sqrt(mu);
    sum_z2 += z * z;
    out.max_abs_z = std::max(out.max_abs_z, std::abs(z));
    sum_count += counts[k];
    sum_mu += mu;
    ++out.windows;
  }
  if (out.windows) {
    out.rms_z = std::sqrt(sum_z2 / static_cast<double>(out.windows));
    out.mean_expected = sum_mu / static_cast<double>(out.windows);
    out.bias = (sum_count - sum_mu) / sum_mu;
  }
  return out;
}

std::pair<double, double> density_scale(const DensityFunction& rho) {
  constexpr int kGrid = 256;
  double sum = 0, largest = 0;
  for (int j = 0; j < kGrid; ++j)
    for (int i = 0; i < kGrid; ++i) {
      const double v = std::max(0.0, rho((i + 0.5) / kGrid, (j + 0.5) / kGrid));
      sum += v, largest = std::max(largest, v);
    }
  return {sum / (kGrid * kGrid), largest};
}

}  // namespace kdm::analysis
