/* Links only the installed runtime's C API: queries the built-in set and prints what it got. */
#include <kdm/runtime/kdm_runtime.h>
#include <stdio.h>
#include <string.h>

int main(void) {
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
  return s == KDM_OK && n > 1540 && n < 1660 ? 0 : 1;
}
