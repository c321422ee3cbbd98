// The C interface (kdm_runtime.h) over kdm/runtime/query.h. No exception crosses it.
#include <new>

#include "kdm/runtime/kdm_runtime.h"
#include "kdm/runtime/query.h"

struct kdm_tileset {
  kdm::Tileset set;
};

namespace {

kdm_status to_c(kdm::Status s) {
  return static_cast<kdm_status>(static_cast<int>(s));
}

template <class Load>
kdm_status load_into(kdm_tileset** out, Load&& load) {
  if (!out) return KDM_INVALID_ARGUMENT;
  *out = nullptr;
  try {
    auto* handle = new kdm_tileset;
    const kdm::Status s = load(handle->set);
    if (s != kdm::Status::kOk) {
      delete handle;
      return to_c(s);
    }
    *out = handle;
    return KDM_OK;
  } catch (const std::bad_alloc&) {
    return KDM_OUT_OF_MEMORY;
  } catch (...) {
    return KDM_INVALID_CONTENT;
  }
}

}  // namespace

extern "C" {

kdm_status kdm_tileset_load_file(const char* path, kdm_tileset** out) {
  if (!path) return KDM_INVALID_ARGUMENT;
  return load_into(out, [&](kdm::Tileset& t) { return kdm::Tileset::load_file(path, t); });
}

kdm_status kdm_tileset_load_memory(const void* data, size_t size, kdm_tileset** out) {
  if (!data && size) return KDM_INVALID_ARGUMENT;
  return load_into(out, [&](kdm::Tileset& t) { return kdm::Tileset::load_memory(data, size, t); });
}

const kdm_tileset* kdm_tileset_builtin(void) {
  static const kdm_tileset* builtin = new kdm_tileset{kdm::Tileset::builtin()};
  return builtin;
}

void kdm_tileset_free(kdm_tileset* tileset) {
  if (tileset != kdm_tileset_builtin()) delete tileset;
}

size_t kdm_tileset_resident_bytes(const kdm_tileset* tileset) {
  return tileset ? tileset->set.resident_bytes() : 0;
}

kdm_status kdm_query_points(const kdm_tileset* tileset, const kdm_query* query, kdm_point* out,
                            size_t capacity, size_t* written, kdm_cursor* cursor) {
  if (!tileset || !query || !written || !cursor) return KDM_INVALID_ARGUMENT;
  static_assert(sizeof(kdm_point) == sizeof(kdm::QueryPoint), "kdm_point mirrors QueryPoint");
  kdm::QueryParams q;
  q.x0 = query->x0, q.y0 = query->y0, q.x1 = query->x1, q.y1 = query->y1;
  q.origin_x = query->origin_x, q.origin_y = query->origin_y;
  q.tile_size = query->tile_size, q.scale = query->scale;
  if (query->density_callback) {
    q.density.kind = kdm::QueryDensity::Kind::kCallback;
    q.density.callback = query->density_callback;
    q.density.user = query->user;
    q.density.callback_max = query->density_max;
  } else {
    q.density.constant = query->density;
  }
  kdm::QueryCursor c{cursor->tile_x, cursor->tile_y, cursor->rank, cursor->started != 0,
                     cursor->finished != 0};
  // kdm_point and QueryPoint share their layout (asserted above): write straight into the caller's buffer.
  const kdm::Status s =
      kdm::query_points(tileset->set, q, reinterpret_cast<kdm::QueryPoint*>(out), capacity, written, &c);
  *cursor = kdm_cursor{c.tile_x, c.tile_y, c.rank, c.started ? 1 : 0, c.finished ? 1 : 0};
  return to_c(s);
}

const char* kdm_status_message(kdm_status status) {
  if (status == KDM_OUT_OF_MEMORY) return "out of memory";
  return kdm::status_message(static_cast<kdm::Status>(static_cast<int>(status)));
}

}  // extern "C"
