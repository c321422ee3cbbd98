// Parts 3 and 4 of the generator test (verify.h): seams and in-between densities.
//
// Seams. For each density, over the tori of all tiles: (a) every tile's edge links (NN links crossing a
// tile edge) have δmin ≥ 0.9 × the δmin of its other links; (b) the pooled NN distances of edge links are
// not shorter than those of links crossing the lines halfway between tile edges (the same count of lines
// with the same geometry, so the comparison is neutral: longer links cross any line more often, which
// makes edge links look better than interior ones in a plain seam/interior split). A seam defect shortens
// links, so the comparison is one-sided: Kolmogorov–Smirnov D+ (analysis::ks_smaller), the largest excess
// of edge links over midline links shorter than any length below the midline links' median. Above it the
// excess says nothing about short links: a set has few distinct edge patches, so link lengths repeat and
// the CDFs step, and a set whose edge links are all near the median (edges more regular than midlines)
// showed D+ 0.14 there (4-level set with 1-spacing margins, 104 points per tile: no edge link shorter than
// 0.80 d, 26% of midline links shorter). A density fails when the excess is both
// significant (p < 0.001) and large (D+ > 0.1: a visible seam, a tenth of the edge links pushed short).
// Significance alone is no bar: with 10^4 links per density p falls below 0.001 already at D+ = 0.03, and
// the default set's top level measures D+ 0.035, p 7e-8, a small real excess of short edge links. Size alone
// is none either: a set of one tile has a few dozen edge links at its lowest level, where D+ 0.4 is chance (p
// 0.02). On the default set D+ is at most 0.096. A two-sided test would also flag edge links that are longer
// than midline links, no defect. Each distinct link counts once: a shared patch shows the same links in
// every torus that holds it (and a mutual nearest pair is one link seen from both ends), so the pools hold
// few distinct lengths many times over (a 4-level set at 224 points per tile: 40 distinct edge links in
// 5,142), and counting repeats as samples would make chance look significant.
//
// Between complete levels (what the runtime emits at in-between densities) the tiles stay blue at low
// frequencies: lowP ≤ 0.105 on every tile's torus once it holds ≥ 1792 points (fewer average too few
// frequencies for lowP to mean much). The target is 0.1; on the default set the worst of the 16 tiles
// × 9 densities measures 0.1002 (3/4 of the way from 512 to 2048 points per tile), the rest at most
// 0.0962.
#include <algorithm>
#include <cmath>
#include <limits>

#include "kdm/analysis/common.h"
#include "kdm/analysis/nearest_neighbor.h"
#include "kdm/analysis/periodogram.h"
#include "kdm/analysis/tiling.h"
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

void judge_densities(const TilesetData& set, const VerifyOptions& options, Report& report,
                     const std::function<void(double)>& done) {
  const Bars& b = options.bars;
  for (double count : densities(set, options.levels)) {
    DensityResult row;
    row.points_per_tile = count;
    row.complete_level =
        std::find(set.level_nominal.begin(), set.level_nominal.end(), count) != set.level_nominal.end();
    row.worst_low_p = std::numeric_limits<double>::quiet_NaN();
    row.worst_edge_ratio = std::numeric_limits<double>::infinity();
    std::vector<double> edge_pool, midline_pool;
    row.closest_pair = std::numeric_limits<double>::infinity();
    analysis::EdgeBands bands;
    for (std::size_t t = 0; t < set.tiles.size(); ++t) {
      const std::vector<double> coords = torus_points(set, t, count);
      const std::size_t n = coords.size() / 2;
      done(double(n));
      if (n < 2) continue;
      analysis::NearestNeighbors nn;
      add_torus_nn(coords, set.tiles.size(), options.threads, nn, row);
      analysis::add_edge_bands(coords, 2, 0.5, bands);
      std::vector<double> edge, inside;
      analysis::split_by_seam(coords, 2, nn, 0.5, edge, inside);
      if (!edge.empty() && !inside.empty())
        row.worst_edge_ratio =
            std::min(row.worst_edge_ratio, *std::min_element(edge.begin(), edge.end()) /
                                               *std::min_element(inside.begin(), inside.end()));
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
    // Distinct links only, and the short half only: above the midline median the gap measures the shape
    // of the body, not short links (see the file comment).
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
    report.densities.push_back(std::move(row));
  }
}

}  // namespace kdm::verify
