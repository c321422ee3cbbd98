// kdm._kdm.query: a runtime query run to completion (by tools::query_all's rules, as `kdm query` runs it)
// with the GIL released, into memory numpy then views: the runtime's own point records (positions, tile
// ids and ranks are strided views of them, nothing is converted) and the points' levels.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "kdm/runtime/class_query.h"
#include "kdm/runtime/compact_query.h"
#include "kdm/runtime/parallel_query.h"
#include "query_density.h"
#include "runtime_query.h"

namespace kdm::python {
namespace {

/// A refused query's parameters as Python's keyword arguments.
constexpr QueryParameterNames kKeywordNames{"scale=", "tile_size=", "origin="};

using Rect = std::array<double, 4>;

/// Four finite numbers, and unless `allow_empty` (a query's region: no points when x1 <= x0 or y1 <= y0, as
/// in C and C++) x0 < x1 and y0 < y1.
void check_rect(const char* name, const Rect& r, bool allow_empty = false) {
  for (double v : r)
    if (!std::isfinite(v)) throw std::invalid_argument(std::string(name) + " must be four finite numbers");
  if (!allow_empty && !(r[2] > r[0] && r[3] > r[1]))
    throw std::invalid_argument(std::string(name) + " is empty or inverted (needs x0 < x1 and y0 < y1)");
}

/// Where a query's image lies: `density_rect`, by default the region queried. An empty region has no points
/// and its image is never read: the unit square stands in for it.
Rect image_rect(const Rect& rect, const std::optional<Rect>& density_rect) {
  if (density_rect) return *density_rect;
  return rect[2] > rect[0] && rect[3] > rect[1] ? rect : Rect{0, 0, 1, 1};
}

/// A query's mode from the package's "stable" or "smooth", with "/together" for QueryParams::glide_together.
void set_mode(QueryParams& q, const std::string& mode) {
  const std::size_t slash = mode.find('/');
  const std::string name = mode.substr(0, slash), rest = slash == std::string::npos ? "" : mode.substr(slash);
  if ((name != "stable" && name != "smooth") || (!rest.empty() && rest != "/together"))
    throw std::invalid_argument("mode must be 'stable' or 'smooth', got '" + mode + "'");
  q.mode = name == "smooth" ? QueryMode::kSmooth : QueryMode::kStable;
  q.glide_together = !rest.empty();
}

/// Points and their levels in memory numpy arrays view: the runtime's QueryPoint records themselves (no
/// conversion; `xy`, `tile` and `rank` are strided views of them) and a level per point. Plain malloc
/// memory, so a buffer no array views yet grows by realloc (pages moved, not copied); once arrays view it,
/// it never moves (an `out=` result with too little room is copied into a new buffer instead).
struct Buffer {
  QueryPoint* points = nullptr;
  std::uint32_t* levels = nullptr;
  std::size_t capacity = 0;
  bool shared = false;  ///< numpy arrays view it: never realloc or free it here

  Buffer() = default;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  ~Buffer() {
    if (!shared) std::free(points), std::free(levels);
  }

  /// Room for at least `wanted` points, keeping the first `kept`. Throws std::bad_alloc.
  void reserve(std::size_t wanted, std::size_t kept) {
    if (wanted <= capacity) return;
    const std::size_t grown = std::max(wanted, 2 * capacity);
    if (shared) {  // arrays view the old memory: copy what is kept into new memory
      auto* p = static_cast<QueryPoint*>(std::malloc(grown * sizeof(QueryPoint)));
      auto* l = static_cast<std::uint32_t*>(std::malloc(grown * sizeof(std::uint32_t)));
      if (!p || !l) std::free(p), std::free(l), throw std::bad_alloc();
      if (kept) std::memcpy(p, points, kept * sizeof(QueryPoint)), std::memcpy(l, levels, kept * 4);
      points = p, levels = l, shared = false;
    } else {
      void* p = std::realloc(points, grown * sizeof(QueryPoint));
      if (!p) throw std::bad_alloc();
      points = static_cast<QueryPoint*>(p);
      void* l = std::realloc(levels, grown * sizeof(std::uint32_t));
      if (!l) throw std::bad_alloc();
      levels = static_cast<std::uint32_t*>(l);
    }
    capacity = grown;
  }
};

/// The C++ side of an earlier result's `storage`: the buffer its arrays view, if it is one of ours.
struct Storage {
  QueryPoint* points = nullptr;
  std::uint32_t* levels = nullptr;
  std::size_t capacity = 0;
  explicit Storage(const py::object& storage) {
    if (storage.is_none() || !py::isinstance<py::tuple>(storage)) return;
    const py::tuple t = storage.cast<py::tuple>();
    if (t.size() != 2 || !py::isinstance<py::array>(t[0]) ||
        !py::isinstance<py::array_t<std::uint32_t>>(t[1]))
      return;
    py::array records = t[0].cast<py::array>();
    py::array_t<std::uint32_t> levels_array = t[1].cast<py::array_t<std::uint32_t>>();
    // Written through plain pointers: only whole, forward, contiguous arrays (not a reversed or strided
    // view).
    const auto contiguous = [](const py::array& a) { return (a.flags() & py::array::c_style) != 0; };
    if (records.itemsize() != sizeof(QueryPoint) || records.ndim() != 1 || !records.writeable() ||
        !levels_array.writeable() || levels_array.ndim() != 1 || levels_array.shape(0) != records.shape(0) ||
        !contiguous(records) || !contiguous(levels_array))
      return;
    points = static_cast<QueryPoint*>(records.mutable_data());
    levels = levels_array.mutable_data();
    capacity = static_cast<std::size_t>(records.shape(0));
  }
};

constexpr std::size_t kChunk = std::size_t(1) << 14;

/// Fills levels[from .. end) with the levels of points[from .. end). Points come tile by tile, ranks
/// ascending: a run of one tile's points takes its levels a level at a time, the run's end at each level
/// found by binary search (ranks ascend) and the levels filled.
void fill_levels(const Tileset& tiles, const QueryPoint* points, std::uint32_t* levels, std::size_t from,
                 std::size_t end) {
  const Tile* t = nullptr;
  PointId tile{std::numeric_limits<std::int64_t>::min(), 0, 0, 0};
  for (std::size_t i = from; i < end;) {
    const PointId& id = points[i].id;
    if (!t || id.tile_x != tile.tile_x || id.tile_y != tile.tile_y || id.depth != tile.depth)
      tile = id, t = tile_of(tiles, id);
    std::size_t run = i + 1;
    for (std::uint32_t last = id.rank; run < end; last = points[run++].id.rank) {
      const PointId& next = points[run].id;
      if (next.tile_x != tile.tile_x || next.tile_y != tile.tile_y || next.depth != tile.depth ||
          next.rank <= last)
        break;
    }
    for (std::uint32_t level = t->level_of(id.rank); i < run; ++level) {
      const bool last_level = level + 1 >= t->level_end.size();
      const std::size_t upto =
          last_level ? run
                     : static_cast<std::size_t>(std::partition_point(points + i, points + run,
                                                                     [&](const QueryPoint& p) {
                                                                       return p.id.rank < t->level_end[level];
                                                                     }) -
                                                points);
      std::fill(levels + i, levels + upto, level);
      i = upto;
    }
  }
}

/// Runs the query to completion (the rules of tools::query_all) into `buffer`, a chunk at a time so that
/// each chunk's levels are found while its points are still in cache. Returns the count. Call without
/// the GIL.
std::size_t collect(const Tileset& tiles, const QueryParams& q, Buffer& buffer) {
  QueryCursor cursor;
  std::size_t m = 0;
  for (;;) {
    if (m == buffer.capacity) buffer.reserve(m + kChunk, m);
    std::size_t written = 0;
    QueryProblem problem;
    const Status s = query_points(tiles, q, buffer.points + m, std::min(kChunk, buffer.capacity - m),
                                  &written, &cursor, &problem);
    fill_levels(tiles, buffer.points, buffer.levels, m, m + written);
    m += written;
    if (m > tools::kMaxCollectedPoints)  // 1 GiB of points: stop before memory runs out
      throw std::invalid_argument(
          "the query emits more than 2^25 points; lower the scale or split the region");
    if (s == Status::kOk) return m;
    if (s != Status::kBufferFull)
      throw std::invalid_argument("query: " + tools::describe(problem, kKeywordNames));
  }
}

/// numpy's view of a QueryPoint record (x, y, tile_x, tile_y, rank, depth; 40 bytes).
py::dtype record_dtype() {
  static_assert(offsetof(QueryPoint, y) == 8 && offsetof(QueryPoint, id) == 16 &&
                    offsetof(PointId, tile_y) == 8 && offsetof(PointId, rank) == 16 &&
                    offsetof(PointId, depth) == 20,
                "the record layout numpy is told");
  return py::dtype::from_args(py::dict(
      py::arg("names") = py::make_tuple("x", "y", "tile_x", "tile_y", "rank", "depth"),
      py::arg("formats") = py::make_tuple("<f8", "<f8", "<i8", "<i8", "<u4", "<u4"),
      py::arg("offsets") = py::make_tuple(0, 8, 16, 24, 32, 36), py::arg("itemsize") = sizeof(QueryPoint)));
}

/// The result: the records (m,), xy (m×2) and tile (m×2) and rank views of them, level (m,), then the
/// storage they are the first rows of (for a later query's `storage`).
py::tuple result(std::size_t m, Buffer& buffer, const py::object& storage) {
  py::tuple full;
  if (!buffer.shared) {  // new memory: numpy takes it over
    buffer.shared = true;
    py::capsule points_owner(buffer.points, [](void* p) { std::free(p); });
    py::capsule levels_owner(buffer.levels, [](void* p) { std::free(p); });
    const auto capacity = static_cast<py::ssize_t>(buffer.capacity);
    full = py::make_tuple(
        py::array(record_dtype(), {capacity}, {py::ssize_t(sizeof(QueryPoint))}, buffer.points, points_owner),
        py::array_t<std::uint32_t>({capacity}, buffer.levels, levels_owner));
  } else {
    full = storage.cast<py::tuple>();
  }
  const py::array records = full[0].cast<py::array>()[py::slice(0, static_cast<py::ssize_t>(m), 1)];
  const py::array levels = full[1].cast<py::array>()[py::slice(0, static_cast<py::ssize_t>(m), 1)];
  const auto rows = static_cast<py::ssize_t>(m), stride = static_cast<py::ssize_t>(sizeof(QueryPoint));
  auto* base = reinterpret_cast<char*>(buffer.points);
  py::array_t<double> xy({rows, py::ssize_t(2)}, {stride, py::ssize_t(8)}, reinterpret_cast<double*>(base),
                         records);
  py::array_t<std::int64_t> tile({rows, py::ssize_t(2)}, {stride, py::ssize_t(8)},
                                 reinterpret_cast<std::int64_t*>(base + 16), records);
  py::array_t<std::uint32_t> rank({rows}, {stride}, reinterpret_cast<std::uint32_t*>(base + 32), records);
  return py::make_tuple(records, xy, tile, rank, levels, full);
}

/// `threads` as positions() takes it: 0 (one query) or 1 … kMaxParallelWorkers.
void check_threads(int threads) {
  if (threads < 0 || threads > int(kMaxParallelWorkers))
    throw std::invalid_argument("threads must be 1 to " + std::to_string(kMaxParallelWorkers) + ", got " +
                                std::to_string(threads));
}

/// A density prepared once for many queries (kdm.DensityMap): its spec stretched over `rect`, the max-mip
/// of an image built and its values checked, so that a query of a chunk costs what the chunk does, not
/// what the map does (a 1,024² array took 7 ms a query, converted and mipped each time).
/// A set of class maps' running sums, built once (tools::read_images_by_sums' rule, so the same points):
/// the maps by their serials, the sums a copy of their texels, so that no map need outlive it.
struct ClassSumsCache {
  std::vector<std::uint64_t> serials;
  ClassImageSums sums;
  bool used = false;  ///< whether the rule reads these classes by their sums
};

struct PreparedDensity {
  PreparedDensity(std::shared_ptr<const tools::DensitySpec> s, const Rect& r) : spec(std::move(s)), rect(r) {
    if (spec->kind != tools::DensitySpec::Kind::kConstant) check_rect("rect", rect);
    density = std::make_unique<SpecDensity>(*spec, rect.data());
  }
  std::shared_ptr<const tools::DensitySpec> spec;  ///< what `density` points into
  Rect rect;
  std::unique_ptr<SpecDensity> density;
  const std::uint64_t serial = next_serial();  ///< names it in a ClassSumsCache
  /// The last set of classes this map led (as class 0), with their sums: classes of small maps built
  /// their sums at every query (1.4 ms for three 512² maps, where the chunk itself took 0.1).
  mutable std::shared_ptr<ClassSumsCache> class_sums;

 private:
  static std::uint64_t next_serial() {
    static std::atomic<std::uint64_t> count{0};
    return ++count;
  }
};

/// `ready` as a PreparedDensity, or null for None.
const PreparedDensity* ready_density(const py::object& ready) {
  return ready.is_none() ? nullptr : ready.cast<const PreparedDensity*>();
}

/// A query's parameters and the density objects they point at (kept alive with them).
struct PreparedQuery {
  QueryParams q;
  std::unique_ptr<SpecDensity> from_spec;
  std::unique_ptr<CallableDensity> from_callable;
};

void prepare(PreparedQuery& p, const Rect& rect, double scale, const tools::DensitySpec* spec,
             const PreparedDensity* ready, py::object callable, bool vectorized, py::object bounds,
             std::optional<Rect> density_rect, std::optional<double> density_max, double tile_size,
             const std::string& mode, const std::array<double, 2>& origin, int& threads) {
  if (ready) spec = ready->spec.get();
  check_threads(threads);
  check_rect("rect", rect, true);
  QueryParams& q = p.q;
  q.x0 = rect[0], q.y0 = rect[1], q.x1 = rect[2], q.y1 = rect[3];
  q.origin_x = origin[0], q.origin_y = origin[1];
  q.tile_size = tile_size;
  q.scale = scale;
  set_mode(q, mode);
  const bool call = !callable.is_none();
  if (call == (spec != nullptr)) throw std::invalid_argument("give one density: a spec or a callable");
  if (density_rect && (call || spec->kind == tools::DensitySpec::Kind::kConstant))
    throw std::invalid_argument("density_rect needs an image, an array or a test map density");
  if (density_max && !call) throw std::invalid_argument("density_max is for a callable density only");
  if (vectorized && !call) throw std::invalid_argument("vectorized is for a callable density only");
  if (!bounds.is_none() && !call)
    throw std::invalid_argument("density_bounds is for a callable density only");
  if (density_rect) check_rect("density_rect", *density_rect);
  if (call) {
    if (!density_max)
      throw std::invalid_argument("a callable density needs density_max, an upper bound of its values");
    check_number("density_max", *density_max, 0, false);
    p.from_callable =
        std::make_unique<CallableDensity>(std::move(callable), *density_max, std::move(bounds), vectorized);
    q.density = p.from_callable->density;
    threads = 0;  // a Python function runs on one thread at a time (the GIL): one query
  } else if (ready) {
    if (density_rect) throw std::invalid_argument("density_rect is the DensityMap's own: give it no other");
    q.density = ready->density->density;
  } else {
    const Rect r = image_rect(rect, density_rect);
    p.from_spec = std::make_unique<SpecDensity>(*spec, r.data());
    q.density = p.from_spec->density;
  }
}

/// Arrays of malloc'd memory that numpy takes over once filled: positions and, if asked, keys.
struct CompactBuffer {
  float* xy = nullptr;
  std::uint64_t* keys = nullptr;
  std::size_t capacity = 0;
  bool with_keys = false;
  CompactBuffer() = default;
  CompactBuffer(const CompactBuffer&) = delete;
  CompactBuffer& operator=(const CompactBuffer&) = delete;
  ~CompactBuffer() { std::free(xy), std::free(keys); }
  void reserve(std::size_t wanted) {  // keeps the contents; throws std::bad_alloc
    if (wanted <= capacity) return;
    const std::size_t grown = std::max(wanted, 2 * capacity);
    auto* x = static_cast<float*>(std::realloc(xy, std::max<std::size_t>(grown, 1) * 2 * sizeof(float)));
    if (!x) throw std::bad_alloc();
    xy = x;
    if (with_keys) {
      auto* k =
          static_cast<std::uint64_t*>(std::realloc(keys, std::max<std::size_t>(grown, 1) * sizeof *keys));
      if (!k) throw std::bad_alloc();
      keys = k;
    }
    capacity = grown;
  }
  CompactPoints at(std::size_t i) const { return CompactPoints{xy + 2 * i, with_keys ? keys + i : nullptr}; }
};

[[noreturn]] void refused(const QueryProblem& problem) {
  throw std::invalid_argument("query: " + tools::describe(problem, kKeywordNames));
}

void check_collected(std::size_t m) {
  if (m > tools::kMaxCollectedPoints)
    throw std::invalid_argument("the query emits more than 2^25 points; lower the scale or split the region");
}

/// numpy takes over `buffer`'s first m positions and keys: (m × 2 float32, m uint64 or None).
py::tuple take_compact(CompactBuffer& buffer, std::size_t m) {
  const auto rows = static_cast<py::ssize_t>(m);
  float* xy = buffer.xy;
  std::uint64_t* key = buffer.keys;
  const bool keys = buffer.with_keys;
  buffer.xy = nullptr, buffer.keys = nullptr;
  py::capsule xy_owner(xy, [](void* p) { std::free(p); });
  py::array_t<float> xy_array({rows, py::ssize_t(2)}, xy, xy_owner);
  if (!keys) return py::make_tuple(xy_array, py::none());
  py::capsule keys_owner(key, [](void* p) { std::free(p); });
  return py::make_tuple(xy_array, py::array_t<std::uint64_t>({rows}, key, keys_owner));
}

/// An upper bound of density `d` over the query's rectangle.
double density_bound(const QueryDensity& d, const QueryParams& q) {
  switch (d.kind) {
    case QueryDensity::Kind::kConstant:
      return std::max(d.constant, 0.0);
    case QueryDensity::Kind::kImage:
      return d.image->max_over(q.x0, q.y0, q.x1, q.y1);
    case QueryDensity::Kind::kCallback:
      break;
  }
  return d.callback_max;
}

/// The largest value density `d` takes anywhere (an image's over its whole rectangle, a callback's bound).
double density_peak(const QueryDensity& d) {
  if (d.kind == QueryDensity::Kind::kImage)
    return d.image->max_over(d.image->x0, d.image->y0, d.image->x1, d.image->y1);
  return density_bound(d, QueryParams{});
}

/// Warns (UserWarning) as kdm query does where the tile size is too small for the density's peak,
/// `peak`, unless the region is empty. `level` frames up is the caller's line (the package's methods call
/// these functions one or two frames below it).
void warn_tile_size(const Tileset& set, double peak, const QueryParams& q, int level) {
  if (!(q.x1 > q.x0 && q.y1 > q.y0)) return;
  const std::string text =
      tools::tile_size_warning(tile_size_advice(set, peak, q.scale, q.tile_size), "tile_size");
  if (!text.empty() && PyErr_WarnEx(PyExc_UserWarning, text.c_str(), level) < 0)
    throw py::error_already_set();
}

/// Room for a parallel query's points at density `rho` (a bound), with a margin for smooth mode's glide;
/// ParallelQuery then says exactly what it needs if that was short.
std::size_t room_for(double rho, const QueryParams& q) {
  const double bound = std::max(rho, 0.0) * (q.x1 - q.x0) * (q.y1 - q.y0) * q.scale * 1.05 + 4096;
  return std::size_t(std::min(bound, double(tools::kMaxCollectedPoints) + 1));
}

/// Fills `buffer` by a ParallelQuery of `threads` workers, the GIL released: run(parallel, written,
/// needed, problem) writes into buffer.points (with room first for `room` points, then for what the run
/// said it needs; grow(capacity) sizes what is kept beside them). Returns the count; a refusal raises
/// ValueError.
template <class Grow, class Run>
std::size_t collect_parallel(Buffer& buffer, int threads, std::size_t room, Grow&& grow, Run&& run) {
  ParallelQuery parallel;
  if (parallel.init(static_cast<std::uint32_t>(threads)) != Status::kOk) throw std::bad_alloc();
  buffer.reserve(std::max<std::size_t>(room, 1), 0);
  grow(buffer.capacity);
  for (;;) {
    std::size_t m = 0, needed = 0;
    QueryProblem problem;
    Status s;
    {
      py::gil_scoped_release release;  // a callable density takes it back at each call
      s = run(parallel, &m, &needed, &problem);
    }
    if (s == Status::kOk) {
      check_collected(m);
      return m;
    }
    if (s != Status::kBufferFull || needed <= buffer.capacity) refused(problem);
    check_collected(needed);
    buffer.reserve(needed, 0);
    grow(buffer.capacity);
  }
}

py::tuple query(const TilesetHandle& handle, const Rect& rect, double scale, const tools::DensitySpec* spec,
                const py::object& ready, py::object callable, bool vectorized, py::object bounds,
                std::optional<Rect> density_rect, std::optional<double> density_max, double tile_size,
                const std::string& mode, const std::array<double, 2>& origin, const py::object& storage,
                int threads) {
  PreparedQuery prepared;
  prepare(prepared, rect, scale, spec, ready_density(ready), std::move(callable), vectorized,
          std::move(bounds), density_rect, density_max, tile_size, mode, origin, threads);
  const QueryParams& q = prepared.q;
  tools::check_before_collecting(*handle.set, q, kKeywordNames);
  warn_tile_size(*handle.set, density_peak(q.density), q, 2);
  const std::unique_ptr<CallableDensity>& from_callable = prepared.from_callable;
  const Storage out(storage);
  Buffer buffer;  // an earlier result's memory while it has room, else new memory
  if (out.capacity) buffer.points = out.points, buffer.levels = out.levels, buffer.capacity = out.capacity;
  buffer.shared = out.capacity > 0;
  std::size_t m = 0;
  if (threads == 0) {
    py::gil_scoped_release release;  // a callable density takes it back at each call
    m = collect(*handle.set, q, buffer);
  } else {
    m = collect_parallel(
        buffer, threads, room_for(density_bound(q.density, q), q), [](std::size_t) {},
        [&](ParallelQuery& parallel, std::size_t* written, std::size_t* needed, QueryProblem* problem) {
          return parallel.run(*handle.set, q, buffer.points, buffer.capacity, written, std_thread_runner(),
                              needed, problem);
        });
    fill_levels(*handle.set, buffer.points, buffer.levels, 0, m);
  }
  if (from_callable) from_callable->rethrow();
  return result(m, buffer, storage);
}

/// Fills `buffer` with a compact query's points, the GIL released (a callable density takes it back at each
/// call), and returns their count: with `threads` 0 by serial(at, written, cursor, problem), which writes
/// from slot `at` on, resumed until done; else by parallel(query, written, needed, problem) on a
/// ParallelQuery of `threads` workers, with room first for `wanted` points, then for what it needed.
/// `grow(capacity)` sizes what is kept beside the points (classes). A refusal raises ValueError.
template <class Serial, class Parallel, class Grow>
std::size_t fill_compact(CompactBuffer& buffer, int threads, std::size_t wanted, Serial&& serial,
                         Parallel&& parallel, Grow&& grow) {
  py::gil_scoped_release release;
  QueryProblem problem;
  std::size_t m = 0;
  if (threads == 0) {
    QueryCursor cursor;
    for (;;) {
      buffer.reserve(m + kChunk);
      grow(buffer.capacity);
      std::size_t written = 0;
      const Status s = serial(m, &written, &cursor, &problem);
      m += written;
      check_collected(m);
      if (s == Status::kOk) return m;
      if (s != Status::kBufferFull) refused(problem);
    }
  }
  ParallelQuery query;
  if (query.init(static_cast<std::uint32_t>(threads)) != Status::kOk) throw std::bad_alloc();
  for (;;) {
    buffer.reserve(wanted);
    grow(buffer.capacity);
    // Room for more than may be collected: a full buffer is refusal enough, and the run stops there.
    const bool capped = wanted > tools::kMaxCollectedPoints;
    std::size_t needed = 0;
    const Status s = parallel(query, &m, capped ? nullptr : &needed, &problem);
    if (capped && s == Status::kBufferFull) check_collected(wanted);
    check_collected(std::max(m, needed));
    if (s == Status::kOk) return m;
    if (s != Status::kBufferFull) refused(problem);
    wanted = needed;
  }
}

/// The compact query (kdm/runtime/compact_query.h) into new arrays, with the GIL released: positions
/// (m × 2 float32, relative to the origin) and, with `keys`, each point's 64-bit key (else None). `threads`
/// 0 runs one query (query_points' order); 1 or more a ParallelQuery on as many std::threads (the same
/// bits for any count, in query_points' order where no tile is cut into units).
py::tuple positions(const TilesetHandle& handle, const Rect& rect, double scale,
                    const tools::DensitySpec* spec, const py::object& ready, py::object callable,
                    bool vectorized, py::object bounds, std::optional<Rect> density_rect,
                    std::optional<double> density_max, double tile_size, const std::string& mode,
                    const std::array<double, 2>& origin, bool keys, int threads) {
  PreparedQuery prepared;
  prepare(prepared, rect, scale, spec, ready_density(ready), std::move(callable), vectorized,
          std::move(bounds), density_rect, density_max, tile_size, mode, origin, threads);
  const QueryParams& q = prepared.q;
  tools::check_before_collecting(*handle.set, q, kKeywordNames);
  warn_tile_size(*handle.set, density_peak(q.density), q, 2);
  CompactBuffer buffer;
  buffer.with_keys = keys;
  const std::size_t m = fill_compact(
      buffer, threads, room_for(density_bound(q.density, q), q),
      [&](std::size_t at, std::size_t* written, QueryCursor* cursor, QueryProblem* problem) {
        return query_points_compact(*handle.set, q, buffer.at(at), buffer.capacity - at, written, cursor,
                                    problem);
      },
      [&](ParallelQuery& parallel, std::size_t* written, std::size_t* needed, QueryProblem* problem) {
        return parallel.run(*handle.set, q, buffer.at(0), buffer.capacity, written, std_thread_runner(),
                            needed, problem);
      },
      [](std::size_t) {});
  if (prepared.from_callable) prepared.from_callable->rethrow();
  return take_compact(buffer, m);
}

/// A class query's parameters from Python's arguments, with the densities they point into.
struct PreparedClasses {
  ClassQueryParams q;
  std::vector<std::unique_ptr<SpecDensity>> densities;
  std::vector<std::unique_ptr<CallableDensity>> callables;
  ClassImageSums sums;  ///< images on one grid: their running sums (tools::read_images_by_sums)
  std::shared_ptr<ClassSumsCache> class_sums;  ///< or the DensityMaps' own, kept for the query's time
  /// Raises the first exception a class's callable raised, in class order. Call with the GIL held.
  void rethrow() {
    for (const std::unique_ptr<CallableDensity>& c : callables) c->rethrow();
  }
};

/// specs[k] where callables[k] is None (a density of its own), else a constant standing in for the callable.
std::vector<const tools::DensitySpec*> image_specs(const std::vector<const tools::DensitySpec*>& specs,
                                                   const std::vector<py::object>& callables) {
  static const tools::DensitySpec callable;
  std::vector<const tools::DensitySpec*> out;
  for (std::size_t k = 0; k < specs.size(); ++k)
    out.push_back(k < callables.size() && !callables[k].is_none() ? &callable
                  : specs[k]                                      ? specs[k]
                                                                  : &callable);
  return out;
}

/// A class's density is specs[k], or ready[k] (a PreparedDensity, its spec specs[k]) where that is not None,
/// or callables[k] where that is not None (bounded by maxima[k]).
void prepare_classes(PreparedClasses& prepared, const Rect& rect, double scale,
                     const std::vector<const tools::DensitySpec*>& specs,
                     const std::vector<py::object>& ready, const std::vector<py::object>& callables,
                     const std::vector<double>& maxima, const std::vector<py::object>& bounds,
                     bool vectorized, std::optional<Rect> density_rect, double tile_size,
                     const std::string& mode, const std::array<double, 2>& origin, int& threads) {
  check_threads(threads);
  check_rect("rect", rect, true);
  if (specs.empty() || specs.size() > kMaxQueryClasses)
    throw std::invalid_argument("classes must hold 1 to " + std::to_string(kMaxQueryClasses) +
                                " densities, got " + std::to_string(specs.size()));
  if (callables.size() != specs.size() || maxima.size() != specs.size() || bounds.size() != specs.size() ||
      ready.size() != specs.size())
    throw std::invalid_argument(
        "classes: one callable (or None), one maximum, one bounds (or None) and one map (or None) per class");
  const bool any_ready =
      std::any_of(ready.begin(), ready.end(), [](const py::object& r) { return !r.is_none(); });
  if (any_ready && density_rect)
    throw std::invalid_argument("density_rect is the DensityMaps' own: give it no other");
  std::optional<Rect> map_rect;  // the DensityMaps' images, all over one rectangle
  for (const py::object& r : ready)
    if (const PreparedDensity* d = ready_density(r);
        d && d->spec->kind != tools::DensitySpec::Kind::kConstant) {
      if (map_rect && *map_rect != d->rect)
        throw std::invalid_argument("class DensityMaps must all lie over one rect, as class images do");
      map_rect = d->rect;
    }
  if (density_rect) check_rect("density_rect", *density_rect);
  const auto [i, j] = tools::images_of_different_shapes(image_specs(specs, callables));
  if (j >= 0) {
    auto shape = [&](int k) {
      return "classes[" + std::to_string(k) + "] is " + std::to_string(specs[k]->width) + "x" +
             std::to_string(specs[k]->height);
    };
    throw std::invalid_argument(
        "class images must have one shape (width to height), each stretched over the "
        "same rectangle: " +
        shape(i) + ", " + shape(j));
  }
  const Rect r = image_rect(rect, density_rect);
  ClassQueryParams& q = prepared.q;
  q.query.x0 = rect[0], q.query.y0 = rect[1], q.query.x1 = rect[2], q.query.y1 = rect[3];
  q.query.origin_x = origin[0], q.query.origin_y = origin[1];
  q.query.tile_size = tile_size;
  q.query.scale = scale;
  set_mode(q.query, mode);
  q.class_count = static_cast<std::uint32_t>(specs.size());
  if (vectorized &&
      std::all_of(callables.begin(), callables.end(), [](const py::object& f) { return f.is_none(); }))
    throw std::invalid_argument("vectorized is for callable classes only");
  for (std::size_t k = 0; k < specs.size(); ++k) {
    const std::string name = "classes[" + std::to_string(k) + "]";
    if (!callables[k].is_none()) {
      if (!(maxima[k] >= 0 && maxima[k] < std::numeric_limits<double>::infinity()))
        throw std::invalid_argument(name + ": a callable's density_max must be finite and >= 0");
      prepared.callables.push_back(
          std::make_unique<CallableDensity>(callables[k], maxima[k], bounds[k], vectorized, name));
      q.classes[k] = prepared.callables.back()->density;
      threads = 0;  // Python functions run one at a time (the GIL): one query
      continue;
    }
    if (const PreparedDensity* d = ready_density(ready[k])) {
      q.classes[k] = d->density->density;
      continue;
    }
    if (!specs[k]) throw std::invalid_argument(name + " is not a density");
    prepared.densities.push_back(std::make_unique<SpecDensity>(*specs[k], (map_rect ? *map_rect : r).data()));
    q.classes[k] = prepared.densities.back()->density;
  }
  // Classes that are all DensityMaps keep their sums with the first map (the GIL is held here; a query
  // running on another thread keeps its own reference to the sums it reads).
  const PreparedDensity* first = ready_density(ready[0]);
  std::vector<std::uint64_t> serials;
  for (std::size_t k = 0; k < ready.size() && first; ++k)
    if (const PreparedDensity* d = ready_density(ready[k])) serials.push_back(d->serial);
  if (!first || serials.size() != ready.size()) {
    tools::read_images_by_sums(q, prepared.sums);
    return;
  }
  std::shared_ptr<ClassSumsCache> cache = first->class_sums;
  if (!cache || cache->serials != serials) {
    cache = std::make_shared<ClassSumsCache>();
    cache->serials = serials;
    ClassQueryParams probe = q;
    cache->used = tools::read_images_by_sums(probe, cache->sums);
    first->class_sums = cache;
  }
  prepared.class_sums = cache;
  if (cache->used) q.image_sums = &cache->sums;
}

/// The largest the classes' summed density can be (their peaks summed).
double classes_peak(const ClassQueryParams& q) {
  double peak = 0;
  for (std::uint32_t k = 0; k < q.class_count; ++k) peak += density_peak(q.classes[k]);
  return peak;
}

/// warn_tile_size for the classes' sum, then the warning of a class the tiles serve unevenly
/// (class_count_warnings).
void warn_classes(const Tileset& set, const ClassQueryParams& q, int level) {
  warn_tile_size(set, classes_peak(q), q.query, level);
  if (!(q.query.x1 > q.query.x0 && q.query.y1 > q.query.y0)) return;
  std::vector<double> peaks;
  for (std::uint32_t k = 0; k < q.class_count; ++k) peaks.push_back(density_peak(q.classes[k]));
  for (const std::string& text :
       tools::class_count_warnings(set, peaks, q.query.scale, q.query.tile_size, "tile_size"))
    if (PyErr_WarnEx(PyExc_UserWarning, text.c_str(), level) < 0) throw py::error_already_set();
}

/// Several classes (kdm/runtime/class_query.h), each density a spec: the records, views and levels as
/// query() returns them, then each point's class. New memory every call (no `storage`).
py::tuple query_classes(const TilesetHandle& handle, const Rect& rect, double scale,
                        const std::vector<const tools::DensitySpec*>& specs,
                        const std::vector<py::object>& ready, const std::vector<py::object>& callables,
                        const std::vector<double>& maxima, const std::vector<py::object>& bounds,
                        bool vectorized, std::optional<Rect> density_rect, double tile_size,
                        const std::string& mode, const std::array<double, 2>& origin, int threads) {
  PreparedClasses prepared;
  prepare_classes(prepared, rect, scale, specs, ready, callables, maxima, bounds, vectorized, density_rect,
                  tile_size, mode, origin, threads);
  warn_classes(*handle.set, prepared.q, 3);  // via _query_classes
  std::vector<QueryPoint> points;
  std::vector<std::uint8_t> classes;
  Buffer buffer;
  std::size_t m = 0;
  if (threads == 0) {
    py::gil_scoped_release release;  // a callable class takes it back at each call
    tools::query_all(*handle.set, prepared.q, points, classes, kKeywordNames);
    m = points.size();
    buffer.reserve(std::max<std::size_t>(m, 1), 0);
    std::copy(points.begin(), points.end(), buffer.points);
  } else {
    const ClassQueryParams& q = prepared.q;
    tools::check_before_collecting(*handle.set, q, kKeywordNames);
    double rho = 0;
    for (std::uint32_t k = 0; k < q.class_count; ++k) rho += density_bound(q.classes[k], q.query);
    m = collect_parallel(
        buffer, threads, room_for(rho, q.query), [&](std::size_t capacity) { classes.resize(capacity); },
        [&](ParallelQuery& parallel, std::size_t* written, std::size_t* needed, QueryProblem* problem) {
          return parallel.run(*handle.set, q, buffer.points, classes.data(), buffer.capacity, written,
                              std_thread_runner(), needed, problem);
        });
    classes.resize(m);
  }
  fill_levels(*handle.set, buffer.points, buffer.levels, 0, m);
  prepared.rethrow();
  py::array_t<std::uint8_t> labels(static_cast<py::ssize_t>(classes.size()));
  std::copy(classes.begin(), classes.end(), labels.mutable_data());
  const py::tuple base = result(m, buffer, py::none());
  return py::make_tuple(base[0], base[1], base[2], base[3], base[4], base[5], labels);
}

/// Several classes into the compact output (query_classes_compact), with the GIL released: positions
/// (m × 2 float32), each point's key if asked (else None), and each point's class.
py::tuple class_positions(const TilesetHandle& handle, const Rect& rect, double scale,
                          const std::vector<const tools::DensitySpec*>& specs,
                          const std::vector<py::object>& ready, const std::vector<py::object>& callables,
                          const std::vector<double>& maxima, const std::vector<py::object>& bounds,
                          bool vectorized, std::optional<Rect> density_rect, double tile_size,
                          const std::string& mode, const std::array<double, 2>& origin, bool keys,
                          int threads) {
  PreparedClasses prepared;
  prepare_classes(prepared, rect, scale, specs, ready, callables, maxima, bounds, vectorized, density_rect,
                  tile_size, mode, origin, threads);
  const ClassQueryParams& q = prepared.q;
  tools::check_before_collecting(*handle.set, q, kKeywordNames);
  warn_classes(*handle.set, q, 2);
  CompactBuffer buffer;
  buffer.with_keys = keys;
  std::vector<std::uint8_t> classes;
  double rho = 0;  // a bound of the classes' sum
  for (std::uint32_t k = 0; k < q.class_count; ++k) rho += density_bound(q.classes[k], q.query);
  const std::size_t m = fill_compact(
      buffer, threads, room_for(rho, q.query),
      [&](std::size_t at, std::size_t* written, QueryCursor* cursor, QueryProblem* problem) {
        return query_classes_compact(*handle.set, q, buffer.at(at), classes.data() + at, buffer.capacity - at,
                                     written, cursor, problem);
      },
      [&](ParallelQuery& parallel, std::size_t* written, std::size_t* needed, QueryProblem* problem) {
        return parallel.run(*handle.set, q, buffer.at(0), classes.data(), buffer.capacity, written,
                            std_thread_runner(), needed, problem);
      },
      [&](std::size_t capacity) { classes.resize(capacity); });
  prepared.rethrow();
  py::array_t<std::uint8_t> labels(static_cast<py::ssize_t>(m));
  std::copy(classes.begin(), classes.begin() + m, labels.mutable_data());
  const py::tuple arrays = take_compact(buffer, m);
  return py::make_tuple(arrays[0], arrays[1], labels);
}

}  // namespace

void bind_query(py::module_& m) {
  py::class_<PreparedDensity>(m, "PreparedDensity",
                              "A density spec stretched over a rectangle, prepared once for many queries")
      .def(py::init<std::shared_ptr<const tools::DensitySpec>, const Rect&>(), py::arg("spec"),
           py::arg("rect"))
      .def(
          "at",
          [](const PreparedDensity& d,
             const py::array_t<double, py::array::c_style | py::array::forcecast>& x,
             const py::array_t<double, py::array::c_style | py::array::forcecast>& y) {
            if (x.size() != y.size()) throw std::invalid_argument("x and y must have the same length");
            py::array_t<double> out(x.size());
            const QueryDensity& q = d.density->density;
            const double *px = x.data(), *py_ = y.data();
            double* o = out.mutable_data();
            // As a query reads it at a point; 0 at no position (NaN, infinite), as kdm_density_image_at.
            for (py::ssize_t i = 0; i < x.size(); ++i)
              o[i] = !(std::isfinite(px[i]) && std::isfinite(py_[i])) ? 0.0
                     : q.kind == QueryDensity::Kind::kConstant        ? q.constant
                     : q.kind == QueryDensity::Kind::kImage           ? q.image->at(px[i], py_[i])
                                                                      : q.callback(q.user, px[i], py_[i]);
            return out;
          },
          py::arg("x"), py::arg("y"), "The density at world positions, as a query reads it");
  m.def("query_classes", &query_classes, py::arg("tileset"), py::arg("rect"), py::arg("scale"),
        py::arg("specs"), py::arg("ready"), py::arg("callables"), py::arg("maxima"), py::arg("bounds"),
        py::arg("vectorized"), py::arg("density_rect").none(true), py::arg("tile_size"), py::arg("mode"),
        py::arg("origin"), py::arg("threads"),
        "several classes in one query: query()'s tuple and each point's class");
  m.def("class_positions", &class_positions, py::arg("tileset"), py::arg("rect"), py::arg("scale"),
        py::arg("specs"), py::arg("ready"), py::arg("callables"), py::arg("maxima"), py::arg("bounds"),
        py::arg("vectorized"), py::arg("density_rect").none(true), py::arg("tile_size"), py::arg("mode"),
        py::arg("origin"), py::arg("keys"), py::arg("threads"),
        "several classes into the compact output: float32 positions, keys if asked, each point's class");
  m.def("positions", &positions, py::arg("tileset"), py::arg("rect"), py::arg("scale"),
        py::arg("spec").none(true), py::arg("ready").none(true), py::arg("callable").none(true),
        py::arg("vectorized"), py::arg("bounds").none(true), py::arg("density_rect").none(true),
        py::arg("density_max").none(true), py::arg("tile_size"), py::arg("mode"), py::arg("origin"),
        py::arg("keys"), py::arg("threads"),
        "the compact query into new arrays: float32 positions and, if asked, 64-bit keys");
  m.def(
      "query", &query, py::arg("tileset"), py::arg("rect"), py::arg("scale"), py::arg("spec").none(true),
      py::arg("ready").none(true), py::arg("callable").none(true), py::arg("vectorized"),
      py::arg("bounds").none(true), py::arg("density_rect").none(true), py::arg("density_max").none(true),
      py::arg("tile_size"), py::arg("mode"), py::arg("origin"), py::arg("storage").none(true),
      py::arg("threads"),
      "tools::query_all into numpy arrays (reusing `storage`, an earlier result's, when it is large enough)");
}

}  // namespace kdm::python
