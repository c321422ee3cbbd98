// kdm._kdm.Tileset: loaded tile sets (the built-in one, a file, or one just baked) and what they hold;
// kdm._kdm.bake: the tile baker. Queries on them are query.cpp's.
#include <cmath>
#include <fstream>
#include <iterator>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include "atomic_file.h"
#include "bindings.h"
#include "kdm/generator/bake.h"
#include "kdm/runtime/compact_query.h"
#include "kdm/runtime/query.h"
#include "kdm/runtime/tileset_format.h"
#include "kdm/runtime/version.h"

namespace kdm::python {
const Tileset& builtin_tileset() {
  const Tileset& set = Tileset::builtin();
  if (set.empty()) throw std::bad_alloc();
  return set;
}

namespace {

/// `h` keeping `bytes`, the file they were decoded from, for to_bytes() and save(), where they are what
/// encoding the set gives (a file of the current format; an older one is encoded anew).
template <class Bytes>
TilesetHandle with_bytes(TilesetHandle h, const Bytes& bytes) {
  if (h.format_version == tileset_format_version_for(h.set->data()))
    h.encoded->bytes.assign(bytes.begin(), bytes.end());
  return h;
}

TilesetHandle builtin() {
  TilesetHandle h;
  {
    py::gil_scoped_release release;  // the first call decodes the set (a tenth of a second)
    h.set = std::shared_ptr<const Tileset>(&builtin_tileset(), [](const Tileset*) {});
  }
  h.format_version = tileset_format_version_for(h.set->data());  // as tilesets/default.kdmt has it
  return h;
}

/// The message is `kdm query --tileset`'s.
TilesetHandle load(const std::string& path) {
  auto set = std::make_shared<Tileset>();
  std::string detail;
  TilesetHeader header;
  std::vector<char> bytes;
  Status s;
  {
    py::gil_scoped_release release;
    s = read_tileset_file(path, bytes, &detail);  // the header's version too, which the set does not keep
    if (s == Status::kOk) s = read_tileset_header(bytes.data(), bytes.size(), header, &detail);
    if (s == Status::kOk) s = Tileset::load_memory(bytes.data(), bytes.size(), *set, &detail);
  }
  if (s != Status::kOk) throw read_error(path, "'" + path + "': " + status_message(s) + ": " + detail);
  return with_bytes({std::move(set), header.format_version}, bytes);
}

/// The set from a .kdmt file's bytes, checked as load() checks a file.
TilesetHandle from_bytes(const py::bytes& data) {
  const std::string bytes = data;  // one copy, then the GIL is free
  auto set = std::make_shared<Tileset>();
  std::string detail;
  TilesetHeader header;
  Status s;
  {
    py::gil_scoped_release release;
    s = read_tileset_header(bytes.data(), bytes.size(), header, &detail);
    if (s == Status::kOk) s = Tileset::load_memory(bytes.data(), bytes.size(), *set, &detail);
  }
  if (s != Status::kOk)
    throw std::invalid_argument(std::string("data: ") + status_message(s) + ": " + detail);
  return with_bytes({std::move(set), header.format_version}, bytes);
}

/// The set's .kdmt bytes: those it was read from, or encoded once (the GIL released). Throws
/// std::runtime_error if the set cannot be encoded.
const std::vector<std::uint8_t>& encoded_bytes(const TilesetHandle& h) {
  EncodedTileset& e = *h.encoded;
  py::gil_scoped_release release;  // another thread may be encoding: wait for it without the GIL
  const std::lock_guard<std::mutex> lock(e.mutex);
  if (e.bytes.empty()) {
    std::string detail;
    const Status s = encode_tileset(h.set->data(), e.bytes, &detail);
    if (s != Status::kOk) {
      e.bytes.clear();
      throw std::runtime_error(std::string("tile set: ") + status_message(s) + ": " + detail);
    }
  }
  return e.bytes;
}

/// The bytes save() writes.
py::bytes to_bytes(const TilesetHandle& h) {
  const std::vector<std::uint8_t>& bytes = encoded_bytes(h);
  return py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size());
}

void save(const TilesetHandle& h, const std::string& path) {
  std::string detail;
  Status s = check_tileset_path(path, &detail);  // before any encoding
  if (s == Status::kOk) {
    const std::vector<std::uint8_t>& bytes = encoded_bytes(h);
    py::gil_scoped_release release;
    std::string error;
    if (!tools::write_text_file_atomic(path, std::string(bytes.begin(), bytes.end()), error))
      s = Status::kIoError, detail = error;
  }
  if (s != Status::kOk) throw FileError("'" + path + "': " + status_message(s) + ": " + detail);
}

py::dict info(const TilesetHandle& h) {
  const Tileset& t = *h.set;
  const TilesetData& d = t.data();
  py::dict out;
  out["levels"] = d.levels;
  out["level_points"] = std::vector<std::uint32_t>(d.level_nominal.begin(), d.level_nominal.end());
  out["keyframes"] = std::vector<std::uint32_t>(d.keyframe_nominal.begin(), d.keyframe_nominal.end());
  out["max_points_per_tile"] = t.max_points_per_tile();
  out["smooth_limit_per_tile"] = query_density_limit(t, QueryMode::kSmooth);
  out["subtiles_per_side"] = d.handover_zone ? d.subtiles_per_side() : 0u;
  out["handover_level"] = d.handover_level;
  out["handover_slack"] = d.handover_slack;
  out["colours"] = d.colours;
  out["tiles"] = d.tiles.size();
  out["format_version"] = h.format_version;
  out["resident_bytes"] = t.resident_bytes();
  out["recipe"] = d.recipe;
  out["generator_version"] = d.generator_version;
  out["glide_reach"] = t.glide_reach();
  return out;
}

TilesetHandle bake(const std::string& recipe_text, int threads) {
  if (threads < 0) throw std::invalid_argument("threads must be >= 0 (0: the default count)");
  if (!gen::BakeRecipe::gives_any_key(recipe_text))
    throw std::invalid_argument(
        "recipe_text gives no key, only blank lines and comments (the defaults alone bake for minutes: give "
        "at least one key, e.g. 'levels 6')");
  const gen::BakeRecipe recipe = gen::BakeRecipe::parse(recipe_text);  // gen::InvalidArgument: ValueError
  auto set = std::make_shared<Tileset>();
  std::string detail;
  std::vector<std::uint8_t> bytes;
  Status s;
  {
    py::gil_scoped_release release;
    const TilesetData data =
        gen::bake_tileset(recipe, threads, stop_on_signal);  // Ctrl-C: after the runs it samples
    s = encode_tileset(data, bytes, &detail);  // through the file format, as `kdm bake` then a load
    if (s == Status::kOk) s = Tileset::load_memory(bytes.data(), bytes.size(), *set, &detail);
  }
  if (s != Status::kOk)
    throw std::runtime_error(std::string("baked set: ") + status_message(s) + ": " + detail);
  const std::uint32_t version = tileset_format_version_for(set->data());
  return with_bytes({std::move(set), version}, bytes);
}

/// emission_threshold of every id given as tile (m × 2), rank and depth (m each).
/// The thresholds of a compact output's points by their keys (point_id_of_key, near the tile given).
py::array_t<double> key_thresholds(
    const TilesetHandle& h, const py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>& keys,
    std::int64_t near_x, std::int64_t near_y) {
  if (keys.ndim() != 1)
    throw std::invalid_argument("keys must be an (m,) array, as positions(keys=True) gives");
  const py::ssize_t n = keys.size();
  py::array_t<double> out(n);
  const std::uint64_t* k = keys.data();
  double* o = out.mutable_data();
  py::ssize_t bad = -1;
  {
    py::gil_scoped_release release;
    for (py::ssize_t i = 0; i < n && bad < 0; ++i) {
      o[i] = emission_threshold(*h.set, point_id_of_key(*h.set, k[i], near_x, near_y));
      if (o[i] < 0) bad = i;
    }
  }
  if (bad >= 0)
    throw std::invalid_argument("key " + std::to_string(bad) + " (" + std::to_string(k[bad]) +
                                ") is not a point of this tile set near tile (" + std::to_string(near_x) +
                                ", " + std::to_string(near_y) + ")");
  return out;
}

using TileArray = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;
using CountArray = py::array_t<std::uint32_t, py::array::c_style | py::array::forcecast>;

/// Calls f(i, id) for every id given as tile (m × 2), rank and depth (m each), the GIL released, until f
/// returns false; then raises ValueError naming that point (not one of this set's).
template <class F>
void for_each_id(const TileArray& tile, const CountArray& rank, const CountArray& depth, F&& f) {
  const py::ssize_t n = rank.size();
  if (tile.ndim() != 2 || tile.shape(0) != n || tile.shape(1) != 2 || rank.ndim() != 1 || depth.ndim() != 1 ||
      depth.size() != n)
    throw std::invalid_argument("tile must be (m, 2) and rank, depth (m,), as a query's result holds them");
  const std::int64_t* t = tile.data();
  const std::uint32_t *r = rank.data(), *d = depth.data();
  py::ssize_t bad = -1;
  {
    py::gil_scoped_release release;
    for (py::ssize_t i = 0; i < n && bad < 0; ++i)
      if (!f(i, PointId{t[2 * i], t[2 * i + 1], r[i], d[i]})) bad = i;
  }
  if (bad >= 0)
    throw std::invalid_argument("point " + std::to_string(bad) + " (tile " + std::to_string(t[2 * bad]) +
                                ", " + std::to_string(t[2 * bad + 1]) + ", rank " + std::to_string(r[bad]) +
                                ", depth " + std::to_string(d[bad]) + ") is not a point of this tile set");
}

py::array_t<double> thresholds(const TilesetHandle& h, const TileArray& tile, const CountArray& rank,
                               const CountArray& depth) {
  py::array_t<double> out(rank.size());
  double* o = out.mutable_data();
  for_each_id(tile, rank, depth, [&](py::ssize_t i, const PointId& id) {
    o[i] = emission_threshold(*h.set, id);
    return o[i] >= 0;
  });
  return out;
}

/// stable_position of every id, for tiles of `tile_size` less `origin`: (m × 2) float64.
py::array_t<double> stable_positions(const TilesetHandle& h, const TileArray& tile, const CountArray& rank,
                                     const CountArray& depth, double tile_size, double origin_x,
                                     double origin_y) {
  check_number("tile_size", tile_size, 0, true);
  if (!(std::isfinite(origin_x) && std::isfinite(origin_y)))
    throw std::invalid_argument("origin must be two finite numbers");
  py::array_t<double> out({rank.size(), py::ssize_t(2)});
  double* o = out.mutable_data();
  for_each_id(tile, rank, depth, [&](py::ssize_t i, const PointId& id) {
    return stable_position(*h.set, id, tile_size, origin_x, origin_y, &o[2 * i], &o[2 * i + 1]);
  });
  return out;
}

}  // namespace

void bind_tileset(py::module_& m) {
  py::class_<TilesetHandle>(m, "Tileset", "A loaded tile set (kdm::Tileset)")
      .def_static("builtin", &builtin)
      .def_static("load", &load, py::arg("path"))
      .def_static("from_bytes", &from_bytes, py::arg("data"))
      .def("to_bytes", &to_bytes)
      .def("save", &save, py::arg("path"))
      .def("thresholds", &thresholds, py::arg("tile"), py::arg("rank"), py::arg("depth"))
      .def("stable_positions", &stable_positions, py::arg("tile"), py::arg("rank"), py::arg("depth"),
           py::arg("tile_size"), py::arg("origin_x"), py::arg("origin_y"))
      .def("key_thresholds", &key_thresholds, py::arg("keys"), py::arg("near_x"), py::arg("near_y"))
      .def_property_readonly("info", &info);
  m.def("bake", &bake, py::arg("recipe_text"), py::arg("threads"));
}

}  // namespace kdm::python
