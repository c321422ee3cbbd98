// Parts 3 and 4 of the generator test (verify.h): seams and in-between densities. A seam defect shortens
// links, so edge links are tested against midline links, one-sided, over the short half and counting each
// distinct link once; why each, and the bars: docs/design.md §5.
#include <algorithm>
#include <cmath>
#include <limits>

#include "kdm/analysis/common.h"
#include "kdm/analysis/nearest_neighbour.h"
#include "kdm/analysis/periodogram.h"
#include "kdm/analysis/tiling.h"
#include "kdm/runtime/check.h"
#include "kdm/verify/verify.h"
#include "tile_torus.h"

namespace kdm::verify {
namespace {

/// The distinct values of `lengths`, sorted: equal up to rounding (a patch's links at other tile offsets
/// differ in the last bits) counts as the same link.
std::vector<double> distinct(std::vector<double> lengths) {
  std::sort(lengths.begin(), lengths.end());
  std::vector<double> out;
  for (double v : lengths)
    if (out.empty() || v - out.back() > 1e-9 * v) out.push_back(v);
  return out;
}

}  // namespace

double worst_edge_ratio(const std::vector<double>& edge_min, const std::vector<double>& other_min) {
  KDM_CHECK(edge_min.size() == other_min.size());
  if (other_min.empty()) return std::numeric_limits<double>::infinity();
  // No stricter than a typical tile's: a tile whose interior happens to hold no close pair would otherwise
  // fail on an edge pair that passes in every other tile showing it (docs/design.md §5).
  std::vector<double> sorted = other_min;
  std::sort(sorted.begin(), sorted.end());
  const double typical = sorted[(sorted.size() - 1) / 2];
  double worst = std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t < edge_min.size(); ++t)
    worst = std::min(worst, edge_min[t] / std::min(other_min[t], typical));
  return worst;
}

void judge_densities(const TilesetData& set, const VerifyOptions& options, Report& report,
                     const std::function<void(double)>& done) {
  const Bars& b = options.bars;
  for (double count : densities(set, options.levels)) {
    DensityResult row;
    row.points_per_tile = count;
    row.complete_level =
        std::find(set.level_nominal.begin(), set.level_nominal.end(), count) != set.level_nominal.end();
    row.worst_low_p = std::numeric_limits<double>::quiet_NaN();
    std::vector<double> edge_pool, midline_pool;
    std::vector<double> edge_min, other_min;  // per tile, where it has both
    const double spacing = analysis::hex_spacing(std::size_t(count));
    row.closest_pair = closest_across_edges(set, stable_positions(set, count), spacing) / spacing;
    analysis::EdgeBands bands;
    TorusHoles holes;
    for (std::size_t t = 0; t < set.tiles.size(); ++t) {
      const std::vector<double> coords = torus_points(set, t, count);
      const std::size_t n = coords.size() / 2;
      done(double(n));
      if (n < 2) continue;
      analysis::NearestNeighbours nn;
      add_torus_nn(coords, set.tiles.size(), options.threads, nn, row);
      if (row.complete_level && options.holes) holes.add(coords);
      analysis::add_edge_bands(coords, 2, 0.5, bands);
      std::vector<double> edge, inside;
      analysis::split_by_seam(coords, 2, nn, 0.5, edge, inside);
      if (!edge.empty() && !inside.empty()) {
        edge_min.push_back(*std::min_element(edge.begin(), edge.end()));
        other_min.push_back(*std::min_element(inside.begin(), inside.end()));
      }
      // The same links split by the lines halfway between tile edges: shift by a quarter of the torus.
      std::vector<double> shifted = coords;
      for (double& u : shifted) u = std::fmod(u + 0.25, 1.0);
      std::vector<double> midline, rest;
      analysis::split_by_seam(shifted, 2, nn, 0.5, midline, rest);
      edge_pool.insert(edge_pool.end(), edge.begin(), edge.end());
      midline_pool.insert(midline_pool.end(), midline.begin(), midline.end());
      if (row.complete_level || n < b.mid_low_p_min_points || n > options.spectrum_budget) continue;
      const double low_p =
          analysis::spectrum_stats(analysis::periodogram(coords, 2, 0.6, options.threads)).low_p;
      row.worst_low_p = std::isnan(row.worst_low_p) ? low_p : std::max(row.worst_low_p, low_p);
    }
    row.worst_edge_ratio = worst_edge_ratio(edge_min, other_min);
    holes.measure(options.threads, row.holes);
    // Distinct links only, and the short half only: above the midline median the gap measures the shape
    // of the body, not short links (docs/design.md §5).
    edge_pool = distinct(std::move(edge_pool)), midline_pool = distinct(std::move(midline_pool));
    const double median = midline_pool.empty() ? std::numeric_limits<double>::infinity()
                                               : midline_pool[midline_pool.size() / 2];
    const analysis::KsResult ks = analysis::ks_smaller(edge_pool, midline_pool, median);
    row.edge_links = edge_pool.size(), row.midline_links = midline_pool.size();
    row.ks_d_plus = ks.statistic, row.ks_p = ks.p_value;
    if (std::isfinite(row.worst_edge_ratio))
      row.checks.push_back({"edge δmin / other δmin", row.worst_edge_ratio, b.edge_dmin, false});
    // The excess counts only where it is significant.
    row.checks.push_back(
        {"edge vs midline KS D+ (significant)", ks.p_value < b.ks_p ? ks.statistic : 0.0, b.ks_d_plus, true});
    if (!std::isnan(row.worst_low_p)) row.checks.push_back({"lowP", row.worst_low_p, b.mid_low_p, true});
    if (std::isfinite(row.closest_pair) && b.closest_pair > 0)
      row.checks.push_back({"closest pair / d_hex", row.closest_pair, b.closest_pair, false});
    row.edge_band = bands.first_spacing_ratio();
    if (b.edge_band > 0)
      row.checks.push_back({"|edge band density − 1|", std::fabs(row.edge_band - 1), b.edge_band, true});
    check_holes(row.holes, b, row.checks);
    report.densities.push_back(std::move(row));
  }
}

}  // namespace kdm::verify
