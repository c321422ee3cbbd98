// Internal: query_points with the count of candidates examined carried in and out, so that a caller
// running it in pieces (query_classes, a chunk at a time) keeps one call's bound on its work.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

#include "image_sampler.h"
#include "kdm/runtime/class_query.h"
#include "kdm/runtime/compact_query.h"
#include "kdm/runtime/query.h"

namespace kdm::detail {

/// A query's refusals: the caller's optional QueryProblem, reset on entry and filled by a refusal.
class Refusal {
 public:
  explicit Refusal(QueryProblem* problem) : why_(problem ? *problem : unused_) { why_ = QueryProblem{}; }
  Refusal(const Refusal&) = delete;
  Refusal& operator=(const Refusal&) = delete;
  /// Records the problem; returns kInvalidArgument.
  Status operator()(QueryProblem::Kind kind, const char* parameter, double value = 0, double limit = 0) {
    why_.kind = kind, why_.parameter = parameter, why_.value = value, why_.limit = limit;
    return Status::kInvalidArgument;
  }
  QueryProblem& problem() { return why_; }

 private:
  QueryProblem unused_;  // where a caller without a QueryProblem gets its answer
  QueryProblem& why_;
};

/// A run of a query's depth-0 tiles in the order it visits them (rows bottom to top, each left to right):
/// the tiles (tx, ty) with (from_y, from_x) <= (ty, tx) < (to_y, to_x), row first. Consecutive runs, the
/// first from the lowest tile and the last to the highest, share out whatever tiles a query visits, each
/// with the points it emits (in smooth mode, those that glide in from beside the region too): ParallelQuery's
/// units. The default run is every tile.
struct TileRun {
  std::int64_t from_x = std::numeric_limits<std::int64_t>::min(), from_y = from_x;
  std::int64_t to_x = std::numeric_limits<std::int64_t>::max(), to_y = to_x;
};

/// Where a call's count of candidates examined starts, so that a call that does more per candidate stops
/// after about as much work as a plain one: a class query (`classes`) counts 1 + its classes read at each
/// candidate (a callback, an image, the joint density or the images' sums each one), and smooth mode's
/// glide_together, which reads the density again where a point glides, 8 times that (measured: the
/// longest calls of longest_call_benchmark then take about as long).
inline std::uint64_t first_examined(const QueryParams& q, bool classes, std::uint32_t reads) {
  const std::uint64_t together = q.mode == QueryMode::kSmooth && q.glide_together ? 8 : 1;
  const std::uint64_t weight = (classes ? 1 + std::uint64_t(reads) : 1) * together;
  return kMaxQueryCandidates - kMaxQueryCandidates / weight;
}

/// query_points over the tiles of `run`, counting into `examined` (on entry, what this call of the caller
/// has examined so far): it returns kBufferFull once `examined` reaches kMaxQueryCandidates.
Status query_points_counted(const Tileset& tileset, const QueryParams& params, QueryPoint* out,
                            std::size_t capacity, std::size_t* written, QueryCursor* cursor,
                            QueryProblem* problem, std::uint64_t& examined, const TileRun& run = {});

/// query_points_compact over the tiles of `run`.
Status query_compact_run(const Tileset& tileset, const QueryParams& params, const CompactPoints& out,
                         std::size_t capacity, std::size_t* written, QueryCursor* cursor,
                         QueryProblem* problem, const TileRun& run);

/// The compact output's own refusal, before query_points': `keys` asked of a set whose tiles hold more
/// points than a key's ranks (how far a float reaches from the origin is query_into's limit). kOk when
/// it does not apply, else kInvalidArgument with `refuse`'s problem filled.
Status compact_refusal(const Tileset& tileset, bool keys, Refusal& refuse);

/// Classes of constant densities (class_query.h), classed as they are written (emit_tile.h's ClassSink:
/// `counts` the classes' cumulative expected counts per depth-0 tile, `last` the last class, class_of_id
/// for points past the top level).
struct ConstantClasses {
  std::uint8_t* classes;
  const double* counts;
  std::uint32_t last;
  std::uint8_t (*class_of_id)(void* user, const PointId& id);
  void* user;
};

/// The union's density at the last position it was read (class_query.cpp's sum of the classes' densities
/// writes it): the position and the running sums of the classes' densities there, class 0 first. NaN
/// until the first read, so that no position matches it.
struct ClassScratch {
  double x = std::numeric_limits<double>::quiet_NaN(), y = x;
  double cumulative[kMaxQueryClasses] = {};
  /// The union's last batch read (classes read in batches): its `batch_count` positions and the running
  /// sums there, batch_cumulative[k][i] at position i.
  std::size_t batch_count = 0;
  double batch_x[kDensityBatch], batch_y[kDensityBatch];
  double batch_cumulative[kMaxQueryClasses][kDensityBatch];
};

/// Classes of varying densities, classed as they are written (emit_tile.h's VaryingClassSink). A candidate
/// whose union density was just read at its stable position (`scratch` holds that position) is classed from
/// the running sums there, without reading a density again; other points by `class_ranks` (ranks
/// [first, first + count) of depth-0 tile (tx, ty) into out[0..count)) or, past the top level,
/// `class_of_id`. `area` is a depth-0 tile's area times the scale, as the classifier multiplies it.
/// Classes that are all images on one grid of texels (class_query.cpp): `grid` reads class 0's, values[k]
/// are class k's texels, k < count; or, `cumulative`, classes 0 … k's summed density's (ClassImageSums),
/// the union's density then being the last one's image.
struct ClassImages {
  const ImageSampler* grid;
  const float* values[kMaxQueryClasses];
  std::uint32_t count;
  bool cumulative;
  const DensityImageView* sums[kMaxQueryClasses];  ///< when cumulative: the images of values[k], with mips
};

struct VaryingClasses {
  std::uint8_t* classes;
  ClassScratch* scratch;
  double area;
  std::uint32_t last;
  void (*class_ranks)(void* user, std::int64_t tx, std::int64_t ty, std::uint32_t first, std::uint32_t count,
                      std::uint8_t* out);
  std::uint8_t (*class_of_id)(void* user, const PointId& id);
  /// Ranks ranks[0 … n) of depth-0 tile (tx, ty) at their stable positions (x[i], y[i]), n at most
  /// kDensityBatch, into out[0 … n), the densities read in batches where any class is.
  void (*class_points)(void* user, std::int64_t tx, std::int64_t ty, const std::uint32_t* ranks,
                       std::size_t n, const double* x, const double* y, std::uint8_t* out);
  /// The points p[0 … n) of any depths into out[0 … n), the densities read in batches where any class is.
  void (*class_records)(void* user, const QueryPoint* p, std::size_t n, std::uint8_t* out);
  void* user;
  /// Classes all images on one grid, else null: the union's density is then read a block of candidates
  /// at a time (emit_tile.h: image_sums_run instead of its callback, or for running sums
  /// image_classes_run, the union being an image).
  const ClassImages* images = nullptr;
};

/// query_points into `out`, or query_points_compact into `compact`, with each point's class into
/// `classes.classes` (Classes: ConstantClasses or VaryingClasses), over the tiles of `run`, counting into
/// `examined` as query_points_counted does.
template <class Classes>
Status query_classes_counted(const Tileset& tileset, const QueryParams& params, QueryPoint* out,
                             const Classes& classes, std::size_t capacity, std::size_t* written,
                             QueryCursor* cursor, QueryProblem* problem, std::uint64_t& examined,
                             const TileRun& run);
template <class Classes>
Status query_classes_counted(const Tileset& tileset, const QueryParams& params, const CompactPoints& compact,
                             const Classes& classes, std::size_t capacity, std::size_t* written,
                             QueryCursor* cursor, QueryProblem* problem, std::uint64_t& examined,
                             const TileRun& run);

/// query_classes and query_classes_compact over the tiles of `run`.
Status query_classes_run(const Tileset& tileset, const ClassQueryParams& params, QueryPoint* out,
                         std::uint8_t* classes, std::size_t capacity, std::size_t* written,
                         QueryCursor* cursor, QueryProblem* problem, const TileRun& run);
Status query_classes_run(const Tileset& tileset, const ClassQueryParams& params, const CompactPoints& out,
                         std::uint8_t* classes, std::size_t capacity, std::size_t* written,
                         QueryCursor* cursor, QueryProblem* problem, const TileRun& run);

/// How many points query_points would write for `params` over the tiles of `run` from `cursor` on, into
/// `*count`, without writing them (the loops run with a sink that keeps nothing: whole tiles cost nothing
/// to count). Returns kOk, kBufferFull after kMaxQueryCandidates candidates (call again with the cursor
/// and add), or kInvalidArgument as query_points refuses.
Status count_points(const Tileset& tileset, const QueryParams& params, std::size_t* count,
                    QueryCursor* cursor, const TileRun& run = {});

}  // namespace kdm::detail
