// Several classes of points in one query: trees, bushes and rocks, or the inks of a colour stipple, each
// with its own density and all of them keeping their distance from one another (multi-class blue noise,
// L.-Y. Wei, "Multi-class blue noise sampling", SIGGRAPH 2010, over the one-class query of query.h).
//
// The classes' densities ρ_0 … ρ_{K-1} are given in priority order. The query emits the points of a
// one-class query at their sum, and a point of threshold t (query.h) emitted at its stable position x
// takes the first class k whose cumulative expected count passes it: (ρ_0 + … + ρ_k)(x) · A · scale > t.
// So, in stable mode, class 0 is exactly the one-class query at ρ_0, classes 0 … k together exactly the
// one at ρ_0 + … + ρ_k, and all classes together exactly the one at the sum; each later class fills in
// around the earlier ones. In smooth mode every point glides on the track of the sum (so the union is
// exactly the smooth one-class query at the sum and no two points of any classes come closer than its
// points do); class 0 then holds the same ids as a one-class query at ρ_0, at the union's positions
// (but within a glide's reach of the region's sides, which each query's points cross by their own track).
// A point's class is settled at its stable position, so where a class's own density drops sharply
// to 0 (and the sum's does not) its points may show up to about a spacing inside the zero side; no point
// shows where the sum is 0. Objects that must keep out of an area exactly are placed in stable mode.
// Choose priorities largest objects first: class 0 is the best spread, a later class fills the gaps. But
// query rare objects (under about 32 points per tile) on their own with larger tiles: a later class gets
// what the counts at two running sums leave, which are off by up to about 2 points per tile where the
// densities are constant, and class 0 under the coarsest level stands at the same few places of every
// tile (docs/limits.md, "Several classes").
// Give a callback class its bounds (QueryDensity::bounds): the union's are their sum, and a tile's bounds
// settle most of its points' classes without reading any density. Classes whose densities come from one
// computation are best given by one function (ClassQueryParams::joint): the query then makes one call per
// candidate instead of one per class.
// A class given by a batch callback (QueryDensity::batch_callback), or every class by a joint batch function
// (JointClassDensity::batch_densities), is read as a one-class query reads a batch callback: up to
// kDensityBatch positions a call, the classes found from the same values.
//
// Zoom coherence: as densities rise a point keeps its id and can only move to an earlier class (its
// cumulative counts only grow), never to a later one. Past the top level (smooth mode, depth > 0), a
// point's class follows its own threshold in the subtile that holds it, so class counts hold there on
// average rather than exactly. Partitions, determinism and thread safety are those of query_points.
#pragma once

#include <cstddef>
#include <cstdint>

#include "kdm/runtime/compact_query.h"
#include "kdm/runtime/export.h"
#include "kdm/runtime/query.h"
#include "kdm/runtime/status.h"
#include "kdm/runtime/tileset.h"

namespace kdm {

/// Most classes one query may carry.
inline constexpr std::uint32_t kMaxQueryClasses = 8;

class ClassImageSums;  // class_image_sums.h

/// Every class's density from one call, for classes that share their inputs (a biome map that gives the
/// densities of trees, bushes and rocks at once): one call where separate callbacks would take one each,
/// at every candidate the bounds leave open.
struct JointClassDensity {
  /// Writes the class_count densities at world position (x, y), points per unit area at scale 1, class 0
  /// first, into values[0 … class_count). NaN, negative and infinite values count as 0. Called from the
  /// querying thread (from every worker at once under ParallelQuery); it must give the same values for
  /// the same position.
  void (*densities)(void* user, double x, double y, double* values) = nullptr;
  /// Optional: bounds of each class's density over [x0, x1] × [y0, y1] into lo[k] ≤ ρ_k ≤ hi[k], as
  /// QueryDensity::bounds gives one density's (values that are not numbers fall back to 0 and max[k]).
  void (*bounds)(void* user, double x0, double y0, double x1, double y1, double* lo, double* hi) = nullptr;
  void* user = nullptr;  ///< passed to all three
  /// An upper bound of each class's density wherever it is read (finite, ≥ 0), as QueryDensity::callback_max
  /// (which says what values above it do). A class bounded by 0 has no points; all of them 0 is refused
  /// (the function would never be called: the bounds were left unset).
  double max[kMaxQueryClasses] = {};
  /// Instead of `densities` (set one of the two): the densities at n positions (x[i], y[i]) at once, class
  /// k's at position i into values[k · n + i], n ≤ kDensityBatch, for a vectorised function. The query
  /// gathers its reads as a one-class query gathers a batch callback's; the same points and classes.
  void (*batch_densities)(void* user, std::size_t n, const double* x, const double* y,
                          double* values) = nullptr;
};

struct ClassQueryParams {
  QueryParams query;              ///< region, origin, tile size, scale and mode; query.density is not read
  std::uint32_t class_count = 0;  ///< how many of `classes` are used: 1 … kMaxQueryClasses
  QueryDensity classes[kMaxQueryClasses];  ///< each class's density, class 0 first (highest priority)
  /// Optional: when joint.densities or joint.batch_densities is set, it gives every class's density and
  /// `classes` is not read.
  JointClassDensity joint;
  /// Optional: classes that are images on one grid, by the images of their running sums
  /// (class_image_sums.h; image_sums->count() must equal class_count). When set it gives every class's
  /// density, `classes` is not read, and the query reads one image where `classes` would read each.
  const ClassImageSums* image_sums = nullptr;
};

/// A hash of every field of `params` that a query reads: the identity its cursor keeps.
KDM_RUNTIME_API std::uint64_t query_fingerprint(const ClassQueryParams& params);

/// Writes the region's points into `out[0..capacity)` and each one's class (0 … class_count - 1) into
/// `classes[0..capacity)`, in query_points' order; `*written` receives the count. Returns kOk when the
/// region is complete, kBufferFull to be called again with the same cursor and params, kInvalidArgument
/// with `problem` (optional) naming the parameter for: a class count of 0 or more than kMaxQueryClasses
/// (kBadClassCount), a class's missing image or callback or bad callback_max (parameter
/// "classes[k].image", "classes[k].callback", "classes[k].callback_max"), a bad joint maximum
/// ("joint.max[k]"), both joint functions ("joint.batch_densities"), image sums for another class count
/// or with a joint density, or with an image the query cannot read ("image_sums"), a null `classes` with room
/// in `out`, and everything query_points refuses, judged on the sum of the densities (a density too high
/// names the scale: lower it or the classes). Capacity 0 checks the query, as query_points'. In smooth
/// mode points glide from the stable positions that keep classes apart, so where a class's density jumps
/// (an image with hard edges) two of different classes may come closer than stable mode lets them: place
/// objects that must keep apart in stable mode. No allocation.
KDM_RUNTIME_API Status query_classes(const Tileset& tileset, const ClassQueryParams& params, QueryPoint* out,
                                     std::uint8_t* classes, std::size_t capacity, std::size_t* written,
                                     QueryCursor* cursor, QueryProblem* problem = nullptr);

/// query_classes into a compact output (compact_query.h): the same points, order, classes, statuses and
/// cursor, each point's position as floats at out.xy[2i], out.xy[2i + 1] (bit for bit those
/// query_points_compact writes for the one-class query at the sum of the densities) and, if out.keys is not
/// null, its point_key at out.keys[i]. Refusals as query_classes', and query_points_compact's for the output
/// ("out.xy", a region beyond a float of the origin, kKeysUnsupported). No allocation.
KDM_RUNTIME_API Status query_classes_compact(const Tileset& tileset, const ClassQueryParams& params,
                                             const CompactPoints& out, std::uint8_t* classes,
                                             std::size_t capacity, std::size_t* written, QueryCursor* cursor,
                                             QueryProblem* problem = nullptr);

}  // namespace kdm
