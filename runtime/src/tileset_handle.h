// The C API's tile-set handle (kdm_runtime.h's opaque kdm_tileset), shared by kdm_runtime.cpp and
// builtin.cpp.
#pragma once

#include "kdm/runtime/tileset.h"

struct kdm_tileset {
  kdm::Tileset owned;                // empty for the built-in set
  const kdm::Tileset* set = &owned;  // what queries read: `owned`, or the one built-in copy
};

namespace kdm::detail {
/// The built-in set's handle, known without decoding the set, which only kdm_tileset_builtin() does:
/// freeing another set must not decode it.
kdm_tileset& builtin_handle();
}  // namespace kdm::detail
