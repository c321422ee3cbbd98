// Loading a tile set for queries (kdm/runtime/tileset.h): the data and the tables the query loop reads
// (the built-in set: builtin.cpp).
#include "kdm/runtime/tileset.h"

#include <algorithm>
#include <new>
#include <utility>

#include "kdm/runtime/hash.h"
#include "query_tables.h"

namespace kdm {
namespace {

/// Colour of the tile-grid vertex (vx, vy): a hash, so every region is assembled locally.
std::uint32_t vertex_colour(std::int64_t vx, std::int64_t vy, std::uint32_t colours) {
  const std::uint64_t h =
      mix64(mix64(static_cast<std::uint64_t>(vx) + 0x6b647469ull) ^ static_cast<std::uint64_t>(vy));
  return static_cast<std::uint32_t>(h % colours);
}

/// The tables live in the tile-set allocator's memory, like every array they hold, and go back to the
/// hooks they came from.
detail::QueryTables* make_tables(const TilesetData& set) {
  TilesetAllocator<detail::QueryTables> from;
  void* memory = from.allocate(1);
#if defined(__cpp_exceptions) || defined(__EXCEPTIONS)
  try {
#endif
    detail::QueryTables* tables = new (memory) detail::QueryTables(set);
    tables->hooks = from.hooks;
    return tables;
#if defined(__cpp_exceptions) || defined(__EXCEPTIONS)
  } catch (...) {  // a placement new gives nothing back when the constructor throws
    from.deallocate(static_cast<detail::QueryTables*>(memory), 1);
    throw;
  }
#endif
}

void free_tables(detail::QueryTables* tables) {
  if (!tables) return;
  TilesetAllocator<detail::QueryTables> from;
  from.hooks = tables->hooks;
  tables->~QueryTables();
  from.deallocate(tables, 1);
}

}  // namespace

Tileset::~Tileset() {
  free_tables(tables_);
}

Tileset::Tileset(const Tileset& other) : set_(other.set_) {
  if (other.tables_) tables_ = make_tables(set_);
}

Tileset::Tileset(Tileset&& other) noexcept : set_(std::move(other.set_)), tables_(other.tables_) {
  other.set_ = TilesetData{};
  other.tables_ = nullptr;
}

Tileset& Tileset::operator=(const Tileset& other) {
  if (this != &other) *this = Tileset(other);
  return *this;
}

Tileset& Tileset::operator=(Tileset&& other) noexcept {
  if (this != &other) {
    free_tables(tables_);
    set_ = std::move(other.set_), tables_ = other.tables_;
    other.set_ = TilesetData{}, other.tables_ = nullptr;
  }
  return *this;
}

void Tileset::adopt(TilesetData&& set) {
  free_tables(tables_);
  tables_ = nullptr;
  set_ = std::move(set);
  tables_ = make_tables(set_);
}

/// decode() into a set `out` adopts: an allocation refused on the way (the query tables come last) is
/// kOutOfMemory with `out` left empty, not an exception through a caller that asked for a status.
template <class Decode>
Status Tileset::load_with(Tileset& out, std::string* detail, Decode&& decode) {
  out = Tileset{};
  (void)detail;  // said only where an exception can be caught
#if defined(__cpp_exceptions) || defined(__EXCEPTIONS)
  try {
#endif
    TilesetData set;
    const Status s = decode(set);
    if (s == Status::kOk) out.adopt(std::move(set));
    return s;
#if defined(__cpp_exceptions) || defined(__EXCEPTIONS)
  } catch (const std::bad_alloc&) {
    out = Tileset{};
    if (detail) *detail = "an allocation failed while the tile set was loaded";
    return Status::kOutOfMemory;
  }
#endif
}

Status Tileset::load_memory(const void* data, std::size_t size, Tileset& out, std::string* detail) {
  return load_with(out, detail, [&](TilesetData& set) { return decode_tileset(data, size, set, detail); });
}

Status Tileset::load_file(const std::string& path, Tileset& out, std::string* detail) {
  return load_with(out, detail, [&](TilesetData& set) { return load_tileset(path, set, detail); });
}

std::size_t Tileset::tile_index_at(std::int64_t tx, std::int64_t ty) const {
  const std::uint32_t c = set_.colours;
  if (c == 1) return 0;
  return set_.tile_index(vertex_colour(tx, ty, c), vertex_colour(tx + 1, ty, c),
                         vertex_colour(tx + 1, ty + 1, c), vertex_colour(tx, ty + 1, c));
}

double Tileset::glide_reach() const {
  double r = 0;
  if (tables_)
    for (double v : tables_->glide_reach) r = std::max(r, v);
  return r;
}

std::size_t Tileset::resident_bytes() const {
  std::size_t bytes = sizeof(*this) + set_.level_nominal.capacity() * sizeof(std::uint32_t) +
                      set_.keyframe_nominal.capacity() * sizeof(std::uint32_t) +
                      set_.tiles.capacity() * sizeof(Tile) + set_.recipe.capacity() +
                      set_.generator_version.capacity();
  for (const Tile& t : set_.tiles)
    bytes += t.points.capacity() * sizeof(TilePoint) + t.keys.capacity() * sizeof(std::uint16_t) +
             t.level_end.capacity() * sizeof(std::uint32_t) + t.glide.capacity() * sizeof(std::int8_t) +
             t.handover.capacity() * sizeof(std::uint16_t) + t.appearing.capacity() * sizeof(std::uint32_t);
  if (tables_) bytes += tables_->resident_bytes();
  return bytes;
}

}  // namespace kdm
