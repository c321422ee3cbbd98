// One query over several threads: the same bits for any worker count and task system, the same points as
// query_points (in its order too where no tile is cut into parts), dense tiles cut into parts, a short
// buffer, refusals, no allocation in a run; and the same for several classes.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <map>
#include <tuple>
#include <vector>

#include "allocation_counter.h"
#include "kdm/runtime/parallel_query.h"
#include "run_query.h"

namespace kdm {
namespace {

TaskRunner sequential_runner() {
  TaskRunner r;
  r.run = [](void*, void (*task)(void*, std::size_t), void* context, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) task(context, i);
  };
  return r;
}

/// A task system that runs only the last of the tasks it is given, as one that is busy may: the task it
/// runs takes every unit (the contract in parallel_query.h).
TaskRunner last_task_runner() {
  TaskRunner r;
  r.run = [](void*, void (*task)(void*, std::size_t), void* context, std::size_t count) {
    if (count > 0) task(context, count - 1);
  };
  return r;
}

std::vector<QueryPoint> run_whole(const QueryParams& q) {
  return testing::run_query(q, 1 << 16);
}

std::vector<QueryPoint> run_parallel(const QueryParams& q, std::uint32_t workers, const TaskRunner& runner) {
  ParallelQuery pq;
  EXPECT_EQ(pq.init(workers), Status::kOk);
  std::vector<QueryPoint> out(1 << 21);
  std::size_t written = 0, needed = 0;
  EXPECT_EQ(pq.run(Tileset::builtin(), q, out.data(), out.size(), &written, runner, &needed), Status::kOk);
  EXPECT_EQ(written, needed);
  out.resize(written);
  return out;
}

using testing::same_bits;

using Key = std::tuple<std::int64_t, std::int64_t, std::uint32_t, std::uint32_t>;
std::map<Key, std::pair<double, double>> by_id(const std::vector<QueryPoint>& points) {
  std::map<Key, std::pair<double, double>> m;
  for (const QueryPoint& p : points)
    EXPECT_TRUE(
        m.emplace(Key{p.id.tile_x, p.id.tile_y, p.id.rank, p.id.depth}, std::make_pair(p.x, p.y)).second);
  return m;
}

double ramp(void*, double x, double) {
  return 0.2 + 0.1 * x;
}

QueryParams region(QueryMode mode, int kind) {
  QueryParams q;
  q.x0 = -2.3, q.y0 = 0.6, q.x1 = 4.2, q.y1 = 5.1;
  q.origin_x = 1, q.origin_y = 2;
  q.scale = 20000;  // units of two tiles' runs: many units
  q.mode = mode;
  if (kind == 1) {
    q.density.kind = QueryDensity::Kind::kCallback;
    q.density.callback = ramp, q.density.callback_max = 0.7;
  }
  return q;
}

TEST(ParallelQueryTest, GivesTheSameBitsForAnyWorkerCountAndTheWholeQuerysPoints) {
  for (QueryMode mode : {QueryMode::kStable, QueryMode::kSmooth}) {
    for (int kind = 0; kind < 2; ++kind) {
      SCOPED_TRACE(::testing::Message() << "mode " << int(mode) << " kind " << kind);
      const QueryParams q = region(mode, kind);
      const std::vector<QueryPoint> whole = run_whole(q);
      const std::vector<QueryPoint> one = run_parallel(q, 1, sequential_runner());
      ASSERT_GT(one.size(), 100000u);
      EXPECT_TRUE(same_bits(one, run_parallel(q, 2, std_thread_runner())));
      EXPECT_TRUE(same_bits(one, run_parallel(q, 3, std_thread_runner())));
      EXPECT_TRUE(same_bits(one, run_parallel(q, 2, sequential_runner())));
      EXPECT_TRUE(same_bits(one, run_parallel(q, 3, last_task_runner())));
      EXPECT_TRUE(by_id(one) == by_id(whole));
    }
  }
}

// An engine's budget refuses the scratch: a status, no workers, and a later init with memory works.
TEST(ParallelQueryTest, ScratchTheAllocatorRefusesIsOutOfMemory) {
  AllocatorHooks refusing;
  refusing.allocate = [](std::size_t, std::size_t, void*) -> void* { return nullptr; };
  refusing.deallocate = [](void*, std::size_t, std::size_t, void*) {};
  set_tileset_allocator(refusing);
  ParallelQuery parallel;
  const Status refused = parallel.init(2);
  set_tileset_allocator(AllocatorHooks{});
  EXPECT_EQ(refused, Status::kOutOfMemory);
  EXPECT_EQ(parallel.workers(), 0u);
  EXPECT_EQ(parallel.init(2), Status::kOk);
  EXPECT_EQ(parallel.workers(), 2u);
}

TEST(ParallelQueryTest, KeepsTheWholeQuerysOrderWhereTilesAreWhole) {
  for (QueryMode mode : {QueryMode::kStable, QueryMode::kSmooth}) {
    for (int kind = 0; kind < 2; ++kind) {      // counted and written in place, and through the scratch
      for (double scale : {3000.0, 15000.0}) {  // runs of several tiles, and of one, none cut
        QueryParams q = region(mode, kind);
        q.scale = scale;
        const std::vector<QueryPoint> whole = run_whole(q);
        ASSERT_GT(whole.size(), 20000u);
        EXPECT_TRUE(same_bits(run_parallel(q, 2, std_thread_runner()), whole))
            << "mode " << int(mode) << " density kind " << kind << " scale " << scale;
      }
    }
  }
}

TEST(ParallelQueryTest, CutsDenseTilesAndWritesCompactOutput) {
  QueryParams q;
  q.x0 = 0.1, q.y0 = 0.2, q.x1 = 1.3, q.y1 = 1.1;
  q.mode = QueryMode::kSmooth;
  q.scale = 2 * Tileset::builtin().max_points_per_tile();  // past the top: tiles cut into parts
  const std::vector<QueryPoint> whole = run_whole(q);
  ASSERT_GT(whole.size(), 60000u);
  const std::vector<QueryPoint> two = run_parallel(q, 2, std_thread_runner());
  EXPECT_TRUE(by_id(two) == by_id(whole));
  // The compact form: the records' points, in their order, as floats and keys.
  ParallelQuery pq;
  ASSERT_EQ(pq.init(2), Status::kOk);
  std::vector<float> xy(2 * two.size());
  std::vector<std::uint64_t> keys(two.size());
  std::size_t written = 0;
  ASSERT_EQ(pq.run(Tileset::builtin(), q, CompactPoints{xy.data(), keys.data()}, keys.size(), &written,
                   std_thread_runner()),
            Status::kOk);
  ASSERT_EQ(written, two.size());
  for (std::size_t i = 0; i < written; ++i) {
    ASSERT_EQ(keys[i], point_key(two[i].id)) << i;
    ASSERT_LE(std::fabs(xy[2 * i] - two[i].x), std::ldexp(std::fabs(two[i].x) + 1, -21));
  }
}

TEST(ParallelQueryTest, AShortBufferHoldsThePrefixAndTellsTheCount) {
  const QueryParams q = region(QueryMode::kSmooth, 0);
  const std::vector<QueryPoint> all = run_parallel(q, 2, std_thread_runner());
  ParallelQuery pq;
  ASSERT_EQ(pq.init(2), Status::kOk);
  std::vector<QueryPoint> out(all.size() / 3);
  std::size_t written = 0, needed = 0;
  EXPECT_EQ(pq.run(Tileset::builtin(), q, out.data(), out.size(), &written, std_thread_runner(), &needed),
            Status::kBufferFull);
  EXPECT_EQ(written, out.size());
  EXPECT_EQ(needed, all.size());
  EXPECT_EQ(std::memcmp(out.data(), all.data(), out.size() * sizeof(QueryPoint)), 0);
  // No room: a count alone.
  EXPECT_EQ(pq.run(Tileset::builtin(), q, static_cast<QueryPoint*>(nullptr), 0, &written, std_thread_runner(),
                   &needed),
            Status::kBufferFull);
  EXPECT_EQ(written, 0u);
  EXPECT_EQ(needed, all.size());
}

std::atomic<std::size_t> ramp_calls{0};
double counted_ramp(void* user, double x, double y) {
  ++ramp_calls;
  return ramp(user, x, y);
}

// A caller that does not ask for the count (a collector refusing more than it holds) gets its prefix, and
// the run stops soon after the buffer fills instead of querying the rest of the region.
TEST(ParallelQueryTest, WithoutNeededARunStopsOnceItsBufferIsFull) {
  for (const int kind : {0, 1}) {
    QueryParams q = region(QueryMode::kStable, kind);
    if (kind == 1) q.density.callback = counted_ramp;
    ramp_calls = 0;
    const std::vector<QueryPoint> all = run_parallel(q, 2, std_thread_runner());
    const std::size_t calls_for_all = ramp_calls.load();
    ParallelQuery pq;
    ASSERT_EQ(pq.init(2), Status::kOk);
    std::vector<QueryPoint> out(all.size() / 10);
    std::size_t written = 0;
    ramp_calls = 0;
    EXPECT_EQ(pq.run(Tileset::builtin(), q, out.data(), out.size(), &written, std_thread_runner()),
              Status::kBufferFull);
    EXPECT_EQ(written, out.size());
    EXPECT_EQ(std::memcmp(out.data(), all.data(), out.size() * sizeof(QueryPoint)), 0) << kind;
    // A tenth of the points, and the units the two workers had in hand: far from all of the calls.
    if (kind == 1) {
      EXPECT_LT(ramp_calls.load(), calls_for_all / 2) << calls_for_all;
    }
  }
}

TEST(ParallelQueryTest, ARegionEndingASliverPastATileSideIsServedWhole) {
  // The region's last row of tiles is 3e-322 high: a unit that thin would be refused as too narrow for its
  // distance from the origin, where the whole region is not; the run still returns the region's points.
  for (int kind = 0; kind < 2; ++kind) {  // counted and written in place, and through the scratch
    QueryParams q = region(QueryMode::kStable, kind);
    q.x0 = 0, q.x1 = 2.0001639128425146, q.y0 = -6, q.y1 = 3.1620201333839779e-322;
    q.origin_x = -9, q.origin_y = -12.125, q.tile_size = 2.953125, q.scale = 3000;
    for (QueryMode mode : {QueryMode::kStable, QueryMode::kSmooth}) {
      q.mode = mode;
      const std::vector<QueryPoint> whole = run_whole(q);
      ASSERT_GT(whole.size(), 1000u);
      EXPECT_TRUE(by_id(run_parallel(q, 2, sequential_runner())) == by_id(whole))
          << "kind " << kind << " mode " << int(mode);
    }
  }
}

TEST(ParallelQueryTest, ARegionStartingASliverPastATileSideIsServedWhole) {
  // Dense enough to cut tiles into halves of a unit each: the grid of halves starts at the tile's side, a
  // column wholly before the region, then one from x0 = -1.7e-154 to 0, a unit too narrow for its
  // distance from the origin; both join the column after them.
  QueryParams q = region(QueryMode::kSmooth, 1);
  q.x0 = -1.6781495144799912e-154, q.x1 = 0.6, q.y0 = 6.3240035215958458e-228, q.y1 = 0.75;
  q.origin_x = 1.625, q.origin_y = 0, q.tile_size = 3.359375, q.scale = 1878.0242804831666;
  q.density.callback_max = 2;  // 42,000 points per tile: halves of more than half a unit's
  const std::vector<QueryPoint> whole = run_whole(q);
  ASSERT_GT(whole.size(), 100u);
  EXPECT_TRUE(by_id(run_parallel(q, 2, sequential_runner())) == by_id(whole));
}

TEST(ParallelQueryTest, RefusesByName) {
  ParallelQuery pq;
  std::vector<QueryPoint> out(16);
  std::size_t written = 0;
  QueryProblem why;
  QueryParams q = region(QueryMode::kStable, 0);
  EXPECT_EQ(pq.run(Tileset::builtin(), q, out.data(), 16, &written, sequential_runner(), nullptr, &why),
            Status::kInvalidArgument);
  EXPECT_STREQ(why.parameter, "ParallelQuery::init");
  EXPECT_EQ(pq.init(0), Status::kInvalidArgument);
  EXPECT_EQ(pq.init(kMaxParallelWorkers + 1), Status::kInvalidArgument);
  ASSERT_EQ(pq.init(2), Status::kOk);
  EXPECT_EQ(pq.run(Tileset::builtin(), q, out.data(), 16, &written, TaskRunner{}, nullptr, &why),
            Status::kInvalidArgument);
  EXPECT_STREQ(why.parameter, "runner.run");
  EXPECT_EQ(why.kind, QueryProblem::Kind::kMissingArgument);
  // A runner that returns without running a task: said as what happened, not as a null argument.
  TaskRunner idle;
  idle.run = [](void*, void (*)(void*, std::size_t), void*, std::size_t) {};
  EXPECT_EQ(pq.run(Tileset::builtin(), q, out.data(), 16, &written, idle, nullptr, &why),
            Status::kInvalidArgument);
  EXPECT_EQ(why.kind, QueryProblem::Kind::kRunnerIncomplete);
  EXPECT_STREQ(why.parameter, "runner.run");
  EXPECT_EQ(why.value, 0);
  EXPECT_GE(why.limit, 1);  // the units it left
  char line[300];
  describe_query_problem(why, line, sizeof line);
  EXPECT_NE(std::strstr(line, "the task runner ('runner.run') returned without running any task"), nullptr)
      << line;
  EXPECT_EQ(std::strstr(line, "null"), nullptr) << line;
  EXPECT_EQ(pq.run(Tileset::builtin(), q, static_cast<QueryPoint*>(nullptr), 16, &written,
                   sequential_runner(), nullptr, &why),
            Status::kInvalidArgument);
  EXPECT_EQ(why.kind, QueryProblem::Kind::kMissingArgument);
  q.scale = -1;  // refused as query_points refuses it
  EXPECT_EQ(pq.run(Tileset::builtin(), q, out.data(), 16, &written, sequential_runner(), nullptr, &why),
            Status::kInvalidArgument);
  EXPECT_EQ(why.kind, QueryProblem::Kind::kNegative);
  EXPECT_STREQ(why.parameter, "scale");
  q = region(QueryMode::kStable, 0);
  q.x1 = q.x0;  // empty: no point, kOk
  EXPECT_EQ(pq.run(Tileset::builtin(), q, out.data(), 16, &written, sequential_runner()), Status::kOk);
  EXPECT_EQ(written, 0u);
}

/// Three classes over region(mode, 0): constants 1 : 2 : 4 of a seventh of the density (kind 0), or a
/// constant, the ramp by callback and the ramp by batch callback (kind 1).
ClassQueryParams three_classes(QueryMode mode, int kind) {
  ClassQueryParams c;
  c.query = region(mode, 0);
  c.class_count = 3;
  for (int k = 0; k < 3; ++k) c.classes[k].constant = double(1 << k) / 7;
  if (kind == 1) {
    QueryDensity& ramp_class = c.classes[1];
    ramp_class.kind = QueryDensity::Kind::kCallback;
    ramp_class.callback = ramp, ramp_class.callback_max = 0.7;
    c.classes[2] = ramp_class;
    c.classes[2].callback = nullptr;
    c.classes[2].batch_callback = [](void*, std::size_t n, const double* x, const double*, double* out) {
      for (std::size_t i = 0; i < n; ++i) out[i] = 0.1 + 0.05 * x[i];
    };
    c.classes[2].callback_max = 0.35;
  }
  return c;
}

/// A class query's points and classes, whole (resumed through a buffer) or in parallel.
struct Classed {
  std::vector<QueryPoint> points;
  std::vector<std::uint8_t> classes;
};
Classed run_classes_whole(const ClassQueryParams& q) {
  Classed r;
  std::vector<QueryPoint> out(1 << 16);
  std::vector<std::uint8_t> classes(out.size());
  QueryCursor cursor;
  for (;;) {
    std::size_t written = 0;
    const Status s =
        query_classes(Tileset::builtin(), q, out.data(), classes.data(), out.size(), &written, &cursor);
    EXPECT_TRUE(s == Status::kOk || s == Status::kBufferFull);
    r.points.insert(r.points.end(), out.begin(), out.begin() + written);
    r.classes.insert(r.classes.end(), classes.begin(), classes.begin() + written);
    if (s != Status::kBufferFull) return r;
  }
}
Classed run_classes_parallel(const ClassQueryParams& q, std::uint32_t workers, const TaskRunner& runner) {
  ParallelQuery pq;
  EXPECT_EQ(pq.init(workers), Status::kOk);
  Classed r;
  r.points.resize(1 << 21), r.classes.resize(1 << 21);
  std::size_t written = 0, needed = 0;
  EXPECT_EQ(pq.run(Tileset::builtin(), q, r.points.data(), r.classes.data(), r.points.size(), &written,
                   runner, &needed),
            Status::kOk);
  EXPECT_EQ(written, needed);
  r.points.resize(written), r.classes.resize(written);
  return r;
}

TEST(ParallelQueryTest, ClassesGiveTheSameBitsForAnyWorkerCountAndTheWholeQuerysPointsAndClasses) {
  // Constant classes are counted and written in place, varying ones go through the scratch.
  for (QueryMode mode : {QueryMode::kStable, QueryMode::kSmooth}) {
    for (int kind = 0; kind < 2; ++kind) {
      SCOPED_TRACE(::testing::Message() << "mode " << int(mode) << " kind " << kind);
      const ClassQueryParams q = three_classes(mode, kind);
      const Classed whole = run_classes_whole(q), one = run_classes_parallel(q, 1, sequential_runner());
      ASSERT_GT(one.points.size(), 100000u);
      for (const Classed& other : {run_classes_parallel(q, 2, std_thread_runner()),
                                   run_classes_parallel(q, 3, std_thread_runner())}) {
        EXPECT_TRUE(same_bits(one.points, other.points));
        EXPECT_TRUE(one.classes == other.classes);
      }
      // The whole query's points, each with its class.
      std::map<Key, std::uint8_t> class_of;
      for (std::size_t i = 0; i < whole.points.size(); ++i) {
        const PointId& id = whole.points[i].id;
        class_of[Key{id.tile_x, id.tile_y, id.rank, id.depth}] = whole.classes[i];
      }
      EXPECT_TRUE(by_id(one.points) == by_id(whole.points));
      std::size_t counts[3] = {};
      for (std::size_t i = 0; i < one.points.size(); ++i) {
        const PointId& id = one.points[i].id;
        ASSERT_EQ(one.classes[i], class_of.at(Key{id.tile_x, id.tile_y, id.rank, id.depth}));
        ++counts[one.classes[i]];
      }
      for (std::size_t c : counts) EXPECT_GT(c, 10000u);
      // Into the compact output: the records' points, in their order, with the same classes.
      ParallelQuery pq;
      ASSERT_EQ(pq.init(2), Status::kOk);
      std::vector<float> xy(2 * one.points.size());
      std::vector<std::uint8_t> classes(one.points.size());
      std::size_t written = 0;
      ASSERT_EQ(pq.run(Tileset::builtin(), q, CompactPoints{xy.data(), nullptr}, classes.data(),
                       classes.size(), &written, std_thread_runner()),
                Status::kOk);
      ASSERT_EQ(written, one.points.size());
      EXPECT_TRUE(classes == one.classes);
      for (std::size_t i = 0; i < written; ++i)
        ASSERT_LE(std::fabs(xy[2 * i] - one.points[i].x), std::ldexp(std::fabs(one.points[i].x) + 1, -21));
    }
  }
}

TEST(ParallelQueryTest, ClassesKeepTheWholeQuerysOrderWhereTilesAreWhole) {
  for (QueryMode mode : {QueryMode::kStable, QueryMode::kSmooth}) {
    for (int kind = 0; kind < 2; ++kind) {
      ClassQueryParams q = three_classes(mode, kind);
      q.query.scale = 6000;  // runs of one tile (varying classes) or of many (constant ones), none cut
      const Classed whole = run_classes_whole(q), two = run_classes_parallel(q, 2, std_thread_runner());
      ASSERT_GT(whole.points.size(), 20000u);
      EXPECT_TRUE(same_bits(two.points, whole.points)) << "mode " << int(mode) << " kind " << kind;
      EXPECT_TRUE(two.classes == whole.classes) << "mode " << int(mode) << " kind " << kind;
    }
  }
}

TEST(ParallelQueryTest, ClassesAreRefusedByName) {
  ParallelQuery pq;
  ASSERT_EQ(pq.init(2), Status::kOk);
  std::vector<QueryPoint> out(16);
  std::uint8_t classes[16];
  std::size_t written = 0;
  QueryProblem why;
  ClassQueryParams q = three_classes(QueryMode::kStable, 1);
  q.class_count = 0;
  EXPECT_EQ(
      pq.run(Tileset::builtin(), q, out.data(), classes, 16, &written, sequential_runner(), nullptr, &why),
      Status::kInvalidArgument);
  EXPECT_EQ(why.kind, QueryProblem::Kind::kBadClassCount);
  q.class_count = 3;
  q.classes[1].callback_max = -1;
  EXPECT_EQ(
      pq.run(Tileset::builtin(), q, out.data(), classes, 16, &written, sequential_runner(), nullptr, &why),
      Status::kInvalidArgument);
  EXPECT_STREQ(why.parameter, "classes[1].callback_max");
  q.classes[1].callback_max = 0.7;
  EXPECT_EQ(
      pq.run(Tileset::builtin(), q, out.data(), nullptr, 16, &written, sequential_runner(), nullptr, &why),
      Status::kInvalidArgument);
  EXPECT_EQ(why.kind, QueryProblem::Kind::kMissingArgument);
  // A short buffer: its prefix, and the count.
  const Classed all = run_classes_parallel(q, 2, std_thread_runner());
  std::size_t needed = 0;
  EXPECT_EQ(pq.run(Tileset::builtin(), q, out.data(), classes, 16, &written, std_thread_runner(), &needed),
            Status::kBufferFull);
  EXPECT_EQ(written, 16u);
  EXPECT_EQ(needed, all.points.size());
  EXPECT_TRUE(same_bits(out, std::vector<QueryPoint>(all.points.begin(), all.points.begin() + 16)));
  EXPECT_EQ(std::memcmp(classes, all.classes.data(), 16), 0);
}

TEST(ParallelQueryTest, ARunAllocatesNothing) {
  ParallelQuery pq;
  ASSERT_EQ(pq.init(2), Status::kOk);
  std::vector<QueryPoint> out(1 << 21);
  (void)Tileset::builtin();
  for (int kind = 0; kind < 2; ++kind) {  // counted and written in place, and through the scratch
    const QueryParams q = region(QueryMode::kSmooth, kind);
    std::size_t written = 0;
    const long before = testing::allocations();
    EXPECT_EQ(pq.run(Tileset::builtin(), q, out.data(), out.size(), &written, sequential_runner()),
              Status::kOk);
    EXPECT_EQ(testing::allocations(), before);
    EXPECT_GT(written, 100000u);
  }
  std::vector<std::uint8_t> classes(out.size());
  for (int kind = 0; kind < 2; ++kind) {
    const ClassQueryParams q = three_classes(QueryMode::kSmooth, kind);
    std::size_t written = 0;
    const long before = testing::allocations();
    EXPECT_EQ(
        pq.run(Tileset::builtin(), q, out.data(), classes.data(), out.size(), &written, sequential_runner()),
        Status::kOk);
    EXPECT_EQ(testing::allocations(), before);
    EXPECT_GT(written, 100000u);
  }
}

}  // namespace
}  // namespace kdm
