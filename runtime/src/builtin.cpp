// The built-in tile set (Tileset::builtin, kdm_tileset_builtin): alone in this file, so that a program
// linking the static library without asking for it does not carry its 14 MB (the linker takes an
// archive's object only for a symbol the program uses).
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <string>

#include "kdm/runtime/kdm_runtime.h"
#include "kdm/runtime/tileset.h"
#include "tileset_handle.h"

extern const unsigned char kdm_builtin_tileset[];
extern const std::size_t kdm_builtin_tileset_size;

namespace kdm {

const Tileset& Tileset::builtin() {
  static std::atomic<const Tileset*> ready{nullptr};
  if (const Tileset* set = ready.load(std::memory_order_acquire)) return *set;
  static std::mutex decoding;  // taken only until the set is decoded
  const std::lock_guard<std::mutex> lock(decoding);
  if (const Tileset* set = ready.load(std::memory_order_relaxed)) return *set;
  static Tileset set;
  static const Tileset none;
  std::string detail;
  const Status s = load_memory(kdm_builtin_tileset, kdm_builtin_tileset_size, set, &detail);
  if (s == Status::kOutOfMemory) return none;  // empty; the next call tries again
  if (s != Status::kOk) {
    // The embedded bytes were validated when the library was tested; failing here is a build bug.
    std::fprintf(stderr, "kdm: the built-in tile set does not decode: %s\n", detail.c_str());
    std::abort();
  }
  ready.store(&set, std::memory_order_release);
  return set;
}

}  // namespace kdm

extern "C" const kdm_tileset* kdm_tileset_builtin(void) {
  const kdm::Tileset& set = kdm::Tileset::builtin();
  if (set.empty()) return nullptr;  // out of memory: the next call tries again
  kdm_tileset& handle = kdm::detail::builtin_handle();
  static kdm_tileset* const shared = (handle.set = &set, &handle);  // no second copy
  return shared;
}
