// kdm._kdm.query: a runtime query run to completion (tools::query_all, as `kdm query` runs it) into numpy
// arrays: positions, tile ids, ranks and levels, filled in one pass with the GIL released.
#include <array>
#include <cmath>
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

/// Where a query collects its points. Each thread keeps one buffer between calls: fresh memory costs more
/// than the query (its first touch, page by page), so only a buffer above 2^20 points (40 MiB) is given
/// back. A query made from inside a callable density, while the thread's buffer is in use, gets its own.
thread_local std::vector<QueryPoint> kept_points;
thread_local bool kept_points_in_use = false;

struct ScratchPoints {
  ScratchPoints() : points(kept_points_in_use ? own : kept_points) { kept_points_in_use = true; }
  ~ScratchPoints() {
    if (&points != &kept_points) return;
    kept_points_in_use = false;
    if (kept_points.capacity() > (std::size_t(1) << 20)) std::vector<QueryPoint>().swap(kept_points);
  }
  ScratchPoints(const ScratchPoints&) = delete;
  ScratchPoints& operator=(const ScratchPoints&) = delete;

  std::vector<QueryPoint> own;  ///< for a query made from a callable density while the kept one is in use
  std::vector<QueryPoint>& points;
};

/// Arrays of room for at least m points: those of `storage` (an earlier result's, reused: refilling warm
/// memory is several times cheaper than first touching fresh memory) when they are large enough and of
/// the right types, else new ones.
struct ResultStorage {
  py::array_t<double> xy;
  py::array_t<std::int64_t> tile;
  py::array_t<std::uint32_t> rank, level;
  ResultStorage(py::ssize_t m, const py::object& storage) {
    if (!storage.is_none() && reuse(m, storage)) return;
    xy = py::array_t<double>({m, py::ssize_t(2)});
    tile = py::array_t<std::int64_t>({m, py::ssize_t(2)});
    rank = py::array_t<std::uint32_t>(m), level = py::array_t<std::uint32_t>(m);
  }

 private:
  bool reuse(py::ssize_t m, const py::object& storage) {
    const py::tuple t = storage.cast<py::tuple>();
    if (t.size() != 4) return false;
    auto fits = [m](const py::array& a, py::ssize_t columns) {
      return a.ndim() == (columns > 1 ? 2 : 1) && a.shape(0) >= m &&
             (columns == 1 || a.shape(1) == columns) && a.writeable() && (a.flags() & py::array::c_style);
    };
    if (!py::isinstance<py::array_t<double>>(t[0]) || !py::isinstance<py::array_t<std::int64_t>>(t[1]) ||
        !py::isinstance<py::array_t<std::uint32_t>>(t[2]) ||
        !py::isinstance<py::array_t<std::uint32_t>>(t[3]))
      return false;
    xy = t[0].cast<py::array_t<double>>(), tile = t[1].cast<py::array_t<std::int64_t>>();
    rank = t[2].cast<py::array_t<std::uint32_t>>(), level = t[3].cast<py::array_t<std::uint32_t>>();
    return fits(xy, 2) && fits(tile, 2) && fits(rank, 1) && fits(level, 1);
  }
};

/// The query's points as arrays: xy (m×2), tile (m×2), rank and level (m), the first m rows of the
/// storage returned as the fifth element (for a later query's `storage`).
py::tuple to_arrays(const Tileset& tiles, const std::vector<QueryPoint>& points, const py::object& storage) {
  const auto m = static_cast<py::ssize_t>(points.size());
  ResultStorage out(m, storage);
  double* out_xy = out.xy.mutable_data();
  std::int64_t* out_tile = out.tile.mutable_data();
  std::uint32_t* out_rank = out.rank.mutable_data();
  std::uint32_t* out_level = out.level.mutable_data();
  {
    py::gil_scoped_release release;
    // Points come tile by tile: look each tile up once.
    std::int64_t tx = std::numeric_limits<std::int64_t>::min(), ty = tx;
    const Tile* t = nullptr;
    for (py::ssize_t i = 0; i < m; ++i) {
      const QueryPoint& p = points[i];
      if (!t || p.id.tile_x != tx || p.id.tile_y != ty)
        tx = p.id.tile_x, ty = p.id.tile_y, t = &tiles.tile_at(tx, ty);
      out_xy[2 * i] = p.x, out_xy[2 * i + 1] = p.y;
      out_tile[2 * i] = tx, out_tile[2 * i + 1] = ty;
      out_rank[i] = p.id.rank;
      out_level[i] = t->level_of(p.id.rank);
    }
  }
  const py::slice first(0, m, 1);
  return py::make_tuple(out.xy[first], out.tile[first], out.rank[first], out.level[first],
                        py::make_tuple(out.xy, out.tile, out.rank, out.level));
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
  ScratchPoints scratch;
  std::vector<QueryPoint>& points = scratch.points;
  try {
    py::gil_scoped_release release;  // a callable density takes it back at each call
    tools::query_all(*handle.set, q, points, tools::ParameterNames{"scale=", "tile_size="});
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::runtime_error& e) {  // more than 2^25 points: too much asked, not a failure
    throw std::invalid_argument(e.what());
  }
  if (from_callable) from_callable->rethrow();
  return to_arrays(*handle.set, points, storage);
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
