// A loaded tile set, ready for queries (kdm/runtime/query.h): the TilesetData of a file
// (kdm/runtime/tileset_format.h) plus tables computed once at load, so the query loop only compares and
// copies. Immutable after loading: any number of threads may query one Tileset at once.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "kdm/runtime/export.h"
#include "kdm/runtime/status.h"
#include "kdm/runtime/tileset_format.h"

namespace kdm {

namespace detail {
struct QueryTables;
struct TilesetInternals;
}  // namespace detail

class KDM_RUNTIME_API Tileset {
 public:
  /// An empty set: queries on it return kInvalidArgument.
  Tileset() = default;
  ~Tileset();
  Tileset(const Tileset& other);
  Tileset(Tileset&& other) noexcept;
  Tileset& operator=(const Tileset& other);
  Tileset& operator=(Tileset&& other) noexcept;

  /// Loads and validates a file / memory buffer (untrusted input; see decode_tileset). On failure the
  /// returned status says why (kOutOfMemory when an allocation, through the tile-set allocator or not,
  /// is refused), `detail` (optional) says more, and `out` is left empty.
  static Status load_file(const std::string& path, Tileset& out, std::string* detail = nullptr);
  static Status load_memory(const void* data, std::size_t size, Tileset& out, std::string* detail = nullptr);
  /// The default tile set compiled into the library (tilesets/default.kdmt). Thread-safe. It is decoded on
  /// the first call, which takes a tenth to a third of a second (the more in a fresh process, which first
  /// touches the memory; docs/performance.md): call it once at start-up to keep that out of a frame. The C API's kdm_tileset_builtin() shares this copy. An empty set (no
  /// tiles; queries refuse it) when memory runs out while it is decoded: a later call tries again.
  static const Tileset& builtin();

  /// The set as the file holds it.
  const TilesetData& data() const { return set_; }
  bool empty() const { return set_.tiles.empty(); }
  /// The expected points per tile at which every tile has emitted all its points (the nominal count of
  /// the top level): the density limit is this per tile area.
  std::uint32_t max_points_per_tile() const {
    return set_.level_nominal.empty() ? 0 : set_.level_nominal.back();
  }
  /// Index into data().tiles of the tile shown at tile coordinates (tx, ty), and that tile. Thread-safe;
  /// the set must not be empty.
  std::size_t tile_index_at(std::int64_t tx, std::int64_t ty) const;
  const Tile& tile_at(std::int64_t tx, std::int64_t ty) const { return set_.tiles[tile_index_at(tx, ty)]; }
  /// Whether the set has a glide track (smooth queries then glide; without one they emit stable
  /// positions).
  bool has_glide_track() const { return !set_.keyframe_nominal.empty(); }
  /// The farthest any point glides from its stable position in smooth mode, per axis, in tile sides (0
  /// without a glide track).
  double glide_reach() const;
  /// Heap bytes this tile set holds once loaded (positions, keys, level tables, per-point emission
  /// thresholds, glide and hand-over tables, recipe text), not counting allocator overhead. The builtin
  /// set's decoded copy is the same size; its compressed bytes in the library's data section are extra.
  /// Thread-safe.
  std::size_t resident_bytes() const;

 private:
  friend struct detail::TilesetInternals;
  void adopt(TilesetData&& set);
  template <class Decode>
  static Status load_with(Tileset& out, std::string* detail, Decode&& decode);
  TilesetData set_;
  detail::QueryTables* tables_ = nullptr;  ///< built by adopt, through the tile-set allocator
};

}  // namespace kdm
