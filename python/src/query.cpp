// kdm._kdm.query: a runtime query run to completion (by tools::query_all's rules, as `kdm query` runs it)
// into numpy arrays: positions, tile ids, ranks and levels, converted chunk by chunk as the query writes
// them, with the GIL released.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "bindings.h"
#include "query_density.h"
#include "runtime_query.h"

namespace kdm::python {
namespace {

using Rect = std::array<double, 4>;

void check_rect(const char* name, const Rect& r) {
  for (double v : r)
    if (!std::isfinite(v)) throw std::invalid_argument(std::string(name) + " must be four finite numbers");
  if (!(r[2] > r[0] && r[3] > r[1]))
    throw std::invalid_argument(std::string(name) + " is empty or inverted (needs x0 < x1 and y0 < y1)");
}

QueryMode parse_mode(const std::string& mode) {
  if (mode == "stable") return QueryMode::kStable;
  if (mode == "smooth") return QueryMode::kSmooth;
  throw std::invalid_argument("mode must be 'stable' or 'smooth', got '" + mode + "'");
}

/// A result's columns, where the points go: positions, tiles, ranks and levels.
struct Columns {
  std::vector<double> xy;
  std::vector<std::int64_t> tile;
  std::vector<std::uint32_t> rank, level;
};

/// What a query writes through: a chunk of points small enough to stay in cache, converted into columns
/// as it fills, and the columns of the points an `out=` result has no room for (all of them without one).
/// Each thread keeps its own between calls (refilling warm memory is several times cheaper than first
/// touching fresh memory); a query made from inside a callable density, while they are in use, gets its
/// own.
struct Scratch {
  std::vector<QueryPoint> chunk;
  Columns spill;
};
thread_local Scratch kept_scratch;
thread_local bool kept_scratch_in_use = false;

struct ScratchLease {
  ScratchLease() : scratch(kept_scratch_in_use ? own : kept_scratch) { kept_scratch_in_use = true; }
  ~ScratchLease() {
    if (&scratch != &kept_scratch) return;
    kept_scratch_in_use = false;
    if (kept_scratch.spill.rank.capacity() > (std::size_t(1) << 20)) kept_scratch.spill = Columns{};
  }
  ScratchLease(const ScratchLease&) = delete;
  ScratchLease& operator=(const ScratchLease&) = delete;

  Scratch own;
  Scratch& scratch;
};

constexpr std::size_t kChunk = std::size_t(1) << 14;

/// The arrays of an earlier result (`storage`), if they are of the right types and writable: the points
/// go straight into them while they have room.
struct Storage {
  py::array_t<double> xy;
  py::array_t<std::int64_t> tile;
  py::array_t<std::uint32_t> rank, level;
  std::size_t capacity = 0;
  explicit Storage(const py::object& storage) {
    if (storage.is_none()) return;
    const py::tuple t = storage.cast<py::tuple>();
    if (t.size() != 4 || !py::isinstance<py::array_t<double>>(t[0]) ||
        !py::isinstance<py::array_t<std::int64_t>>(t[1]) ||
        !py::isinstance<py::array_t<std::uint32_t>>(t[2]) ||
        !py::isinstance<py::array_t<std::uint32_t>>(t[3]))
      return;
    xy = t[0].cast<py::array_t<double>>(), tile = t[1].cast<py::array_t<std::int64_t>>();
    rank = t[2].cast<py::array_t<std::uint32_t>>(), level = t[3].cast<py::array_t<std::uint32_t>>();
    auto usable = [](const py::array& a, py::ssize_t columns) {
      return a.ndim() == (columns > 1 ? 2 : 1) && (columns == 1 || a.shape(1) == columns) && a.writeable() &&
             (a.flags() & py::array::c_style);
    };
    if (!(usable(xy, 2) && usable(tile, 2) && usable(rank, 1) && usable(level, 1))) return;
    capacity =
        static_cast<std::size_t>(std::min({xy.shape(0), tile.shape(0), rank.shape(0), level.shape(0)}));
  }
};

/// Runs the query to completion (the rules of tools::query_all), its points into `direct` (room for
/// `capacity`) and, past that, `spill`. Returns the count. Call without the GIL.
std::size_t collect(const Tileset& tiles, const QueryParams& q, Scratch& scratch, double* xy,
                    std::int64_t* tile, std::uint32_t* rank, std::uint32_t* level, std::size_t capacity) {
  scratch.chunk.resize(kChunk);
  Columns& spill = scratch.spill;
  spill.xy.clear(), spill.tile.clear(), spill.rank.clear(), spill.level.clear();
  QueryCursor cursor;
  std::size_t m = 0;
  // Points come tile by tile: look each tile up once.
  std::int64_t tx = std::numeric_limits<std::int64_t>::min(), ty = tx;
  const Tile* t = nullptr;
  for (;;) {
    std::size_t written = 0;
    QueryProblem problem;
    const Status s = query_points(tiles, q, scratch.chunk.data(), kChunk, &written, &cursor, &problem);
    for (std::size_t i = 0; i < written; ++i, ++m) {
      const QueryPoint& p = scratch.chunk[i];
      if (!t || p.id.tile_x != tx || p.id.tile_y != ty)
        tx = p.id.tile_x, ty = p.id.tile_y, t = &tiles.tile_at(tx, ty);
      const std::uint32_t lv = t->level_of(p.id.rank);
      if (m < capacity) {
        xy[2 * m] = p.x, xy[2 * m + 1] = p.y, tile[2 * m] = tx, tile[2 * m + 1] = ty;
        rank[m] = p.id.rank, level[m] = lv;
      } else {
        spill.xy.insert(spill.xy.end(), {p.x, p.y}), spill.tile.insert(spill.tile.end(), {tx, ty});
        spill.rank.push_back(p.id.rank), spill.level.push_back(lv);
      }
    }
    if (m > tools::kMaxCollectedPoints)  // 1 GiB of points: stop before memory runs out
      throw std::invalid_argument(
          "the query emits more than 2^25 points; lower the scale or split the region");
    if (s == Status::kOk) return m;
    if (s != Status::kBufferFull)
      throw std::invalid_argument("query: " +
                                  tools::describe(problem, tools::ParameterNames{"scale=", "tile_size="}));
  }
}

/// The result's arrays (xy m×2, tile m×2, rank, level), then the storage they are the first rows of (for a
/// later query's `storage`): `out`'s own when they held every point, else new arrays.
py::tuple result(std::size_t m, const Storage& out, const Columns& spill) {
  const auto rows = static_cast<py::ssize_t>(m);
  const py::slice first(0, rows, 1);
  if (spill.rank.empty() && out.capacity > 0 && out.capacity >= m)
    return py::make_tuple(out.xy[first], out.tile[first], out.rank[first], out.level[first],
                          py::make_tuple(out.xy, out.tile, out.rank, out.level));
  py::array_t<double> xy({rows, py::ssize_t(2)});
  py::array_t<std::int64_t> tile({rows, py::ssize_t(2)});
  py::array_t<std::uint32_t> rank(rows), level(rows);
  const std::size_t head = std::min(m, out.capacity);  // in `out`; the rest were spilled
  {
    py::gil_scoped_release release;
    auto copy = [head](auto* to, const auto* from, const auto& rest, std::size_t width) {
      if (head) std::memcpy(to, from, head * width * sizeof(*to));
      if (!rest.empty()) std::memcpy(to + head * width, rest.data(), rest.size() * sizeof(*to));
    };
    copy(xy.mutable_data(), head ? out.xy.data() : nullptr, spill.xy, 2);
    copy(tile.mutable_data(), head ? out.tile.data() : nullptr, spill.tile, 2);
    copy(rank.mutable_data(), head ? out.rank.data() : nullptr, spill.rank, 1);
    copy(level.mutable_data(), head ? out.level.data() : nullptr, spill.level, 1);
  }
  return py::make_tuple(xy, tile, rank, level, py::make_tuple(xy, tile, rank, level));
}

py::tuple query(const TilesetHandle& handle, const Rect& rect, double scale, const tools::DensitySpec* spec,
                py::object callable, std::optional<Rect> density_rect, std::optional<double> density_max,
                double tile_size, const std::string& mode, const std::array<double, 2>& origin,
                const py::object& storage) {
  check_rect("rect", rect);
  QueryParams q;
  q.x0 = rect[0], q.y0 = rect[1], q.x1 = rect[2], q.y1 = rect[3];
  q.origin_x = origin[0], q.origin_y = origin[1];
  q.tile_size = tile_size;
  q.scale = scale;
  q.mode = parse_mode(mode);
  const bool call = !callable.is_none();
  if (call == (spec != nullptr)) throw std::invalid_argument("give one density: a spec or a callable");
  if (density_rect && (call || spec->kind == tools::DensitySpec::Kind::kConstant))
    throw std::invalid_argument("density_rect needs an image, an array or a test map density");
  if (density_max && !call) throw std::invalid_argument("density_max is for a callable density only");
  if (density_rect) check_rect("density_rect", *density_rect);
  std::unique_ptr<SpecDensity> from_spec;
  std::unique_ptr<CallableDensity> from_callable;
  if (call) {
    if (!density_max)
      throw std::invalid_argument("a callable density needs density_max, an upper bound of its values");
    check_number("density_max", *density_max, 0, false);
    from_callable = std::make_unique<CallableDensity>(std::move(callable), *density_max);
    q.density = from_callable->density;
  } else {
    const Rect r = density_rect ? *density_rect : rect;  // by default the image covers the rectangle queried
    from_spec = std::make_unique<SpecDensity>(*spec, r.data());
    q.density = from_spec->density;
  }
  Storage out(storage);
  ScratchLease lease;
  double* xy = out.capacity ? out.xy.mutable_data() : nullptr;
  std::int64_t* tile = out.capacity ? out.tile.mutable_data() : nullptr;
  std::uint32_t* rank = out.capacity ? out.rank.mutable_data() : nullptr;
  std::uint32_t* level = out.capacity ? out.level.mutable_data() : nullptr;
  std::size_t m = 0;
  {
    py::gil_scoped_release release;  // a callable density takes it back at each call
    m = collect(*handle.set, q, lease.scratch, xy, tile, rank, level, out.capacity);
  }
  if (from_callable) from_callable->rethrow();
  return result(m, out, lease.scratch.spill);
}

}  // namespace

void bind_query(py::module_& m) {
  m.def(
      "query", &query, py::arg("tileset"), py::arg("rect"), py::arg("scale"), py::arg("spec").none(true),
      py::arg("callable").none(true), py::arg("density_rect").none(true), py::arg("density_max").none(true),
      py::arg("tile_size"), py::arg("mode"), py::arg("origin"), py::arg("storage").none(true),
      "tools::query_all into numpy arrays (reusing `storage`, an earlier result's, when it is large enough)");
}

}  // namespace kdm::python
