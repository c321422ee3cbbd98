// One large query split over several threads, for callers that fill a large region at once. The query is
// cut into units, fixed by the parameters alone: runs of the tiles it visits, in its own order, or, where a
// tile holds many points, parts of each tile; workers take units in order. With a constant density a worker
// counts its unit (whole tiles cost nothing to count), takes its place once the unit before it has counted,
// and writes it there; with a varying density, whose count costs as much as the query, and in smooth mode
// into compact arrays, it queries the unit into its own scratch and copies it into place. The result is the
// units' points in unit order: the same bits for any number of threads or any task system, and the same
// points as query_points, in its order where no tile is cut into parts (in smooth mode a point that glides
// into the region comes with the tile it belongs to).
//
// The runtime library starts no threads: the caller gives a task system (TaskRunner), or the inline
// std::thread one below.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <thread>
#include <vector>

#include "kdm/runtime/allocator.h"
#include "kdm/runtime/class_query.h"
#include "kdm/runtime/compact_query.h"
#include "kdm/runtime/export.h"
#include "kdm/runtime/query.h"
#include "kdm/runtime/status.h"
#include "kdm/runtime/tileset.h"

namespace kdm {

/// A caller's task system: run(context, task, task_context, count) calls task(task_context, i) for i in
/// [0, count), on as many threads as it has, and returns when all it started have returned. Each task
/// takes units in order from a shared counter and may wait for the task holding the unit before its own,
/// which is running: any schedule works in which a started task runs to its end (concurrently, in turn on
/// one thread, or some tasks not at all so long as one runs), not one that suspends a task to run another
/// of the same call on its thread (fibers switching while a task waits), which can wait forever.
struct TaskRunner {
  void (*run)(void* context, void (*task)(void* task_context, std::size_t index), void* task_context,
              std::size_t count) = nullptr;
  void* context = nullptr;
};

/// A TaskRunner over std::thread: count - 1 new threads and the caller's. Inline, so only a program that
/// uses it links threads.
inline TaskRunner std_thread_runner() {
  TaskRunner r;
  r.run = [](void*, void (*task)(void*, std::size_t), void* task_context, std::size_t count) {
    std::vector<std::thread> threads;
    for (std::size_t i = 1; i < count; ++i) threads.emplace_back(task, task_context, i);
    if (count > 0) task(task_context, 0);
    for (std::thread& t : threads) t.join();
  };
  return r;
}

/// Most workers one ParallelQuery serves.
inline constexpr std::uint32_t kMaxParallelWorkers = 64;

/// Points a worker's scratch holds: a unit of a varying density is sized to expect at most half as many.
inline constexpr std::size_t kParallelUnitPoints = std::size_t(1) << 15;

/// The per-worker scratch of parallel queries, allocated once by init (through the tile-set allocator
/// hooks, allocator.h); run then allocates nothing. One ParallelQuery serves one run at a time.
class KDM_RUNTIME_API ParallelQuery {
 public:
  /// Scratch for `workers` workers (1 … kMaxParallelWorkers; about 1.9 MB each). kInvalidArgument for a
  /// count out of range, kOutOfMemory (and no scratch) when the allocator refuses it.
  Status init(std::uint32_t workers);
  std::uint32_t workers() const { return workers_; }

  /// The region's points into out[0 .. capacity) in unit order, `*written` the count, with `workers()`
  /// tasks on `runner`. kOk when all fit; kBufferFull when there were more (out holds the first
  /// `capacity`, `*needed` the full count if not null: call again with room for it; capacity 0 with a
  /// null out only counts; with `needed` null the run stops soon after the buffer is full, leaving the
  /// rest of the region unvisited). kInvalidArgument with
  /// `problem` as query_points refuses the parameters, or for a ParallelQuery not initialised or a runner
  /// without a run function.
  Status run(const Tileset& tileset, const QueryParams& params, QueryPoint* out, std::size_t capacity,
             std::size_t* written, const TaskRunner& runner, std::size_t* needed = nullptr,
             QueryProblem* problem = nullptr);
  /// The same into a compact output (compact_query.h).
  Status run(const Tileset& tileset, const QueryParams& params, const CompactPoints& out,
             std::size_t capacity, std::size_t* written, const TaskRunner& runner,
             std::size_t* needed = nullptr, QueryProblem* problem = nullptr);
  /// Several classes (class_query.h): query_classes' points and classes, each point's class into
  /// classes[0 .. capacity), split into units as the one-class query at the classes' sum is. The classes'
  /// callbacks are called from the runner's threads at once, so they must be safe to call concurrently.
  /// Statuses and refusals as the one-class run's, and query_classes' for the classes (a null `classes`
  /// with room: "out").
  Status run(const Tileset& tileset, const ClassQueryParams& params, QueryPoint* out, std::uint8_t* classes,
             std::size_t capacity, std::size_t* written, const TaskRunner& runner,
             std::size_t* needed = nullptr, QueryProblem* problem = nullptr);
  /// The same into a compact output.
  Status run(const Tileset& tileset, const ClassQueryParams& params, const CompactPoints& out,
             std::uint8_t* classes, std::size_t capacity, std::size_t* written, const TaskRunner& runner,
             std::size_t* needed = nullptr, QueryProblem* problem = nullptr);

 private:
  template <class Output>
  Status run_into(const Tileset& tileset, const QueryParams& params, const Output& out, std::size_t capacity,
                  std::size_t* written, const TaskRunner& runner, std::size_t* needed, QueryProblem* problem);

  std::uint32_t workers_ = 0;
  TilesetArray<QueryPoint> points_;     ///< workers × kParallelUnitPoints
  TilesetArray<float> xy_;              ///< workers × 2 · kParallelUnitPoints
  TilesetArray<std::uint64_t> keys_;    ///< workers × kParallelUnitPoints
  TilesetArray<std::uint8_t> classes_;  ///< workers × kParallelUnitPoints
};

}  // namespace kdm
