// A runtime query run to completion into a growing array, with refusals as one-line messages: what
// `kdm query`, `kdm stipple` and the Python package share.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "kdm/runtime/class_query.h"
#include "kdm/runtime/compact_query.h"
#include "kdm/runtime/query.h"
#include "point_io.h"

namespace kdm::tools {

/// Most points one such query collects (2^25, 1 GiB as QueryPoint) before it gives up.
inline constexpr std::size_t kMaxCollectedPoints = std::size_t(1) << 25;

/// A refused query's problem in one line (describe_query_problem's).
std::string describe(const QueryProblem& problem, const QueryParameterNames& names = {});

/// tile_size_advice's warning in one line without a prefix, "" where the tile size serves the density
/// evenly; `tile_size` names the option ("--tile-size", "tile_size").
std::string tile_size_warning(const TileSizeAdvice& advice, const char* tile_size);

/// Fewest points per tile a class after the first should expect, where the classes before it fill the
/// coarsest level: a later class gets what the running sums' one-class counts leave, and those are off by
/// up to about 2 points per tile where the densities are constant (docs/limits.md, "Several classes").
inline constexpr double kFewestForALaterClass = 16;

/// The warnings, each one line without a prefix, for the classes the tiles serve unevenly: class 0
/// (of several) under the coarsest level of `tileset` at its peak (its points then repeat with the
/// tiles), or a later class expecting fewer than kFewestForALaterClass points per tile at its peak while
/// the classes before it reach the coarsest level (the first such); none where they are served evenly.
/// `peaks` are the classes' largest densities, class 0 first; `tile_size` names the option.
std::vector<std::string> class_count_warnings(const Tileset& tileset, const std::vector<double>& peaks,
                                              double scale, double tile_size, const char* tile_size_name);

/// A lower bound of how many points a query of `params` emits: its density times scale over its region
/// (exact for a constant; an image's min-mip over 64 × 64 blocks of the region, 0 where its maximum could
/// not reach half of kMaxCollectedPoints), summed over the classes; NaN where nothing is known without
/// querying (a callback, a joint class density) or where the query refuses its density (past
/// query_density_limit: its refusal says what fits).
double points_at_least(const Tileset& tileset, const QueryParams& params);
double points_at_least(const Tileset& tileset, const ClassQueryParams& params);

/// Refuses before any point is collected what collecting would refuse only later: parameters the query
/// refuses (std::invalid_argument with describe()'s line), then a count (points_at_least) clearly past
/// kMaxCollectedPoints (std::length_error), so that such a query fails at once, not after seconds.
void check_before_collecting(const Tileset& tileset, const QueryParams& params,
                             const QueryParameterNames& names = {});
void check_before_collecting(const Tileset& tileset, const ClassQueryParams& params,
                             const QueryParameterNames& names = {});

/// Runs a query to completion into `out` (replaced). Throws std::invalid_argument with describe()'s line
/// on bad parameters, std::length_error when more than kMaxCollectedPoints points would be emitted (before
/// querying where check_before_collecting can tell).
void query_all(const Tileset& tileset, const QueryParams& params, std::vector<QueryPoint>& out,
               const QueryParameterNames& names = {});
/// The same into the compact output (compact_query.h): positions only, `xy` (replaced) holding x, y
/// pairs relative to the query origin, as fast as the runtime writes them; with `keys`, each point's
/// point_key too (replaced; the set's tiles must hold at most 2^19 points: keys_fit).
void query_all_xy(const Tileset& tileset, const QueryParams& params, std::vector<float>& xy,
                  std::vector<std::uint64_t>* keys = nullptr, const QueryParameterNames& names = {});
/// The same for several classes: `classes` (replaced) receives each point's class.
void query_all(const Tileset& tileset, const ClassQueryParams& params, std::vector<QueryPoint>& out,
               std::vector<std::uint8_t>& classes, const QueryParameterNames& names = {});
/// The same into the compact output: x, y pairs and each point's class (and key, with `keys`).
void query_all_xy(const Tileset& tileset, const ClassQueryParams& params, std::vector<float>& xy,
                  std::vector<std::uint8_t>& classes, std::vector<std::uint64_t>* keys = nullptr,
                  const QueryParameterNames& names = {});

/// Whether the compact output can key `tileset`'s points (its tiles hold at most 2^19 points).
bool keys_fit(const Tileset& tileset);

/// Query points whose origin is the corner (r[0], r[1]) of the world rectangle r (x0, y0, x1, y1), as a 2D
/// point set normalised to it: [0, 1) on both axes.
PointSet normalise_to_rect(const std::vector<QueryPoint>& points, const double r[4]);
/// The same for x, y pairs (query_all_xy's).
PointSet normalise_to_rect(const std::vector<float>& xy, const double r[4]);

}  // namespace kdm::tools
