/* Loads the tile set a C project embedded at build time (kdm_bake_tileset's EMBED) and queries it. */
#include <kdm/runtime/kdm_runtime.h>
#include <stdio.h>
#include <string.h>

#include "small_set.h"

int main(void) {
  kdm_tileset* set = NULL;
  kdm_tileset_info info;
  kdm_query q;
  kdm_cursor cursor;
  kdm_point points[4096];
  size_t n = 0;
  if (kdm_tileset_load_memory(small_set, small_set_size, &set) != KDM_OK) return 1;
  info.struct_size = sizeof info;
  if (kdm_tileset_get_info(set, &info) != KDM_OK) return 1;
  memset(&q, 0, sizeof q);
  memset(&cursor, 0, sizeof cursor);
  q.struct_size = sizeof q;
  q.x1 = q.y1 = 4, q.tile_size = 1, q.scale = 64, q.density = 1;
  if (kdm_query_points(set, &q, points, 4096, &n, &cursor, NULL) != KDM_OK) return 1;
  kdm_tileset_free(set);
  printf("c: embedded set of %zu bytes, %u levels, %zu points\n", small_set_size, info.levels, n);
  /* 4x4 tiles at 64 points each: tiles hold their level's nominal count within a few percent. */
  return info.levels == 2 && n > 950 && n < 1100 ? 0 : 1;
}
