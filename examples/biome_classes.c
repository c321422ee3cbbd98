/* Trees, bushes and rocks from one biome map, through the C API: one joint callback gives all three
 * densities at a position (the biome is looked up once for them), its bounds let the query skip the
 * callback wherever they settle a point, and every point comes with its class. Prints each class's count
 * against the count its density asks for; exits 1 if one is off by more than 3% (the tests run it). */
#include <kdm/runtime/kdm_runtime.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

/* The biome: 1 in forest, 0 on rock, varying over about 80 world units. */
static double forest(double x, double y) {
  return 0.5 + 0.5 * sin(x / 40.0) * sin(y / 40.0);
}
/* Its gradient is at most 0.5 / 40 · √2 long, which bounds it over a rectangle around the centre's value. */
static const double kForestSlope = 0.5 / 40.0 * 1.4142135623730951;

/* Objects per square world unit: trees and bushes in the forest (largest first), rocks on rock. */
static const double kMost[3] = {0.02, 0.08, 0.05};
static void densities(double f, double* values) {
  values[0] = kMost[0] * f, values[1] = kMost[1] * f, values[2] = kMost[2] * (1 - f);
}

static void biome_densities(void* user, double x, double y, double* values) {
  (void)user;
  densities(forest(x, y), values);
}

static void biome_bounds(void* user, double x0, double y0, double x1, double y1, double* lo, double* hi) {
  const double reach = kForestSlope * 0.5 * hypot(x1 - x0, y1 - y0);
  const double f = forest(0.5 * (x0 + x1), 0.5 * (y0 + y1));
  const double f_lo = f - reach > 0 ? f - reach : 0, f_hi = f + reach < 1 ? f + reach : 1;
  (void)user;
  densities(f_lo, lo), densities(f_hi, hi);
  { /* rocks fall as the forest rises */
    const double rocks_lo = hi[2];
    hi[2] = lo[2], lo[2] = rocks_lo;
  }
}

int main(void) {
  static float xy[2 * 4096];
  static uint8_t classes[4096];
  const char* names[3] = {"trees", "bushes", "rocks"};
  const kdm_tileset* tiles = kdm_tileset_builtin();
  kdm_joint_class_density joint;
  kdm_query q;
  kdm_cursor cursor;
  kdm_query_problem problem;
  kdm_status status;
  size_t written = 0, counts[3] = {0, 0, 0}, i;
  double expected[3] = {0, 0, 0};
  int k, failed = 0;

  memset(&joint, 0, sizeof joint);
  joint.densities = biome_densities, joint.density_bounds = biome_bounds;
  for (k = 0; k < 3; ++k) joint.density_max[k] = kMost[k];
  memset(&q, 0, sizeof q);
  q.struct_size = sizeof q;
  q.x1 = q.y1 = 1000, q.tile_size = 64, q.scale = 1, q.mode = KDM_MODE_STABLE;
  memset(&cursor, 0, sizeof cursor);
  memset(&problem, 0, sizeof problem);
  problem.struct_size = sizeof problem;
  do { /* a 4096-point buffer, resumed until the region is done */
    status = kdm_query_classes_joint_compact(tiles, &q, &joint, 3, xy, NULL, classes, 4096, &written, &cursor,
                                             &problem);
    if (status != KDM_OK && status != KDM_BUFFER_FULL) {
      char why[256];
      kdm_query_problem_describe(&problem, why, sizeof why);
      fprintf(stderr, "query: %s: %s\n", kdm_status_message(status), why);
      return 1;
    }
    for (i = 0; i < written; ++i) ++counts[classes[i]];
  } while (status == KDM_BUFFER_FULL);

  { /* what the densities ask for: their integrals over the region, by the midpoint rule */
    double x, y, v[3];
    for (y = 0.5; y < 1000; y += 1)
      for (x = 0.5; x < 1000; x += 1) {
        biome_densities(NULL, x, y, v);
        for (k = 0; k < 3; ++k) expected[k] += v[k];
      }
  }
  for (k = 0; k < 3; ++k) {
    const double off = counts[k] / expected[k] - 1;
    printf("%-6s %7zu points, %9.1f expected (%+.2f%%)\n", names[k], counts[k], expected[k], 100 * off);
    failed |= fabs(off) > 0.03;
  }
  return failed;
}
