/* Links only the installed runtime's C API: queries the built-in set and prints what it got; given a tile-set
 * file, loads it through allocator hooks that refuse (an engine's budget), which must be KDM_OUT_OF_MEMORY
 * even in a runtime built without exceptions. */
#include <kdm/runtime/kdm_runtime.h>
#include <stdio.h>
#include <string.h>

static void* refuse(size_t bytes, size_t alignment, void* user) {
  (void)bytes, (void)alignment, (void)user;
  return NULL;
}
static void never(void* p, size_t bytes, size_t alignment, void* user) {
  (void)p, (void)bytes, (void)alignment, (void)user;
}

static int refused_loads(const char* path) {
  static char sentinel; /* a refusal sets the results to NULL */
  kdm_tileset* set = (kdm_tileset*)&sentinel;
  kdm_parallel_query* parallel = (kdm_parallel_query*)&sentinel;
  int ok;
  kdm_set_tileset_allocator(refuse, never, NULL);
  ok = kdm_tileset_load_file(path, &set) == KDM_OUT_OF_MEMORY && !set &&
       kdm_parallel_query_create(2, &parallel) == KDM_OUT_OF_MEMORY && !parallel;
  kdm_set_tileset_allocator(NULL, NULL, NULL);
  ok = ok && kdm_tileset_load_file(path, &set) == KDM_OK;
  kdm_tileset_free(set);
  printf("c: a refused allocation is KDM_OUT_OF_MEMORY: %s\n", ok ? "yes" : "no");
  return ok;
}

int main(int argc, char** argv) {
  kdm_query q;
  kdm_cursor cursor;
  kdm_tileset_info info;
  kdm_point points[4096];
  size_t n = 0;
  kdm_status s;
  memset(&q, 0, sizeof q);
  memset(&cursor, 0, sizeof cursor);
  q.struct_size = sizeof q;
  q.x1 = q.y1 = 4, q.tile_size = 1, q.scale = 100, q.density = 1;
  s = kdm_query_points(kdm_tileset_builtin(), &q, points, 4096, &n, &cursor, NULL);
  info.struct_size = sizeof info;
  if (kdm_tileset_get_info(kdm_tileset_builtin(), &info) != KDM_OK) return 1;
  printf("c: kdm %s, %zu points, %u levels\n", kdm_version(), n, info.levels);
  /* 4x4 tiles at 100 points each: tiles hold their level's nominal count within a few percent. */
  if (argc > 1 && !refused_loads(argv[1])) return 1;
  return s == KDM_OK && n > 1540 && n < 1660 ? 0 : 1;
}
