/* kdm runtime, C interface: load a baked tile set and query blue-noise points, for engines and FFI
 * (C#, Rust, Godot). Same library and semantics as kdm/runtime/query.h.
 *
 * Thread safety: a loaded kdm_tileset is immutable; queries on it may run concurrently. No function
 * here throws; every failure is a status code. Queries allocate nothing. */
#ifndef KDM_RUNTIME_H
#define KDM_RUNTIME_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum kdm_status {
  KDM_OK = 0,
  KDM_IO_ERROR = 1,
  KDM_BAD_MAGIC = 2,
  KDM_UNSUPPORTED_VERSION = 3,
  KDM_TRUNCATED = 4,
  KDM_TRAILING_BYTES = 5,
  KDM_HEADER_CHECKSUM_MISMATCH = 6,
  KDM_PAYLOAD_CHECKSUM_MISMATCH = 7,
  KDM_TOO_LARGE = 8,
  KDM_DECOMPRESSION_FAILED = 9,
  KDM_INVALID_CONTENT = 10,
  KDM_INVALID_ARGUMENT = 11,
  KDM_BUFFER_FULL = 12,
  KDM_OUT_OF_MEMORY = 13
} kdm_status;

typedef struct kdm_tileset kdm_tileset;

typedef struct kdm_point {
  double x, y;            /* world position minus the query origin */
  int64_t tile_x, tile_y; /* stable id: tile coordinates ... */
  uint32_t rank;          /* ... and rank within the tile */
} kdm_point;

typedef struct kdm_query {
  double x0, y0, x1, y1;     /* half-open world region [x0, x1) x [y0, y1) */
  double origin_x, origin_y; /* subtracted from every output position */
  double tile_size;          /* world units per tile side (> 0) */
  double scale;              /* points per unit area at density 1 (>= 0) */
  double density;            /* constant density, used when density_callback is NULL */
  /* Optional: density at world (x, y); NaN, negative and infinite values count as 0. */
  double (*density_callback)(void* user, double x, double y);
  void* user;
  double density_max; /* upper bound of the callback's values */
} kdm_query;

typedef struct kdm_cursor {
  int64_t tile_x, tile_y;
  uint32_t rank;
  int started, finished;
} kdm_cursor; /* zero-initialise before the first call */

/* Loads a tile-set file / memory buffer (untrusted input is validated). *out receives a new handle to
 * free with kdm_tileset_free, or NULL on failure. */
kdm_status kdm_tileset_load_file(const char* path, kdm_tileset** out);
kdm_status kdm_tileset_load_memory(const void* data, size_t size, kdm_tileset** out);
/* The default tile set compiled into the library. Never free it. */
const kdm_tileset* kdm_tileset_builtin(void);
void kdm_tileset_free(kdm_tileset* tileset);
/* Heap bytes a loaded set occupies (positions, keys, emission thresholds, tables); 0 for NULL. */
size_t kdm_tileset_resident_bytes(const kdm_tileset* tileset);

/* Writes up to `capacity` points into `out`, *written = count. KDM_OK when the region is complete,
 * KDM_BUFFER_FULL to be resumed with the same cursor, KDM_INVALID_ARGUMENT for bad parameters. */
kdm_status kdm_query_points(const kdm_tileset* tileset, const kdm_query* query, kdm_point* out,
                            size_t capacity, size_t* written, kdm_cursor* cursor);

/* A static English description of `status`. */
const char* kdm_status_message(kdm_status status);

#ifdef __cplusplus
}
#endif

#endif /* KDM_RUNTIME_H */
