// Where a tile set's memory comes from: one hook, so an engine can put loaded tile sets in its own heap,
// count them, and bound what loading a set it did not bake may cost. Everything a TilesetData and a loaded
// Tileset hold in arrays (positions, keys, level tables, emission thresholds) is allocated through it, and
// so is every sizeable allocation a load makes on the way: the file's bytes (load_file), zstd's context
// and window (the frame's window size, at most the body's size: 8 MiB for the built-in set) and the
// checks' scratch. Not through it: the short recipe and version texts, messages and a stream object, each
// under 64 KiB. A request the hook refuses makes the load return kOutOfMemory before that memory is
// touched, with nothing it took left taken. The body is parsed as zstd decompresses it, never held whole,
// so a small file that claims a large body costs zstd's window, not the body, and is refused where its
// content stops making sense.
// What a load of the built-in set takes through the hook at its peak: from memory 33.0 MB (its 31.9 MB
// loaded; zstd's window goes before the query tables are built), from its file 47.3 MB (the file's
// 14.3 MB beside the window and the arrays as they fill). TilesetAllocatorTest checks both; a program that
// loads it (`kdm info`) peaks at about 50 MiB resident.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <new>
#include <type_traits>
#include <vector>

#include "kdm/runtime/export.h"

namespace kdm {

/// An allocation hook. Both functions must be set, or neither (operator new / delete then serve).
struct AllocatorHooks {
  /// Returns `bytes` bytes aligned to `alignment` (a power of two, at most alignof(std::max_align_t)), or
  /// null when out of memory.
  void* (*allocate)(std::size_t bytes, std::size_t alignment, void* user) = nullptr;
  /// Frees what `allocate` returned, with the same size and alignment.
  void (*deallocate)(void* p, std::size_t bytes, std::size_t alignment, void* user) = nullptr;
  void* user = nullptr;
};

/// Installs `hooks` for tile-set memory allocated from now on (default hooks restore operator new).
/// Memory is always freed through the hooks it came from, so switching is safe, but call it while no
/// other thread is loading or copying a tile set (at start-up, typically).
KDM_RUNTIME_API void set_tileset_allocator(const AllocatorHooks& hooks);

/// The hooks in force (what new tile-set arrays will use).
KDM_RUNTIME_API AllocatorHooks tileset_allocator();

namespace detail {
/// Throws std::bad_alloc for an allocation the hook refused. Out of line, in a file the runtime builds with
/// exceptions even where an engine turns them off, so that a load still returns kOutOfMemory.
[[noreturn]] KDM_RUNTIME_API void tileset_allocation_refused();
}  // namespace detail

/// A standard allocator over the hooks in force when it was made; it keeps them, so its memory goes
/// back where it came from. An allocation the hook refuses throws std::bad_alloc (detail::
/// tileset_allocation_refused), which a load returns as kOutOfMemory. A copy of a Tileset or TilesetData
/// throws it to the caller: in code built without exceptions that ends the program, so where a refusal
/// must be survived, load again rather than copy.
template <class T>
struct TilesetAllocator {
  using value_type = T;
  using propagate_on_container_copy_assignment = std::true_type;
  using propagate_on_container_move_assignment = std::true_type;
  using propagate_on_container_swap = std::true_type;

  AllocatorHooks hooks = tileset_allocator();

  TilesetAllocator() = default;
  template <class U>
  TilesetAllocator(const TilesetAllocator<U>& other) : hooks(other.hooks) {}

  T* allocate(std::size_t n) {
    const std::size_t bytes = n * sizeof(T);
    void* p = hooks.allocate ? hooks.allocate(bytes, alignof(T), hooks.user) : ::operator new(bytes);
    if (!p) detail::tileset_allocation_refused();
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t n) {
    if (hooks.deallocate)
      hooks.deallocate(p, n * sizeof(T), alignof(T), hooks.user);
    else
      ::operator delete(p);
  }
  template <class U>
  friend bool operator==(const TilesetAllocator& a, const TilesetAllocator<U>& b) {
    return a.hooks.allocate == b.hooks.allocate && a.hooks.deallocate == b.hooks.deallocate &&
           a.hooks.user == b.hooks.user;
  }
  template <class U>
  friend bool operator!=(const TilesetAllocator& a, const TilesetAllocator<U>& b) {
    return !(a == b);
  }
};

/// The arrays of tile-set data: std::vector on the tile-set allocator.
template <class T>
using TilesetArray = std::vector<T, TilesetAllocator<T>>;

}  // namespace kdm
