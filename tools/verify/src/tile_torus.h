// Shared pieces of the generator test: the 2×2 torus around a tile, and freeing points among fixed ones.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "kdm/analysis/common.h"
#include "kdm/analysis/empty_circles.h"
#include "kdm/analysis/nearest_neighbour.h"
#include "kdm/generator/sampler.h"
#include "kdm/runtime/tileset_format.h"
#include "kdm/verify/verify.h"

namespace kdm::verify {

/// The points the 2×2 torus around tile `t` emits at expected count `count` per tile, normalised to the
/// unit square; `own` (optional) receives tile (0, 0)'s points separately and `others` the rest.
std::vector<double> torus_points(const TilesetData& set, std::size_t t, double count,
                                 std::vector<double>* own = nullptr, std::vector<double>* others = nullptr);

/// The seam check's ratio (Bars::edge_dmin): the smallest over tiles of the tile's edge-link δmin over its
/// other links' δmin, or over the median tile's if that is less. Inputs are per tile, in one order.
/// Returns infinity for no tiles.
double worst_edge_ratio(const std::vector<double>& edge_min, const std::vector<double>& other_min);

/// Each tile's points at one density, in its own unit coordinates (a glided point may lie outside the
/// tile): the first n ranks, as (x, y) pairs, then any points without a rank (a hand-over's appearing
/// points), which lie where they are stored.
using TilePositions = std::vector<std::vector<double>>;

/// Every tile's points at expected count `count` per tile in stable mode.
TilePositions stable_positions(const TilesetData& set, double count);

/// The smallest distance (tile sides) between a point of one tile and a point of a tile that can meet it
/// across an edge: every tile against each of the C² tiles that can lie right of it and above it. The
/// tiles' tori hold one such neighbour per edge, so a pair that only some neighbours bring together is
/// found here alone. Pairs farther apart than `cutoff` are not looked for (the result is then `cutoff`).
double closest_across_edges(const TilesetData& set, const TilePositions& at, double cutoff);

/// The full sampler's options for a side × side torus (in tiles) at user temperature `temperature`.
gen::SamplerOptions torus_options(double temperature, double side, int threads);

struct Relaxed {
  double drop = 0;   ///< 1 − E_after / E_before
  double drift = 0;  ///< mean displacement of the freed points / point spacing
};

/// Frees `own` among the fixed `others` on a side × side torus (normalised coordinates) and runs 15 MH
/// sweeps of the full sampler at user temperature `temperature`. `spacing` normalises the drift.
Relaxed relax(const std::vector<double>& own, const std::vector<double>& others, double side,
              double temperature, double spacing, std::uint64_t seed, int threads);

/// Nearest neighbours of a tile's torus (`coords`, normalised, at least 2 points) into `nn`, and their
/// summary in d_hex of its point count; adds the summary's δavg / `tiles` and δmin to `row`'s davg and
/// closest_pair (a DensityResult or KeyframeResult).
template <class Row>
analysis::NNStats add_torus_nn(const std::vector<double>& coords, std::size_t tiles, int threads,
                               analysis::NearestNeighbours& nn, Row& row) {
  nn = analysis::nearest_neighbours(coords, 2, true, threads);
  const analysis::NNStats summary =
      analysis::summarise_nn(nn.distance, analysis::hex_spacing(coords.size() / 2));
  row.davg += summary.davg / double(tiles);
  row.closest_pair = std::min(row.closest_pair, summary.dmin);
  return summary;
}

/// The tiles' tori of one density, gathered so that their empty circles are measured at once.
class TorusHoles {
 public:
  /// Adds a tile's torus (`coords`, normalised); one of fewer than 3 points has no triangles.
  void add(const std::vector<double>& coords);
  /// Adds the empty circles of every torus added to `holes` (in parallel on `threads`; the result does
  /// not depend on it).
  void measure(int threads, Holes& holes) const;

 private:
  std::vector<tools::PointSet> tori_;
};

/// Appends the hole checks of `bars` (those not off) for `holes` to `checks`.
void check_holes(const Holes& holes, const Bars& bars, std::vector<Check>& checks);

/// The expected counts per tile judged for `levels`: each complete level and the quarters below it.
std::vector<double> densities(const TilesetData& set, const std::vector<std::uint32_t>& levels);

/// Parts 3 and 4 of the generator test (seams.cpp): appends a DensityResult per density to `report`;
/// `done` receives the points measured.
void judge_densities(const TilesetData& set, const VerifyOptions& options, Report& report,
                     const std::function<void(double)>& done);

/// Whether keyframe g (and the density half-way to the next) lies in one of `levels`: level k holds the
/// counts (N_{k-1}, N_k], the last level every count above too.
bool keyframe_judged(const TilesetData& set, const std::vector<std::uint32_t>& levels, std::size_t g);

/// Part 5 (glide.cpp): appends a KeyframeResult per keyframe of the judged levels, and the density
/// half-way to the next, to `report`.
void judge_keyframes(const TilesetData& set, const VerifyOptions& options, Report& report,
                     const std::function<void(double)>& done);

/// Part 6 (glide.cpp), sets with a hand-over: appends a KeyframeResult (handover set) for each of
/// VerifyOptions::handover_rows even steps from the top keyframe to where 99% of the glides have arrived
/// and every appearing point has appeared, as the runtime places them (a constant density): each point on its
/// straight path onto its sub-point (which glides with its subtile's count once that passes K_h, the
/// hand-over keyframe's count) by the end its glide sets, the appearing points in at evenly spread
/// thresholds, the subtiles' own points by theirs; the last with the glides' motion per top keyframe interval
/// of the scale they span.
void judge_handover(const TilesetData& set, const VerifyOptions& options, Report& report,
                    const std::function<void(double)>& done);

}  // namespace kdm::verify
