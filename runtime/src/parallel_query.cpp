// One query over several threads; see kdm/runtime/parallel_query.h.
#include "kdm/runtime/parallel_query.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <thread>

#include "density_bounds.h"
#include "kdm/runtime/check.h"
#include "kdm/runtime/class_image_sums.h"
#include "query_counted.h"
#include "query_tables.h"

namespace kdm {
namespace {

/// A unit: the query over `part` (the whole region, or a part of it) and the tiles of `run`.
struct Unit {
  QueryParams part;
  detail::TileRun run;
};

/// The units of a region. Where tiles are whole: runs of `per_run` tiles in the query's own order over the
/// tiles it visits (the region widened by the farthest glide, rows bottom to top), each querying the whole
/// region, so that the units' points in unit order are the query's, in its order, in both modes (a point
/// that glides into the region comes with the tile it belongs to). Where a tile expects more than a
/// unit's points: a grid of cells (g × g parts of each tile) cut into runs of `across` cells along a row,
/// each querying its part of the region. Every boundary is computed from integer indices alone, so
/// neighbouring units share it bit for bit.
struct UnitGrid {
  bool runs = true;
  std::int64_t tx0 = 0, ty0 = 0, width = 1, tiles = 1, per_run = 1;  // runs
  double cell = 1;                                                   // cells
  std::int64_t cx0 = 0, cy0 = 0;                                     ///< the first cell's index
  std::int64_t columns = 0, rows = 0, across = 1;

  std::int64_t per_row() const { return (columns + across - 1) / across; }
  std::size_t units() const {
    return static_cast<std::size_t>(runs ? (tiles + per_run - 1) / per_run : per_row() * rows);
  }
  Unit unit(const QueryParams& whole, std::size_t u) const {
    Unit unit{whole, {}};
    if (runs) {  // the first run from the lowest tile and the last to the highest: all tiles are served
      const std::int64_t first = static_cast<std::int64_t>(u) * per_run, next = first + per_run;
      if (u > 0) unit.run.from_x = tx0 + first % width, unit.run.from_y = ty0 + first / width;
      if (next < tiles) unit.run.to_x = tx0 + next % width, unit.run.to_y = ty0 + next / width;
      return unit;
    }
    const std::int64_t r0 = static_cast<std::int64_t>(u) / per_row(), r1 = r0 + 1;
    const std::int64_t c0 = static_cast<std::int64_t>(u) % per_row() * across,
                       c1 = std::min(columns, c0 + across);
    QueryParams& q = unit.part;
    q.x0 = std::max(whole.x0, double(cx0 + c0) * cell), q.x1 = std::min(whole.x1, double(cx0 + c1) * cell);
    q.y0 = std::max(whole.y0, double(cy0 + r0) * cell), q.y1 = std::min(whole.y1, double(cy0 + r1) * cell);
    if (c0 == 0) q.x0 = whole.x0;  // the region's own sides, not a rounding of them
    if (c1 == columns) q.x1 = whole.x1;
    if (r0 == 0) q.y0 = whole.y0;
    if (r1 == rows) q.y1 = whole.y1;
    return unit;
  }
};

/// Points a unit aims at when it is counted first and written in place (a constant density): only its
/// count waits for the unit before, but units many times the workers' count keep the last ones even.
constexpr double kDirectUnitPoints = double(std::size_t(1) << 18);

/// Most cells a tile is cut into per side: units of a denser tile hold more than a unit's points.
constexpr std::int64_t kMaxCellsPerTileSide = 1024;

/// Units that expect about `target` points.
UnitGrid plan_units(const Tileset& tileset, const QueryParams& q, double target) {
  double rho = 0;  // an upper bound of the density (the query has accepted it)
  switch (q.density.kind) {
    case QueryDensity::Kind::kConstant:
      rho = q.density.constant;
      break;
    case QueryDensity::Kind::kImage:
      rho = q.density.image->max_over(q.x0, q.y0, q.x1, q.y1);
      break;
    case QueryDensity::Kind::kCallback:
      rho = q.density.callback_max;
      break;
  }
  const double S = q.tile_size, per_tile = std::max(rho, 0.0) * S * S * q.scale;
  UnitGrid g;
  if (!(per_tile > target)) {
    // The tiles the query visits, about: widened by as far as any point glides (the query's own reach is
    // no farther), clamped where it refuses tile indices.
    double reach = 0;
    if (q.mode == QueryMode::kSmooth && tileset.has_glide_track()) {
      const detail::QueryTables& tables = detail::TilesetInternals::tables(tileset);
      reach = tables.descent_reach;
      for (double r : tables.glide_reach) reach = std::max(reach, r);
      reach *= S;
    }
    auto index = [](double t) { return std::int64_t(std::clamp(t, -9e15, 9e15)); };
    g.tx0 = index(std::floor((q.x0 - reach) / S)), g.ty0 = index(std::floor((q.y0 - reach) / S));
    g.width = std::max<std::int64_t>(1, index(std::ceil((q.x1 + reach) / S)) - g.tx0);
    const std::int64_t height = std::max<std::int64_t>(1, index(std::ceil((q.y1 + reach) / S)) - g.ty0);
    g.tiles = g.width * height;  // at most about kMaxQueryTiles, which the query has accepted
    g.per_run = per_tile > 0 ? std::int64_t(std::clamp(target / per_tile, 1.0, double(g.tiles))) : g.tiles;
    return g;
  }
  g.runs = false;
  const std::int64_t split =
      std::min<std::int64_t>(kMaxCellsPerTileSide, std::int64_t(std::ceil(std::sqrt(per_tile / target))));
  g.cell = S / double(split);
  g.cx0 = std::int64_t(std::floor(q.x0 / S)) * split;
  g.cy0 = std::int64_t(std::floor(q.y0 / S)) * split;
  g.columns = std::max<std::int64_t>(1, std::int64_t(std::ceil(q.x1 / g.cell)) - g.cx0);
  g.rows = std::max<std::int64_t>(1, std::int64_t(std::ceil(q.y1 / g.cell)) - g.cy0);
  const double per_cell = per_tile / double(split * split);
  g.across = std::max<std::int64_t>(1, std::int64_t(std::min(target / per_cell, 1e12)));
  // A query refuses a region too narrow for its distance from the world origin (kTooFarFromOrigin: its
  // side under about 2^-50 of that distance) that the whole region may not be. The first and last rows
  // and columns the region cuts that thin, or misses (the grid starts at a tile's side), are merged into
  // their neighbours; and as far out as even a whole cell could be refused (2^46 cells, where only a
  // density below a point in 16 cells is accepted), the region is one unit.
  const double far = std::max({std::fabs(q.x0), std::fabs(q.x1), std::fabs(q.y0), std::fabs(q.y1)});
  if (far > std::ldexp(g.cell, 46)) {
    g.runs = true, g.tiles = g.per_run = 1;
    return g;
  }
  const double thin = std::ldexp(far, -40);  // under 64 cells: each loop below runs at most split + 64 times
  auto merge_slivers = [&](double lo, double hi, std::int64_t& first, std::int64_t& count) {
    while (count > 1 && double(first + 1) * g.cell - lo < thin) ++first, --count;
    while (count > 1 && hi - double(first + count - 1) * g.cell < thin) --count;
  };
  merge_slivers(q.x0, q.x1, g.cx0, g.columns);
  merge_slivers(q.y0, q.y1, g.cy0, g.rows);
  return g;
}

/// The classes' union as units are planned and counted: their constant sum (the very number the class
/// query adds up), else a callback density bounded by the sum of the classes' bounds over the region
/// (never called: only plan_units reads its bound). For classes the class query has accepted.
QueryParams union_plan(const ClassQueryParams& p) {
  QueryParams q = p.query;
  q.density = QueryDensity{};
  if (p.image_sums) {  // the union is the last sum's image
    q.density.kind = QueryDensity::Kind::kCallback;
    q.density.callback_max = p.image_sums->sum(p.class_count - 1).max_over(q.x0, q.y0, q.x1, q.y1);
    return q;
  }
  const bool joint = p.joint.densities || p.joint.batch_densities;
  bool constant = !joint;
  double sum = 0;
  for (std::uint32_t k = 0; k < p.class_count && k < kMaxQueryClasses; ++k) {
    const QueryDensity& d = p.classes[k];
    if (joint) {
      sum += p.joint.max[k];
    } else if (d.kind == QueryDensity::Kind::kConstant) {
      sum += detail::density_or_zero(d.constant);
    } else {
      constant = false;
      sum +=
          d.kind == QueryDensity::Kind::kImage ? d.image->max_over(q.x0, q.y0, q.x1, q.y1) : d.callback_max;
    }
  }
  if (constant) {
    q.density.constant = sum;
  } else {
    q.density.kind = QueryDensity::Kind::kCallback;
    q.density.callback_max = sum;
  }
  return q;
}

/// A worker's scratch (ParallelQuery's arrays at its offset), which an output takes what it uses of.
struct Scratch {
  QueryPoint* points;
  float* xy;
  std::uint64_t* keys;
  std::uint8_t* classes;
};

/// Where a worker's unit goes and what it reads: QueryPoint records or compact arrays.
struct PointOutput {
  static constexpr bool kRecords = true;
  QueryPoint* out;
  QueryPoint* scratch;  // of this worker
  Status probe(const Tileset& t, const QueryParams& q, QueryCursor* c, QueryProblem* problem) const {
    std::size_t none = 0;
    return query_points(t, q, out, 0, &none, c, problem);
  }
  void take(const Scratch& s) { scratch = s.points; }
  Status query(const Tileset& t, const Unit& u, std::size_t* w, QueryCursor* c, QueryProblem* p) const {
    std::uint64_t examined = 0;
    return detail::query_points_counted(t, u.part, scratch, kParallelUnitPoints, w, c, p, examined, u.run);
  }
  Status query_in_place(const Tileset& t, const Unit& u, std::size_t at, std::size_t room, std::size_t* w,
                        QueryCursor* c) const {
    std::uint64_t examined = 0;
    return detail::query_points_counted(t, u.part, out + at, room, w, c, nullptr, examined, u.run);
  }
  /// The output argument that is null, named as the one-call query names it; null if none is.
  const char* missing_output() const { return out ? nullptr : "out"; }
  void copy(std::size_t to, std::size_t count) const { std::memcpy(out + to, scratch, count * sizeof *out); }
};

struct CompactOutput {
  static constexpr bool kRecords = false;
  CompactPoints out, scratch;
  Status probe(const Tileset& t, const QueryParams& q, QueryCursor* c, QueryProblem* problem) const {
    std::size_t none = 0;
    return query_points_compact(t, q, out, 0, &none, c, problem);
  }
  void take(const Scratch& s) { scratch = CompactPoints{s.xy, out.keys ? s.keys : nullptr}; }
  Status query(const Tileset& t, const Unit& u, std::size_t* w, QueryCursor* c, QueryProblem* p) const {
    return detail::query_compact_run(t, u.part, scratch, kParallelUnitPoints, w, c, p, u.run);
  }
  Status query_in_place(const Tileset& t, const Unit& u, std::size_t at, std::size_t room, std::size_t* w,
                        QueryCursor* c) const {
    return detail::query_compact_run(t, u.part,
                                     CompactPoints{out.xy + 2 * at, out.keys ? out.keys + at : nullptr}, room,
                                     w, c, nullptr, u.run);
  }
  const char* missing_output() const { return out.xy ? nullptr : "out.xy"; }
  void copy(std::size_t to, std::size_t count) const {
    std::memcpy(out.xy + 2 * to, scratch.xy, 2 * count * sizeof(float));
    if (out.keys) std::memcpy(out.keys + to, scratch.keys, count * sizeof(std::uint64_t));
  }
};

/// Either output with each point's class (query_classes, query_classes_compact over a unit): the caller's
/// `classes` beside `base.out`, this worker's `class_scratch` beside its scratch.
template <class Base>
struct ClassOutput {
  static constexpr bool kRecords = Base::kRecords;
  Base base;
  const ClassQueryParams* params;
  std::uint8_t* classes;
  std::uint8_t* class_scratch = nullptr;

  /// The class query over unit `q` (its region; the rest is params').
  ClassQueryParams over(const QueryParams& q) const {
    ClassQueryParams p = *params;
    p.query.x0 = q.x0, p.query.y0 = q.y0, p.query.x1 = q.x1, p.query.y1 = q.y1;
    return p;
  }
  Status probe(const Tileset& t, const QueryParams&, QueryCursor* c, QueryProblem* problem) const {
    std::size_t none = 0;
    return detail::query_classes_run(t, *params, base.out, classes, 0, &none, c, problem, {});
  }
  void take(const Scratch& s) { base.take(s), class_scratch = s.classes; }
  Status query(const Tileset& t, const Unit& u, std::size_t* w, QueryCursor* c, QueryProblem* p) const {
    return detail::query_classes_run(t, over(u.part), base.scratch, class_scratch, kParallelUnitPoints, w, c,
                                     p, u.run);
  }
  Status query_in_place(const Tileset& t, const Unit& u, std::size_t at, std::size_t room, std::size_t* w,
                        QueryCursor* c) const {
    if constexpr (std::is_same_v<Base, CompactOutput>)
      return detail::query_classes_run(
          t, over(u.part), CompactPoints{base.out.xy + 2 * at, base.out.keys ? base.out.keys + at : nullptr},
          classes + at, room, w, c, nullptr, u.run);
    else
      return detail::query_classes_run(t, over(u.part), base.out + at, classes + at, room, w, c, nullptr,
                                       u.run);
  }
  const char* missing_output() const {
    return base.missing_output() ? base.missing_output() : classes ? nullptr : "classes";
  }
  void copy(std::size_t to, std::size_t count) const {
    base.copy(to, count);
    std::memcpy(classes + to, class_scratch, count);
  }
};

/// What the workers share: the units, the next unit to take, and the end of the last unit counted.
template <class Output>
struct Job {
  const Tileset* tileset;
  const QueryParams* params;
  UnitGrid grid;
  std::size_t units, capacity;
  bool direct;            // count_and_write, else through each worker's scratch
  const Output* outputs;  // one per worker
  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> counted{0};  // units [0, counted) have their places; `end` follows the last
  std::atomic<std::size_t> end{0};
  std::atomic<bool> refused{false};  // a unit was refused where the whole query was not (a bug): `why`
  QueryProblem why;
  bool count_all = true;          // the caller asked how many points there are (`needed`)
  std::atomic<bool> full{false};  // a unit's points passed `capacity`: without count_all the rest are skipped

  /// Whether unit u, its place taken, is left undone: the buffer is full and nobody needs its count.
  bool skipped(std::size_t u) {
    if (count_all || !full.load(std::memory_order_relaxed)) return false;
    place_of(u);  // in turn, so that `end` stays the last written unit's
    counted.store(u + 1, std::memory_order_release);
    return true;
  }

  /// Unit u's first slot, once every unit before it has counted its points.
  std::size_t place_of(std::size_t u) {
    while (counted.load(std::memory_order_acquire) != u) std::this_thread::yield();
    return end.load(std::memory_order_relaxed);
  }

  /// Counts unit u, takes its place, then writes it there: no copy (a constant density, whose count costs
  /// little beside its writing).
  void count_and_write(const Output& o, std::size_t u, const Unit& part) {
    QueryCursor cursor;
    std::size_t count = 0;
    for (;;) {
      std::size_t c = 0;
      const Status s = detail::count_points(*tileset, part.part, &c, &cursor, part.run);
      KDM_CHECK(s == Status::kOk || s == Status::kBufferFull);
      count += c;
      if (s == Status::kInvalidArgument &&
          !refused.exchange(true)) {  // the refusal, from a call with no room
        QueryCursor probe;
        std::size_t none = 0;
        query_points(*tileset, part.part, nullptr, 0, &none, &probe, &why);
      }
      if (s != Status::kBufferFull) break;
    }
    const std::size_t base = place_of(u);
    end.store(base + count, std::memory_order_relaxed);
    if (base + count > capacity) full.store(true, std::memory_order_relaxed);
    counted.store(u + 1, std::memory_order_release);
    const std::size_t room = base < capacity ? std::min(count, capacity - base) : 0;
    cursor = QueryCursor{};
    for (std::size_t done = 0; done < room;) {
      std::size_t w = 0;
      const Status s = o.query_in_place(*tileset, part, base + done, room - done, &w, &cursor);
      done += w;
      if (s != Status::kBufferFull) break;
    }
  }

  void work(std::size_t worker) {
    const Output& o = outputs[worker];
    for (;;) {
      const std::size_t u = next.fetch_add(1, std::memory_order_relaxed);
      if (u >= units) return;
      if (skipped(u)) continue;
      const Unit part = grid.unit(*params, u);
      if (direct) {
        count_and_write(o, u, part);
        continue;
      }
      QueryCursor cursor;
      constexpr std::size_t kUnplaced = std::numeric_limits<std::size_t>::max();
      std::size_t base = kUnplaced, count = 0;
      for (;;) {
        std::size_t w = 0;
        QueryProblem problem;
        const Status s = o.query(*tileset, part, &w, &cursor, &problem);
        KDM_CHECK(s == Status::kOk || s == Status::kBufferFull);  // the whole query was accepted
        if (s == Status::kInvalidArgument && !refused.exchange(true)) why = problem;
        const bool last = s != Status::kBufferFull;  // a refused unit ends too: no worker waits forever
        // A unit waits for its place before its first copy and, once counted, publishes its end before
        // copying, so the next unit waits for this one's count, not for its copy.
        if (base == kUnplaced) base = place_of(u);
        if (last) {
          end.store(base + count + w, std::memory_order_relaxed);
          if (base + count + w > capacity) full.store(true, std::memory_order_relaxed);
          counted.store(u + 1, std::memory_order_release);
        }
        if (base + count < capacity) o.copy(base + count, std::min(w, capacity - base - count));
        count += w;
        if (last) break;
      }
    }
  }
};

}  // namespace

Status ParallelQuery::init(std::uint32_t workers) {
  if (workers < 1 || workers > kMaxParallelWorkers) return Status::kInvalidArgument;
#if defined(__cpp_exceptions) || defined(__EXCEPTIONS)
  try {
#endif
    // New arrays, moved in with their allocators: the hooks in force now serve them.
    const std::size_t n = std::size_t(workers) * kParallelUnitPoints;
    *this = ParallelQuery{};
    decltype(points_) points(n, QueryPoint{});
    decltype(xy_) xy(2 * n, 0.0f);
    decltype(keys_) keys(n, 0);
    decltype(classes_) classes(n, 0);
    points_ = std::move(points), xy_ = std::move(xy), keys_ = std::move(keys), classes_ = std::move(classes);
    workers_ = workers;
    return Status::kOk;
#if defined(__cpp_exceptions) || defined(__EXCEPTIONS)
  } catch (const std::bad_alloc&) {  // the hooks refused: no scratch, no workers
    *this = ParallelQuery{};
    return Status::kOutOfMemory;
  }
#endif
}

template <class Output>
Status ParallelQuery::run_into(const Tileset& tileset, const QueryParams& q, const Output& out,
                               std::size_t capacity, std::size_t* written, const TaskRunner& runner,
                               std::size_t* needed, QueryProblem* problem) {
  // The whole query's refusals, from a call with no room (it stops at the first point).
  QueryCursor probe;
  const Status s = out.probe(tileset, q, &probe, problem);
  if (written) *written = 0;
  if (needed) *needed = 0;
  if (s == Status::kInvalidArgument) return s;
  QueryProblem why;
  QueryProblem& p = problem ? *problem : why;
  auto refuse = [&](QueryProblem::Kind kind, const char* parameter) {
    p = QueryProblem{};
    p.kind = kind, p.parameter = parameter;
    return Status::kInvalidArgument;
  };
  if (workers_ == 0) return refuse(QueryProblem::Kind::kMissingArgument, "ParallelQuery::init");
  if (!runner.run) return refuse(QueryProblem::Kind::kMissingArgument, "runner.run");
  if (const char* missing = out.missing_output(); capacity > 0 && missing)
    return refuse(QueryProblem::Kind::kMissingArgument, missing);
  if (s == Status::kOk) return Status::kOk;  // no point at all

  // Classes: units planned and counted over their union.
  QueryParams plan = q;
  if constexpr (!std::is_same_v<Output, PointOutput> && !std::is_same_v<Output, CompactOutput>)
    plan = union_plan(*out.params);
  Job<Output> job;
  job.tileset = &tileset, job.params = &plan;
  // A constant density's units are counted, then written in place; a varying one's, whose count costs
  // as much as the query, go through the scratch (room for a loose bound and the glide's margin). So do
  // a constant one's in smooth mode into compact arrays: there the count, which glides the points along
  // the region's sides, costs more than copying 8 or 16 bytes a point (records: 40). Both outputs plan
  // the same units, so that they hold the same points in the same order.
  const bool constant = plan.density.kind == QueryDensity::Kind::kConstant;
  const bool stable = plan.mode == QueryMode::kStable;
  job.direct = constant && (stable || Output::kRecords);
  job.grid =
      plan_units(tileset, plan, constant && stable ? kDirectUnitPoints : double(kParallelUnitPoints) / 2);
  job.units = job.grid.units(), job.capacity = capacity;
  job.count_all = needed != nullptr;
  Output outputs[kMaxParallelWorkers];
  for (std::uint32_t w = 0; w < workers_; ++w) {
    const std::size_t at = std::size_t(w) * kParallelUnitPoints;
    outputs[w] = out;
    outputs[w].take(
        Scratch{points_.data() + at, xy_.data() + 2 * at, keys_.data() + at, classes_.data() + at});
  }
  job.outputs = outputs;
  runner.run(
      runner.context, [](void* j, std::size_t worker) { static_cast<Job<Output>*>(j)->work(worker); }, &job,
      workers_);
  if (job.refused.load()) {  // KDM_CHECK'd in the workers: units are planned to be accepted
    p = job.why;
    return Status::kInvalidArgument;
  }
  // A runner that returned without running its tasks left units unclaimed: an error, not an empty region.
  if (const std::size_t taken = job.next.load(); taken < job.units) {
    refuse(QueryProblem::Kind::kRunnerIncomplete, "runner.run");
    p.value = double(taken), p.limit = double(job.units);
    return Status::kInvalidArgument;
  }
  const std::size_t total = job.end.load();
  if (written) *written = std::min(total, capacity);
  if (needed) *needed = total;
  return total <= capacity ? Status::kOk : Status::kBufferFull;
}

Status ParallelQuery::run(const Tileset& tileset, const QueryParams& params, QueryPoint* out,
                          std::size_t capacity, std::size_t* written, const TaskRunner& runner,
                          std::size_t* needed, QueryProblem* problem) {
  return run_into(tileset, params, PointOutput{out, nullptr}, capacity, written, runner, needed, problem);
}

Status ParallelQuery::run(const Tileset& tileset, const QueryParams& params, const CompactPoints& out,
                          std::size_t capacity, std::size_t* written, const TaskRunner& runner,
                          std::size_t* needed, QueryProblem* problem) {
  return run_into(tileset, params, CompactOutput{out, {}}, capacity, written, runner, needed, problem);
}

Status ParallelQuery::run(const Tileset& tileset, const ClassQueryParams& params, QueryPoint* out,
                          std::uint8_t* classes, std::size_t capacity, std::size_t* written,
                          const TaskRunner& runner, std::size_t* needed, QueryProblem* problem) {
  return run_into(tileset, params.query,
                  ClassOutput<PointOutput>{PointOutput{out, nullptr}, &params, classes}, capacity, written,
                  runner, needed, problem);
}

Status ParallelQuery::run(const Tileset& tileset, const ClassQueryParams& params, const CompactPoints& out,
                          std::uint8_t* classes, std::size_t capacity, std::size_t* written,
                          const TaskRunner& runner, std::size_t* needed, QueryProblem* problem) {
  return run_into(tileset, params.query, ClassOutput<CompactOutput>{CompactOutput{out, {}}, &params, classes},
                  capacity, written, runner, needed, problem);
}

}  // namespace kdm
