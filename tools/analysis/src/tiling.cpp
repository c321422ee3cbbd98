// Tiling diagnostics: periodicity ratio at tile-lattice frequencies, seam vs interior nearest-neighbour
// statistics and the two-sample Kolmogorov–Smirnov test (asymptotic distribution
// Q(λ) = 2 Σ_{k≥1} (−1)^{k−1} exp(−2k²λ²), λ = (√m + 0.12 + 0.11/√m)·D, m = n_a n_b/(n_a + n_b)).
#include "kdm/analysis/tiling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "kdm/analysis/common.h"

namespace kdm::analysis {

int tiles_per_axis(double tile_size) {
  if (!(tile_size > 0) || tile_size > 1) throw InvalidInput("tile size must be in (0, 1]");
  const double t = 1.0 / tile_size;
  const long ti = std::lround(t);
  if (std::abs(t - static_cast<double>(ti)) > 1e-6 * t || ti < 1 || ti > 1 << 20)
    throw InvalidInput("1 / tile size must be an integer");
  return static_cast<int>(ti);
}

PeriodicityResult periodicity_ratio(const Periodogram& p, const SpectrumStats& stats, double tile_size) {
  const int t = tiles_per_axis(tile_size);
  if (p.lx != 1 || p.ly != 1)
    throw InvalidInput("tiling diagnostics take square tiles of the unit square, not a rectangle's spectrum");
  PeriodicityResult out;
  double power = 0, raps = 0;
  const int rmax = static_cast<int>(stats.raps.size());
  for (int ky = -(p.kmax / t) * t; ky <= p.kmax; ky += t)
    for (int kx = -(p.kmax / t) * t; kx <= p.kmax; kx += t) {
      if (kx == 0 && ky == 0) continue;
      const double kn = std::hypot(kx, ky);
      if (std::lround(kn) > rmax) continue;
      power += p.at(kx, ky);
      raps += stats.raps_at(kn);
      ++out.frequencies;
    }
  if (out.frequencies == 0) {
    out.ratio = out.mean_power = out.mean_raps = out.lattice_ratio = std::numeric_limits<double>::quiet_NaN();
    return out;
  }
  out.mean_power = power / static_cast<double>(out.frequencies);
  out.mean_raps = raps / static_cast<double>(out.frequencies);
  out.ratio = out.mean_power / out.mean_raps;
  // Whole cycles per tile against their neighbours: the local level of the spectrum, whatever its shape.
  double on = 0, off = 0;
  int on_count = 0, off_count = 0;
  for (int j = -2; j <= 2; ++j)
    for (int i = -2; i <= 2; ++i) {
      if (i == 0 && j == 0) continue;
      const int kx = i * t, ky = j * t;
      if (std::hypot(std::abs(kx) + 1, std::abs(ky) + 1) > p.kmax) continue;  // neighbours inside the disc
      on += p.at(kx, ky), ++on_count;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          if (dx || dy) off += p.at(kx + dx, ky + dy), ++off_count;
    }
  out.lattice_frequencies = static_cast<std::size_t>(on_count);
  if (on_count == 0)
    out.lattice_ratio = std::nan("");
  else  // a strictly periodic set has no power off the lattice, bar the transform's rounding (1e-10 of S)
    out.lattice_ratio =
        off / off_count > 1e-9 * (on / on_count) ? (on / on_count) / (off / off_count) : HUGE_VAL;
  return out;
}

namespace {

/// Sorts both samples and walks their empirical CDFs: returns {sup (F_a − F_b), sup |F_a − F_b|}, both over
/// values below `up_to`.
std::pair<double, double> ecdf_gaps(std::vector<double>& a, std::vector<double>& b,
                                    double up_to = std::numeric_limits<double>::infinity()) {
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  const double na = static_cast<double>(a.size()), nb = static_cast<double>(b.size());
  std::size_t i = 0, j = 0;
  double above = 0, both = 0;
  while (i < a.size() && j < b.size()) {
    const double v = std::min(a[i], b[j]);
    if (v >= up_to) break;
    while (i < a.size() && a[i] <= v) ++i;  // step past ties in both samples together
    while (j < b.size() && b[j] <= v) ++j;
    const double d = static_cast<double>(i) / na - static_cast<double>(j) / nb;
    above = std::max(above, d), both = std::max(both, std::abs(d));
  }
  return {above, both};
}

}  // namespace

KsResult ks_two_sample(std::vector<double> a, std::vector<double> b) {
  KsResult r;
  if (a.empty() || b.empty()) return r;
  const double na = static_cast<double>(a.size()), nb = static_cast<double>(b.size());
  const double d = ecdf_gaps(a, b).second;
  r.statistic = d;
  const double m = std::sqrt(na * nb / (na + nb));
  const double lambda = (m + 0.12 + 0.11 / m) * d;
  if (lambda < 0.2) return r;  // Q(λ) = 1 to double precision for small λ (series converges slowly there)
  double q = 0, sign = 1;
  for (int k = 1; k <= 200; ++k) {
    const double term = sign * std::exp(-2.0 * k * k * lambda * lambda);
    q += term;
    if (std::abs(term) < 1e-16) break;
    sign = -sign;
  }
  r.p_value = std::clamp(2.0 * q, 0.0, 1.0);
  return r;
}

KsResult ks_smaller(std::vector<double> a, std::vector<double> b, double up_to) {
  KsResult r;
  if (a.empty() || b.empty()) return r;
  const double na = static_cast<double>(a.size()), nb = static_cast<double>(b.size());
  r.statistic = ecdf_gaps(a, b, up_to).first;
  r.p_value = std::min(1.0, std::exp(-2.0 * na * nb / (na + nb) * r.statistic * r.statistic));
  return r;
}

void split_by_seam(const std::vector<double>& coords, int dim, const NearestNeighbours& nn, double tile_size,
                   std::vector<double>& seam, std::vector<double>& interior) {
  const int t = tiles_per_axis(tile_size);
  const std::size_t n = coords.size() / dim;
  const double spacing = reference_spacing(dim, n);
  for (std::size_t i = 0; i < n; ++i) {
    bool crosses = false;
    for (int a = 0; a < dim; ++a) {
      const double x = coords[i * dim + a];
      // Tile index of both ends of the link, the far end unwrapped (floor < 0 or ≥ t means it left the
      // domain through its edge, which is a tile edge too).
      const double far = x + nn.offset[i * dim + a];
      const double ix = std::min(t - 1.0, std::floor(x * t));
      double ifar = std::floor(far * t);
      if (far <= 1.0) ifar = std::min(t - 1.0, ifar);
      if (ix != ifar) crosses = true;
    }
    (crosses ? seam : interior).push_back(nn.distance[i] / spacing);
  }
}

SeamStats seam_stats(const std::vector<tools::PointSet>& sets, bool torus, double tile_size, int threads) {
  tiles_per_axis(tile_size);
  std::vector<double> seam, interior;
  for (const tools::PointSet& s : sets) {
    const NearestNeighbours nn = nearest_neighbours(s.coords, s.dim, torus, threads);
    split_by_seam(s.coords, s.dim, nn, tile_size, seam, interior);
  }
  SeamStats out;
  out.seam = summarise_nn(seam, 1.0);
  out.interior = summarise_nn(interior, 1.0);
  out.ks = ks_two_sample(seam, interior);
  return out;
}

void add_edge_bands(const std::vector<double>& coords, int dim, double tile_size, EdgeBands& bands) {
  if (dim != 2) throw InvalidInput("edge bands are implemented for 2D sets only");
  const int tiles = tiles_per_axis(tile_size);
  const std::size_t n = coords.size() / 2;
  if (n == 0) return;
  const double s = 1.0 / tiles, step = std::sqrt(2 / (std::sqrt(3.0) * double(n))) / 4;  // d_hex / 4
  for (int b = 0; b < EdgeBands::kBands; ++b) {
    // Area of a tile at distance [a, c) from its nearest edge: (s − 2a)² − (s − 2c)², clipped at the centre.
    const double a = std::min(b * step, s / 2), c = std::min((b + 1) * step, s / 2);
    bands.expected[b] += double(n) * ((s - 2 * a) * (s - 2 * a) - (s - 2 * c) * (s - 2 * c)) / (s * s);
  }
  for (std::size_t i = 0; i < n; ++i) {
    double d = s;
    for (int k = 0; k < 2; ++k) {
      const double u = coords[2 * i + k] * tiles;
      const double f = (u - std::floor(u)) * s;  // position inside its tile
      d = std::min(d, std::min(f, s - f));
    }
    const int b = static_cast<int>(d / step);
    if (b < EdgeBands::kBands) bands.count[b] += 1;
  }
}

}  // namespace kdm::analysis
