// The default tile set compiled into the library (generated from tilesets/default.kdmt).
#include <cstdio>
#include <cstdlib>

#include "kdm/runtime/query.h"

extern const unsigned char kdm_builtin_tileset[];
extern const std::size_t kdm_builtin_tileset_size;

namespace kdm {

const Tileset& Tileset::builtin() {
  static const Tileset set = [] {
    Tileset t;
    std::string detail;
    if (load_memory(kdm_builtin_tileset, kdm_builtin_tileset_size, t, &detail) != Status::kOk) {
      // The embedded bytes were validated when the library was tested; failing here is a build bug.
      std::fprintf(stderr, "kdm: the built-in tile set does not decode: %s\n", detail.c_str());
      std::abort();
    }
    return t;
  }();
  return set;
}

}  // namespace kdm
