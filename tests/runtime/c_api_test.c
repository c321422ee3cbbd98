/* The C interface from C: load, query into a small buffer with resumes, bad input, status codes. */
#include <kdm/runtime/kdm_runtime.h>
#include <stdio.h>
#include <string.h>

#define CHECK(cond)                                                  \
  do {                                                               \
    if (!(cond)) {                                                   \
      fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); \
      return 1;                                                      \
    }                                                                \
  } while (0)

static size_t count_points(const kdm_tileset* set, const kdm_query* q, size_t capacity) {
  kdm_point buffer[64];
  kdm_cursor cursor;
  size_t total = 0, written = 0;
  kdm_status s;
  memset(&cursor, 0, sizeof cursor);
  do {
    s = kdm_query_points(set, q, buffer, capacity, &written, &cursor);
    total += written;
  } while (s == KDM_BUFFER_FULL);
  return s == KDM_OK ? total : (size_t)-1;
}

int main(int argc, char** argv) {
  kdm_tileset* loaded = NULL;
  kdm_query q;
  const kdm_tileset* builtin = kdm_tileset_builtin();
  CHECK(argc == 2);
  CHECK(builtin != NULL);
  CHECK(kdm_tileset_load_file(argv[1], &loaded) == KDM_OK && loaded != NULL);
  memset(&q, 0, sizeof q);
  q.x0 = 0, q.y0 = 0, q.x1 = 2, q.y1 = 2, q.tile_size = 1, q.scale = 500, q.density = 1;
  {
    const size_t a = count_points(builtin, &q, 64), b = count_points(loaded, &q, 5);
    CHECK(a > 1000 && a == b); /* same set from the file and built in; resumed buffers lose nothing */
  }
  CHECK(kdm_tileset_resident_bytes(loaded) == kdm_tileset_resident_bytes(builtin));
  CHECK(kdm_tileset_resident_bytes(loaded) > 1000000 && kdm_tileset_resident_bytes(NULL) == 0);
  q.x1 = 0.0 / 0.0;
  CHECK(count_points(builtin, &q, 64) == (size_t)-1);
  CHECK(kdm_query_points(NULL, &q, NULL, 0, NULL, NULL) == KDM_INVALID_ARGUMENT);
  {
    kdm_tileset* bad = NULL;
    CHECK(kdm_tileset_load_memory("not a tile set", 14, &bad) == KDM_BAD_MAGIC && bad == NULL);
    CHECK(kdm_tileset_load_file("/nonexistent.kdmt", &bad) == KDM_IO_ERROR && bad == NULL);
  }
  CHECK(strlen(kdm_status_message(KDM_TRUNCATED)) > 0);
  kdm_tileset_free(loaded);
  kdm_tileset_free((kdm_tileset*)builtin); /* ignored for the built-in set */
  printf("c api ok\n");
  return 0;
}
