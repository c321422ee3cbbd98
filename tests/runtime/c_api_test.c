/* The C interface from C: load, query into a small buffer with resumes, density images, tile-set info,
 * bad input with its detail, cursor misuse, status codes. */
#include <kdm/runtime/kdm_runtime.h>
#include <limits.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "c_check.h"

static size_t count_points(const kdm_tileset* set, const kdm_query* q, size_t capacity) {
  kdm_point buffer[64];
  kdm_cursor cursor;
  size_t total = 0, written = 0;
  kdm_status s;
  memset(&cursor, 0, sizeof cursor);
  do {
    s = kdm_query_points(set, q, buffer, capacity, &written, &cursor, NULL);
    total += written;
  } while (s == KDM_BUFFER_FULL);
  return s == KDM_OK ? total : (size_t)-1;
}

static size_t g_hooked_bytes = 0;
static void* hooked_allocate(size_t bytes, size_t alignment, void* user) {
  (void)alignment;
  *(size_t*)user += bytes;
  return malloc(bytes ? bytes : 1);
}
static void* failing_allocate(size_t bytes, size_t alignment, void* user) {
  (void)bytes, (void)alignment, (void)user;
  return NULL;
}
/* Counts its calls and refuses the one numbered g_refuse_at (counting from 0; never if negative). */
static long g_allocations = 0, g_refuse_at = -1;
static void* refusing_allocate(size_t bytes, size_t alignment, void* user) {
  if (g_allocations++ == g_refuse_at) return NULL;
  return hooked_allocate(bytes, alignment, user);
}
static void hooked_deallocate(void* p, size_t bytes, size_t alignment, void* user) {
  (void)alignment;
  *(size_t*)user -= bytes;
  free(p);
}

/* A ramp in x counting its calls, and its bounds over a rectangle. */
static long g_ramp_calls = 0;
static double ramp(void* user, double x, double y) {
  (void)user, (void)y;
  ++g_ramp_calls;
  return 0.2 + 0.1 * x;
}
static void ramp_bounds(void* user, double x0, double y0, double x1, double y1, double* lo, double* hi) {
  (void)user, (void)y0, (void)y1;
  *lo = 0.2 + 0.1 * x0, *hi = 0.2 + 0.1 * x1;
}
/* Bounds that record whether the library handed them NaN, and write nothing. */
static int g_bounds_preset_nan = 1;
static void silent_bounds(void* user, double x0, double y0, double x1, double y1, double* lo, double* hi) {
  (void)user, (void)x0, (void)y0, (void)x1, (void)y1;
  if (!(*lo != *lo && *hi != *hi)) g_bounds_preset_nan = 0;
}
/* What kdm_runtime.h tells a binding to do once its callback has failed: bounds of 0 everywhere. */
static void given_up_bounds(void* user, double x0, double y0, double x1, double y1, double* lo, double* hi) {
  (void)user, (void)x0, (void)y0, (void)x1, (void)y1;
  *lo = *hi = 0;
}
/* The ramp at n positions (density_batch_callback), counting its calls and values. */
static long g_batch_calls = 0, g_batch_values = 0;
static void ramp_batch(void* user, size_t n, const double* x, const double* y, double* out) {
  size_t i;
  (void)user, (void)y;
  ++g_batch_calls, g_batch_values += (long)n;
  for (i = 0; i < n; ++i) out[i] = 0.2 + 0.1 * x[i];
}
/* Two classes from one call: the ramp's value for each (at n positions: class k's value i at
 * values[k * n + i]), and their bounds. */
static void two_ramps_batch(void* user, size_t n, const double* x, const double* y, double* values) {
  size_t i;
  (void)user, (void)y;
  ++g_batch_calls, g_batch_values += (long)n;
  for (i = 0; i < n; ++i) values[i] = values[n + i] = 0.2 + 0.1 * x[i];
}
static void two_ramps(void* user, double x, double y, double* values) {
  values[0] = values[1] = ramp(user, x, y);
}
static void two_ramp_bounds(void* user, double x0, double y0, double x1, double y1, double* lo, double* hi) {
  ramp_bounds(user, x0, y0, x1, y1, lo, hi);
  lo[1] = lo[0], hi[1] = hi[0];
}

/* 0.5, or `bad` (user) from x = 1.5 on; in a batch, too. */
static double flawed(void* user, double x, double y) {
  (void)y;
  return x >= 1.5 ? *(const double*)user : 0.5;
}
static void flawed_batch(void* user, size_t n, const double* x, const double* y, double* out) {
  size_t i;
  for (i = 0; i < n; ++i) out[i] = flawed(user, x[i], y[i]);
}

/* Two classes from one call: 0.25 everywhere, and class 1 `flawed`'s value. */
static void flawed_joint(void* user, double x, double y, double* values) {
  values[0] = 0.25, values[1] = flawed(user, x, y);
}

static kdm_query uniform_query(void) {
  kdm_query q;
  memset(&q, 0, sizeof q);
  q.struct_size = sizeof q;
  q.x0 = 0, q.y0 = 0, q.x1 = 2, q.y1 = 2, q.tile_size = 1, q.scale = 500, q.density = 1;
  return q;
}

int main(int argc, char** argv) {
  kdm_tileset* loaded = NULL;
  kdm_query q = uniform_query();
  kdm_query_problem problem;
  const kdm_tileset* builtin = NULL;
  CHECK(argc == 2);
  /* The layouts kdm_runtime.h states for bindings on LP64 platforms. */
  if (sizeof(void*) == 8 && sizeof(long) == 8) {
    CHECK(sizeof(kdm_point) == 40 && sizeof(kdm_query) == 144 && offsetof(kdm_query, mode) == 112);
    CHECK(sizeof(kdm_cursor) == 56 && sizeof(kdm_query_problem) == 56);
    CHECK(sizeof(kdm_tileset_info) == 144 && offsetof(kdm_tileset_info, keyframes) == 120);
    CHECK(sizeof(kdm_class_density) == 56 && sizeof(kdm_joint_class_density) == 96);
  }
  /* Freeing no set (or a loaded one) leaves the built-in set undecoded: nothing reaches the allocator. */
  kdm_set_tileset_allocator(hooked_allocate, hooked_deallocate, &g_hooked_bytes);
  kdm_tileset_free(NULL);
  kdm_set_tileset_allocator(NULL, NULL, NULL);
  /* The built-in set, decoded on first use, is NULL while memory runs out, and there once it does not. */
  kdm_set_tileset_allocator(failing_allocate, hooked_deallocate, &g_hooked_bytes);
  CHECK(kdm_tileset_builtin() == NULL && g_hooked_bytes == 0);
  kdm_set_tileset_allocator(NULL, NULL, NULL);
  CHECK(kdm_tileset_builtin() != NULL && kdm_tileset_builtin() == kdm_tileset_builtin());
  CHECK(g_hooked_bytes == 0);
  builtin = kdm_tileset_builtin();
  CHECK(builtin != NULL);
  CHECK(kdm_tileset_load_file(argv[1], &loaded) == KDM_OK && loaded != NULL);
  {
    const size_t a = count_points(builtin, &q, 64), b = count_points(loaded, &q, 5);
    CHECK(a > 1000 && a == b); /* same set from the file and built in; resumed buffers lose nothing */
    {
      /* kdm_count_points counts what the query writes, with a cursor of its own. */
      kdm_cursor cursor;
      kdm_query_problem problem;
      size_t counted = 0, total = 0;
      kdm_status s;
      memset(&cursor, 0, sizeof cursor);
      problem.struct_size = sizeof problem;
      while ((s = kdm_count_points(builtin, &q, &counted, &cursor, &problem)) == KDM_BUFFER_FULL)
        total += counted;
      CHECK(s == KDM_OK && total + counted == a);
      CHECK(kdm_query_points(builtin, &q, NULL, 0, &counted, &cursor, &problem) == KDM_INVALID_ARGUMENT &&
            problem.kind == KDM_PROBLEM_CURSOR_MISMATCH);
      memset(&cursor, 0, sizeof cursor);
      CHECK(kdm_count_points(builtin, &q, NULL, &cursor, &problem) == KDM_INVALID_ARGUMENT &&
            problem.kind == KDM_PROBLEM_MISSING_ARGUMENT && strcmp(problem.parameter, "count") == 0);
      CHECK(kdm_count_points(NULL, &q, &counted, &cursor, &problem) == KDM_INVALID_ARGUMENT &&
            strcmp(problem.parameter, "tileset") == 0 && counted == 0);
    }
  }
  /* Every point's threshold lies below its tile's expected count (500 here), and an id the set does not
   * have, or a NULL argument, is refused. */
  {
    kdm_point buffer[256];
    kdm_cursor cursor;
    size_t written = 0, i;
    double t = 0, highest = 0;
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_points(builtin, &q, buffer, 256, &written, &cursor, NULL) == KDM_BUFFER_FULL);
    for (i = 0; i < written; ++i) {
      CHECK(kdm_point_threshold(builtin, &buffer[i], &t) == KDM_OK && t >= 0 && t < 500);
      highest = t > highest ? t : highest;
    }
    CHECK(highest > 100); /* the first 256 points span several levels of 32, 128, 512 points */
    CHECK(kdm_point_threshold(NULL, &buffer[0], &t) == KDM_INVALID_ARGUMENT);
    CHECK(kdm_point_threshold(builtin, NULL, &t) == KDM_INVALID_ARGUMENT);
    CHECK(kdm_point_threshold(builtin, &buffer[0], NULL) == KDM_INVALID_ARGUMENT);
    buffer[0].rank = 1u << 30;
    CHECK(kdm_point_threshold(builtin, &buffer[0], &t) == KDM_INVALID_ARGUMENT);
    buffer[1].depth = 99;
    CHECK(kdm_point_threshold(builtin, &buffer[1], &t) == KDM_INVALID_ARGUMENT);
  }
  /* A compact point's threshold from its key and a tile of the region: its point's, negative tiles too. */
  {
    kdm_query k = uniform_query();
    kdm_point points[64];
    float xy[128];
    uint64_t keys[64];
    kdm_cursor c1, c2;
    size_t n1 = 0, n2 = 0, i;
    double a = 0, b = 0;
    k.x0 = -3.5, k.x1 = -2.9, k.y0 = -7.2, k.y1 = -6.6, k.origin_x = -3.5, k.origin_y = -7.2;
    memset(&c1, 0, sizeof c1), memset(&c2, 0, sizeof c2);
    CHECK(kdm_query_points(builtin, &k, points, 64, &n1, &c1, NULL) != KDM_INVALID_ARGUMENT);
    CHECK(kdm_query_compact(builtin, &k, xy, keys, 64, &n2, &c2, NULL) != KDM_INVALID_ARGUMENT);
    CHECK(n1 == n2 && n1 > 30);
    for (i = 0; i < n1; ++i) {
      CHECK(kdm_point_threshold(builtin, &points[i], &a) == KDM_OK);
      CHECK(kdm_key_threshold(builtin, keys[i], -4, -8, &b) == KDM_OK && a == b);
    }
    CHECK(points[0].tile_x < 0 && points[0].tile_y < 0);
    CHECK(kdm_key_threshold(NULL, keys[0], -4, -8, &b) == KDM_INVALID_ARGUMENT);
    CHECK(kdm_key_threshold(builtin, keys[0], -4, -8, NULL) == KDM_INVALID_ARGUMENT);
    CHECK(kdm_key_threshold(builtin, keys[0] | ((uint64_t)7 << 61), -4, -8, &b) == KDM_INVALID_ARGUMENT);
    /* a near tile that cannot be scaled to the key's depth names no tile */
    CHECK(kdm_key_threshold(builtin, (uint64_t)1 << 61, INT64_MAX, INT64_MIN, &b) == KDM_INVALID_ARGUMENT);
  }
  CHECK(kdm_tileset_resident_bytes(loaded) == kdm_tileset_resident_bytes(builtin));
  CHECK(kdm_tileset_resident_bytes(loaded) > 1000000 && kdm_tileset_resident_bytes(NULL) == 0);

  /* Tile-set info and versions. */
  {
    kdm_tileset_info info;
    memset(&info, 0, sizeof info);
    CHECK(kdm_tileset_get_info(builtin, &info) == KDM_INVALID_ARGUMENT); /* struct_size not set */
    info.struct_size = sizeof info;
    CHECK(kdm_tileset_get_info(builtin, &info) == KDM_OK);
    CHECK(info.struct_size == sizeof info);
    CHECK(info.format_version >= 4 &&
          info.format_version <= kdm_tileset_format_version()); /* 4: no hand-over */
    CHECK(info.colours == 2 && info.tiles == 16 && info.levels == 6);
    CHECK(info.level_points[0] == 32 && info.level_points[5] == 32768 && info.max_points_per_tile == 32768);
    CHECK(info.resident_bytes == kdm_tileset_resident_bytes(builtin));
    /* Smooth queries reach m^8 times the top level with a hand-over to m x m subtiles, else the top. */
    CHECK(info.subtiles_per_side == 0
              ? info.smooth_limit_per_tile == 32768.0
              : info.smooth_limit_per_tile == 32768.0 * pow(info.subtiles_per_side, 8));
    /* m subtiles per side hold at their hand-over level as many points as the tile's top level. */
    CHECK(info.subtiles_per_side == 0 ||
          info.level_points[info.handover_level] * info.subtiles_per_side * info.subtiles_per_side == 32768);
    CHECK(info.handover_slack <= 16 && (info.subtiles_per_side > 0 || info.handover_slack == 0));
    CHECK(strstr(info.recipe, "base_points") != NULL && strlen(info.generator_version) > 0);
    CHECK(strchr(kdm_version(), '.') != NULL);
    { /* the number is the string's parts */
      unsigned major = 0, minor = 0, patch = 0;
      CHECK(sscanf(kdm_version(), "%u.%u.%u", &major, &minor, &patch) == 3);
      CHECK(kdm_version_number() == major * 10000 + minor * 100 + patch);
    }
  }

  /* A density image: zero on the left half, 1 on the right half of [0, 2)^2, so no point has x < 0.9. */
  {
    const float values[4] = {0, 1, 0, 1}; /* 2x2, row 0 at y0 */
    kdm_density_image* image = NULL;
    kdm_point buffer[4096];
    kdm_cursor cursor;
    size_t written = 0, i;
    const float bad[4] = {0, -1, 0, 1};
    CHECK(kdm_density_image_create(2, 2, bad, 0, 0, 2, 2, &image) == KDM_INVALID_ARGUMENT && image == NULL);
    CHECK(kdm_density_image_create(0, 2, values, 0, 0, 2, 2, &image) == KDM_INVALID_ARGUMENT);
    CHECK(kdm_density_image_create(2, 2, values, 0, 0, 0, 2, &image) == KDM_INVALID_ARGUMENT);
    /* A side past 2^30 texels is refused before its texels are read (INT_MAX overflowed the mips' block
       count); 4 EiB of texels within that: no memory holds their copy, which is said, not thrown. */
    CHECK(kdm_density_image_create(INT_MAX, 1, values, 0, 0, 2, 2, &image) == KDM_INVALID_ARGUMENT);
    CHECK(kdm_density_image_create(1, (1 << 30) + 1, values, 0, 0, 2, 2, &image) == KDM_INVALID_ARGUMENT);
    CHECK(kdm_density_image_create(1 << 30, 1 << 30, values, 0, 0, 2, 2, &image) == KDM_OUT_OF_MEMORY &&
          image == NULL);
    {
      /* Why, for a log: the first fault, by name and place. */
      char detail[160];
      CHECK(kdm_density_image_create_detail(2, 2, bad, 0, 0, 2, 2, &image, detail, sizeof detail) ==
            KDM_INVALID_ARGUMENT);
      CHECK(image == NULL && strstr(detail, "values[1] (column 1, row 0) is -1") != NULL);
      CHECK(kdm_density_image_create_detail(0, 2, values, 0, 0, 2, 2, &image, detail, sizeof detail) ==
            KDM_INVALID_ARGUMENT);
      CHECK(strstr(detail, "0 x 2 texels") != NULL);
      CHECK(kdm_density_image_create_detail(2, 2, values, 0, 0, 0, 2, &image, detail, sizeof detail) ==
            KDM_INVALID_ARGUMENT);
      CHECK(strstr(detail, "rectangle (0, 0, 0, 2)") != NULL);
      CHECK(kdm_density_image_create_detail(2, 2, NULL, 0, 0, 2, 2, &image, detail, sizeof detail) ==
            KDM_INVALID_ARGUMENT);
      CHECK(strstr(detail, "values is NULL") != NULL);
      CHECK(kdm_density_image_create_detail(2, 2, values, 0, 0, 2, 2, &image, detail, sizeof detail) ==
            KDM_OK);
      CHECK(image != NULL && detail[0] == '\0');
      kdm_density_image_free(image);
      image = NULL;
    }
    CHECK(kdm_density_image_create(2, 2, values, 0, 0, 2, 2, &image) == KDM_OK && image != NULL);
    /* Read as a query reads it: texel centres hold their values, half-way between them the mean. */
    CHECK(kdm_density_image_at(image, 0.5, 0.5) == 0 && kdm_density_image_at(image, 1.5, 1.5) == 1);
    CHECK(kdm_density_image_at(image, 1.0, 0.5) == 0.5 && kdm_density_image_at(image, -7, 1.5) == 0);
    CHECK(kdm_density_image_at(NULL, 1, 1) == 0);
    CHECK(kdm_density_image_at(image, NAN, 1.5) == 0 && kdm_density_image_at(image, 1.5, INFINITY) == 0);
    q.density_image = image;
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_points(builtin, &q, buffer, 4096, &written, &cursor, NULL) == KDM_OK);
    CHECK(written > 300 && written < 1200); /* about half of the ~2000 uniform points, fewer at the ramp */
    for (i = 0; i < written; ++i) CHECK(buffer[i].x >= 0.5);
    { /* A refused call sets *written to 0 and leaves the cursor: corrected, the query resumes it. */
      kdm_point small[7];
      size_t n = 99, resumed;
      kdm_cursor c, before;
      kdm_query bad = q;
      kdm_status st;
      memset(&c, 0, sizeof c);
      CHECK(kdm_query_points(builtin, &q, small, 7, &n, &c, NULL) == KDM_BUFFER_FULL);
      resumed = n;
      before = c;
      bad.tile_size = NAN;
      CHECK(kdm_query_points(builtin, &bad, small, 7, &n, &c, NULL) == KDM_INVALID_ARGUMENT && n == 0);
      CHECK(c.tile_x == before.tile_x && c.tile_y == before.tile_y && c.rank == before.rank &&
            c.started == before.started && c.finished == before.finished &&
            c.fingerprint == before.fingerprint && c.depth == before.depth && c.path == before.path);
      do {
        st = kdm_query_points(builtin, &q, small, 7, &n, &c, NULL);
        resumed += n;
      } while (st == KDM_BUFFER_FULL);
      CHECK(st == KDM_OK && resumed == written);
    }
    kdm_density_image_free(image);
    q.density_image = NULL;
  }

  /* Bad input: the status says invalid, the problem says which parameter and what limit. */
  problem.struct_size = sizeof problem;
  q.x1 = 0.0 / 0.0;
  CHECK(count_points(builtin, &q, 64) == (size_t)-1);
  {
    kdm_cursor cursor;
    size_t written = 7;
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_points(builtin, &q, NULL, 0, &written, &cursor, &problem) == KDM_INVALID_ARGUMENT);
    CHECK(written == 0 && problem.kind == KDM_PROBLEM_NOT_FINITE && strcmp(problem.parameter, "x1") == 0);
    q = uniform_query();
    q.scale = 100000; /* 100,000 points per tile: past the top level of 32,768 */
    CHECK(kdm_query_points(builtin, &q, NULL, 0, &written, &cursor, &problem) == KDM_INVALID_ARGUMENT);
    CHECK(problem.kind == KDM_PROBLEM_DENSITY_TOO_HIGH && strcmp(problem.parameter, "scale") == 0);
    CHECK(problem.limit == 32768 && fabs(problem.largest_valid - 32768) < 1e-6);
    CHECK(fabs(problem.largest_tile_size - sqrt(0.32768)) < 1e-9);
    CHECK(strlen(kdm_problem_message(problem.kind)) > 0);
    {
      /* The problem in one line, with the advice that fits; cut to the buffer, its length as snprintf's. */
      char line[300], cut[12];
      const size_t length = kdm_query_problem_describe(&problem, line, sizeof line);
      CHECK(length == strlen(line) && strstr(line, "100000 points per tile") &&
            strstr(line, "at most 32768") && strstr(line, "use scale 32768 or less, or tile_size 0.572433"));
      CHECK(kdm_query_problem_describe(&problem, cut, sizeof cut) == length &&
            strlen(cut) == sizeof cut - 1 && strncmp(cut, line, sizeof cut - 1) == 0);
      CHECK(kdm_query_problem_describe(&problem, NULL, 0) == length);
      CHECK(kdm_query_problem_describe(NULL, line, sizeof line) > 0 && strstr(line, "'problem'"));
      /* A query that is taken clears the problem, which then names no parameter. */
      kdm_cursor fresh;
      memset(&fresh, 0, sizeof fresh);
      q = uniform_query();
      CHECK(kdm_query_points(builtin, &q, NULL, 0, &written, &fresh, &problem) == KDM_BUFFER_FULL);
      CHECK(problem.kind == KDM_PROBLEM_NONE);
      kdm_query_problem_describe(&problem, line, sizeof line);
      CHECK(strcmp(line, "no problem") == 0);
      /* A kind this library does not know is told by its number, not as a blank field. */
      kdm_query_problem unknown = problem;
      unknown.kind = (kdm_problem_kind)42;
      kdm_query_problem_describe(&unknown, line, sizeof line);
      CHECK(strcmp(line, "unknown problem (kind 42)") == 0);
      CHECK(strcmp(kdm_problem_message((kdm_problem_kind)42), "unknown problem") == 0);
      CHECK(strcmp(kdm_status_message((kdm_status)42), "unknown status") == 0);
    }
    q.struct_size = offsetof(kdm_query, mode) - 8; /* older than the first struct with struct_size */
    CHECK(kdm_query_points(builtin, &q, NULL, 0, &written, &cursor, &problem) == KDM_INVALID_ARGUMENT);
    CHECK(problem.kind == KDM_PROBLEM_NOT_POSITIVE && strcmp(problem.parameter, "query.struct_size") == 0);
    CHECK(problem.value == offsetof(kdm_query, mode) - 8 && problem.limit == offsetof(kdm_query, mode));
    {
      /* Said with its limit, the first version's size, not as "must be > 0". */
      char line[200], expected[200];
      kdm_query_problem_describe(&problem, line, sizeof line);
      snprintf(expected, sizeof expected, "'query.struct_size' must be at least %zu, got %zu",
               offsetof(kdm_query, mode), offsetof(kdm_query, mode) - 8);
      CHECK(strcmp(line, expected) == 0);
      q.struct_size = 8;
      CHECK(kdm_query_points(builtin, &q, NULL, 0, &written, &cursor, &problem) == KDM_INVALID_ARGUMENT);
      kdm_query_problem_describe(&problem, line, sizeof line);
      snprintf(expected, sizeof expected, "'query.struct_size' must be at least %zu, got 8",
               offsetof(kdm_query, mode));
      CHECK(strcmp(line, expected) == 0);
      /* A problem struct too short to be read is told the same way. */
      kdm_query_problem short_problem = problem;
      short_problem.struct_size = 8;
      kdm_query_problem_describe(&short_problem, line, sizeof line);
      snprintf(expected, sizeof expected, "'problem.struct_size' must be at least %zu, got 8",
               sizeof(kdm_query_problem));
      CHECK(strcmp(line, expected) == 0);
    }
    q = uniform_query();
    q.x0 = 1e15, q.x1 = 1e15 + 1; /* a double's step there is 1/8: points would fall together */
    CHECK(kdm_query_points(builtin, &q, NULL, 0, &written, &cursor, &problem) == KDM_INVALID_ARGUMENT);
    CHECK(problem.kind == KDM_PROBLEM_TOO_FAR_FROM_ORIGIN && problem.limit < 1e15);
    q = uniform_query();
    q.density = -1; /* a constant density that is none */
    CHECK(kdm_query_points(builtin, &q, NULL, 0, &written, &cursor, &problem) == KDM_INVALID_ARGUMENT);
    CHECK(problem.kind == KDM_PROBLEM_NEGATIVE && strcmp(problem.parameter, "density") == 0);
    q.density = 0.0 / 0.0;
    CHECK(kdm_query_points(builtin, &q, NULL, 0, &written, &cursor, &problem) == KDM_INVALID_ARGUMENT);
    CHECK(problem.kind == KDM_PROBLEM_NOT_FINITE && strcmp(problem.parameter, "density") == 0);
    q = uniform_query();
    q.density_callback = ramp; /* density_max left as the zeroed struct has it: nothing would be called */
    CHECK(kdm_query_points(builtin, &q, NULL, 0, &written, &cursor, &problem) == KDM_INVALID_ARGUMENT);
    CHECK(problem.kind == KDM_PROBLEM_NOT_POSITIVE && strcmp(problem.parameter, "density_max") == 0);
    q.density_max = -1; /* "must be > 0" too, not "must not be negative", which would allow the 0 above */
    CHECK(kdm_query_points(builtin, &q, NULL, 0, &written, &cursor, &problem) == KDM_INVALID_ARGUMENT);
    CHECK(problem.kind == KDM_PROBLEM_NOT_POSITIVE && problem.value == -1);
    q = uniform_query(); /* bounds with nothing to bound: not silently the constant (0 when zeroed) */
    q.density = 0, q.density_bounds = ramp_bounds, q.density_max = 1;
    CHECK(kdm_query_points(builtin, &q, NULL, 0, &written, &cursor, &problem) == KDM_INVALID_ARGUMENT);
    CHECK(problem.kind == KDM_PROBLEM_BAD_DENSITY && strcmp(problem.parameter, "density_callback") == 0);
    q = uniform_query();
    q.mode = 7;
    CHECK(kdm_query_points(builtin, &q, NULL, 0, &written, &cursor, &problem) == KDM_INVALID_ARGUMENT);
    CHECK(problem.kind == KDM_PROBLEM_BAD_MODE && strcmp(problem.parameter, "mode") == 0);
    { /* the mode's value is told, not the problem kind's number */
      char line[160];
      kdm_query_problem_describe(&problem, line, sizeof line);
      CHECK(strstr(line, "('mode' = 7)") != NULL && strstr(line, "kind") == NULL);
    }
    q.struct_size = offsetof(kdm_query, mode); /* a caller built before `mode`: stable, whatever follows */
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_points(builtin, &q, NULL, 0, &written, &cursor, &problem) == KDM_BUFFER_FULL);
  }
  CHECK(kdm_query_points(NULL, &q, NULL, 0, NULL, NULL, NULL) == KDM_INVALID_ARGUMENT);

  /* A cursor belongs to its query: a finished one gives nothing more, and other parameters are refused. */
  {
    kdm_point buffer[16];
    kdm_cursor cursor;
    size_t written = 0;
    q = uniform_query();
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_points(builtin, &q, buffer, 16, &written, &cursor, &problem) == KDM_BUFFER_FULL);
    q.x1 = 3;
    CHECK(kdm_query_points(builtin, &q, buffer, 16, &written, &cursor, &problem) == KDM_INVALID_ARGUMENT);
    CHECK(problem.kind == KDM_PROBLEM_CURSOR_MISMATCH && written == 0);
    {
      char line[512]; /* a cursor has no number to show */
      kdm_query_problem_describe(&problem, line, sizeof line);
      CHECK(strstr(line, "('cursor')") != NULL && strstr(line, "= ") == NULL);
    }
    q.x1 = 0.5, q.y1 = 0.5, q.scale = 20;
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_points(builtin, &q, buffer, 16, &written, &cursor, &problem) == KDM_OK &&
          cursor.finished);
    CHECK(kdm_query_points(builtin, &q, buffer, 16, &written, &cursor, &problem) == KDM_OK && written == 0);
    q.x0 = 1, q.x1 = 1.5;
    CHECK(kdm_query_points(builtin, &q, buffer, 16, &written, &cursor, &problem) == KDM_INVALID_ARGUMENT);
    CHECK(problem.kind == KDM_PROBLEM_CURSOR_MISMATCH);
  }
  /* A point's stable position is where a stable query puts it. */
  {
    kdm_point points[64];
    kdm_cursor cursor;
    size_t n = 0, i;
    double x = 0, y = 0;
    q = uniform_query();
    q.origin_x = 0.5, q.origin_y = -1;
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_points(builtin, &q, points, 64, &n, &cursor, NULL) == KDM_BUFFER_FULL && n == 64);
    for (i = 0; i < n; ++i) {
      CHECK(kdm_point_stable_position(builtin, &points[i], 1, 0.5, -1, &x, &y) == KDM_OK);
      CHECK(fabs(x - points[i].x) < 1e-12 && fabs(y - points[i].y) < 1e-12);
    }
    CHECK(kdm_point_stable_position(builtin, &points[0], 0, 0, 0, &x, &y) == KDM_INVALID_ARGUMENT);
    CHECK(kdm_point_stable_position(builtin, NULL, 1, 0, 0, &x, &y) == KDM_INVALID_ARGUMENT);
    CHECK(kdm_point_stable_position(builtin, &points[0], 1, 0, 0, NULL, &y) == KDM_INVALID_ARGUMENT);
  }
  /* A tile size too small for the density is told, with one that fits the coarsest level. */
  {
    kdm_tile_size_advice advice;
    CHECK(kdm_tile_size_advise(builtin, 1, 1000, 0.01, &advice) == KDM_OK);
    CHECK(advice.kind == KDM_TILE_SIZE_UNDER_ONE_POINT && advice.tiles == 16 && advice.coarsest == 32);
    CHECK(fabs(advice.points_per_tile - 0.1) < 1e-12 && fabs(advice.tile_size - sqrt(0.032)) < 1e-12);
    CHECK(kdm_tile_size_advise(builtin, 1, 1000, 0.1, &advice) == KDM_OK);
    CHECK(advice.kind == KDM_TILE_SIZE_UNDER_COARSEST_LEVEL);
    CHECK(kdm_tile_size_advise(builtin, 1, 1000, 1, &advice) == KDM_OK && advice.kind == KDM_TILE_SIZE_EVEN);
    CHECK(kdm_tile_size_advise(NULL, 1, 1000, 1, &advice) == KDM_INVALID_ARGUMENT);
    CHECK(kdm_tile_size_advise(builtin, 1, 1000, 1, NULL) == KDM_INVALID_ARGUMENT);
  }
  /* A density check: the same points where the values fit; the first bad value and where it was read. */
  {
    static kdm_point bare[4096], checked[4096];
    kdm_density_check* check = NULL;
    kdm_class_density density;
    kdm_cursor cursor;
    size_t n_bare = 0, n_checked = 0;
    double bad = 0.5, value = 0, x = 0, y = 0;
    char line[160];
    CHECK(kdm_density_check_create(NULL) == KDM_INVALID_ARGUMENT);
    CHECK(kdm_density_check_create(&check) == KDM_OK && check != NULL);
    q = uniform_query();
    q.density_callback = flawed, q.user = &bad, q.density_max = 1;
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_points(builtin, &q, bare, 4096, &n_bare, &cursor, NULL) == KDM_OK);
    CHECK(kdm_density_check_wrap_query(check, &q) == KDM_OK && q.user == (void*)check);
    CHECK(kdm_density_check_wrap_query(check, &q) == KDM_OK && q.user == (void*)check); /* no 2nd layer */
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_points(builtin, &q, checked, 4096, &n_checked, &cursor, NULL) == KDM_OK);
    CHECK(n_bare > 300 && n_bare == n_checked && memcmp(bare, checked, n_bare * sizeof(kdm_point)) == 0);
    CHECK(kdm_density_check_failed(check, &value, &x, &y) == 0);
    CHECK(kdm_density_check_largest(check) == 0.5 && kdm_density_check_largest(NULL) == -1);
    kdm_density_check_describe(check, line, sizeof line);
    CHECK(strcmp(line, "no bad density value") == 0);
    bad = NAN; /* the same wrapped query, now with a flaw */
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_points(builtin, &q, checked, 4096, &n_checked, &cursor, NULL) == KDM_OK);
    CHECK(kdm_density_check_failed(check, &value, &x, &y) == 1 && value != value && x >= 1.5 && x < 2);
    CHECK(kdm_density_check_describe(check, line, sizeof line) == strlen(line));
    CHECK(strstr(line, "density callback returned nan at (") == line);
    kdm_density_check_reset(check);
    CHECK(kdm_density_check_failed(check, NULL, NULL, NULL) == 0);
    /* A class's batch callback above its bound. */
    memset(&density, 0, sizeof density);
    bad = 3;
    density.density_batch_callback = flawed_batch, density.user = &bad, density.density_max = 1;
    CHECK(kdm_density_check_wrap_class(check, &density) == KDM_OK && density.user == (void*)check);
    { /* another density through the same check is refused, and left as it was */
      kdm_class_density other;
      memset(&other, 0, sizeof other);
      other.density_callback = flawed, other.user = &bad, other.density_max = 1;
      CHECK(kdm_density_check_wrap_class(check, &other) == KDM_INVALID_ARGUMENT);
      CHECK(other.user == (void*)&bad && other.density_callback == flawed);
    }
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_classes(builtin, &q, &density, 1, bare, (uint8_t*)checked, 4096, &n_checked, &cursor,
                            NULL) == KDM_OK);
    CHECK(kdm_density_check_failed(check, &value, NULL, NULL) == 1 && value == 3);
    kdm_density_check_describe(check, line, sizeof line);
    CHECK(strstr(line, "above its bound callback_max 1") != NULL);
    /* A joint density's class 1 NaN right of x = 1.5: found, its class named. */
    kdm_density_check_reset(check);
    {
      kdm_joint_class_density joint;
      memset(&joint, 0, sizeof joint);
      bad = NAN;
      joint.densities = flawed_joint, joint.user = &bad, joint.density_max[0] = 1, joint.density_max[1] = 1;
      CHECK(kdm_density_check_wrap_joint(check, &joint, 0) == KDM_INVALID_ARGUMENT);
      CHECK(kdm_density_check_wrap_joint(check, &joint, KDM_MAX_CLASSES + 1) == KDM_INVALID_ARGUMENT);
      CHECK(kdm_density_check_wrap_joint(check, NULL, 2) == KDM_INVALID_ARGUMENT);
      CHECK(joint.user == (void*)&bad);
      CHECK(kdm_density_check_wrap_joint(check, &joint, 2) == KDM_OK && joint.user == (void*)check);
      memset(&cursor, 0, sizeof cursor);
      CHECK(kdm_query_classes_joint(builtin, &q, &joint, 2, bare, (uint8_t*)checked, 4096, &n_checked,
                                    &cursor, NULL) == KDM_OK);
      CHECK(kdm_density_check_failed(check, &value, &x, NULL) == 1 && value != value && x >= 1.5);
      kdm_density_check_describe(check, line, sizeof line);
      CHECK(strstr(line, "joint density's class 1 was nan at (") == line);
    }
    /* Constants are left alone; NULL arguments are refused or told. */
    q = uniform_query();
    CHECK(kdm_density_check_wrap_query(check, &q) == KDM_OK && q.user == NULL && q.density_callback == NULL);
    CHECK(kdm_density_check_wrap_query(NULL, &q) == KDM_INVALID_ARGUMENT);
    CHECK(kdm_density_check_wrap_query(check, NULL) == KDM_INVALID_ARGUMENT);
    CHECK(kdm_density_check_wrap_class(check, NULL) == KDM_INVALID_ARGUMENT);
    CHECK(kdm_density_check_failed(NULL, &value, &x, &y) == 0);
    CHECK(kdm_density_check_describe(NULL, line, sizeof line) == strlen(line) && strstr(line, "NULL"));
    kdm_density_check_free(check);
    kdm_density_check_free(NULL);
  }
  /* Several classes: class 0 is the one-class query at its density, the union the one at the sum. */
  {
    static kdm_point points[4096], single[4096];
    static uint8_t classes[4096];
    kdm_class_density densities[3];
    kdm_cursor cursor;
    size_t written = 0, alone = 0, zeros = 0, i;
    memset(densities, 0, sizeof densities);
    densities[0].density = 1, densities[1].density = 2, densities[2].density = 4;
    q = uniform_query();
    q.scale = 100;
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_classes(builtin, &q, densities, 3, points, classes, 4096, &written, &cursor, &problem) ==
          KDM_OK);
    q.density = 1;
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_points(builtin, &q, single, 4096, &alone, &cursor, NULL) == KDM_OK);
    for (i = 0; i < written; ++i) {
      CHECK(classes[i] < 3);
      if (classes[i] == 0) CHECK(memcmp(&points[i], &single[zeros++], sizeof(kdm_point)) == 0);
    }
    CHECK(zeros == alone && alone > 300 && written > 6 * alone && written < 8 * alone);
    q.density = 7;
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_points(builtin, &q, single, 4096, &alone, &cursor, NULL) == KDM_OK && alone == written);
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_classes(builtin, &q, densities, 9, points, classes, 4096, &written, &cursor, &problem) ==
          KDM_INVALID_ARGUMENT);
    CHECK(problem.kind == KDM_PROBLEM_BAD_CLASS_COUNT && problem.value == 9);
    kdm_query_problem_describe(&problem, (char*)single, sizeof single);
    CHECK(strstr((const char*)single, "('class_count' = 9)") != NULL);
    densities[2].density_bounds = ramp_bounds; /* bounds with no callback */
    CHECK(kdm_query_classes(builtin, &q, densities, 3, points, classes, 4096, &written, &cursor, &problem) ==
          KDM_INVALID_ARGUMENT);
    CHECK(problem.kind == KDM_PROBLEM_BAD_DENSITY &&
          strcmp(problem.parameter, "classes[2].density_callback") == 0);
    densities[2].density_bounds = NULL;
    CHECK(kdm_query_classes(builtin, &q, NULL, 3, points, classes, 4096, &written, &cursor, &problem) ==
          KDM_INVALID_ARGUMENT);
    CHECK(problem.kind == KDM_PROBLEM_MISSING_ARGUMENT && strcmp(problem.parameter, "classes") == 0);
    CHECK(kdm_query_classes(builtin, &q, densities, 3, points, NULL, 4096, &written, &cursor, &problem) ==
          KDM_INVALID_ARGUMENT);
    CHECK(problem.kind == KDM_PROBLEM_MISSING_ARGUMENT && strcmp(problem.parameter, "out_classes") == 0);
    /* A class's field is named as kdm_class_density spells it. */
    densities[1].density = -1;
    CHECK(kdm_query_classes(builtin, &q, densities, 3, points, classes, 4096, &written, &cursor, &problem) ==
          KDM_INVALID_ARGUMENT);
    CHECK(problem.kind == KDM_PROBLEM_NEGATIVE && strcmp(problem.parameter, "classes[1].density") == 0);
    densities[1].density = 2;
    densities[2].density_callback = ramp; /* its density_max unset */
    CHECK(kdm_query_classes(builtin, &q, densities, 3, points, classes, 4096, &written, &cursor, &problem) ==
          KDM_INVALID_ARGUMENT);
    CHECK(problem.kind == KDM_PROBLEM_NOT_POSITIVE &&
          strcmp(problem.parameter, "classes[2].density_max") == 0);
    densities[2].density_max = 1, densities[2].density_batch_callback = ramp_batch; /* two callbacks */
    CHECK(kdm_query_classes(builtin, &q, densities, 3, points, classes, 4096, &written, &cursor, &problem) ==
          KDM_INVALID_ARGUMENT);
    CHECK(problem.kind == KDM_PROBLEM_BAD_DENSITY &&
          strcmp(problem.parameter, "classes[2].density_batch_callback") == 0);
    densities[2].density_callback = NULL, densities[2].density_batch_callback = NULL;
    densities[2].density_max = 0;
    /* The compact output: the same classes, keys and rounded positions (the union here is a constant). */
    {
      static float xy[2 * 4096], sum_xy[2 * 4096];
      static uint64_t keys[4096];
      static uint8_t compact_classes[4096];
      size_t compact = 0;
      q.density = 1;
      memset(&cursor, 0, sizeof cursor);
      CHECK(kdm_query_classes(builtin, &q, densities, 3, points, classes, 4096, &written, &cursor, NULL) ==
            KDM_OK);
      memset(&cursor, 0, sizeof cursor);
      CHECK(kdm_query_classes_compact(builtin, &q, densities, 3, xy, keys, compact_classes, 4096, &compact,
                                      &cursor, &problem) == KDM_OK);
      CHECK(compact == written);
      q.density = 7;
      memset(&cursor, 0, sizeof cursor);
      CHECK(kdm_query_compact(builtin, &q, sum_xy, NULL, 4096, &alone, &cursor, NULL) == KDM_OK &&
            alone == written);
      CHECK(memcmp(xy, sum_xy, 2 * written * sizeof(float)) == 0);
      for (i = 0; i < written; ++i) {
        CHECK(compact_classes[i] == classes[i]);
        CHECK((keys[i] >> 42 & 0x7FFFF) == points[i].rank);
        CHECK(fabs(xy[2 * i] - points[i].x) < 1e-5 && fabs(xy[2 * i + 1] - points[i].y) < 1e-5);
      }
      CHECK(kdm_query_classes_compact(builtin, &q, densities, 3, NULL, keys, compact_classes, 4096, &compact,
                                      &cursor, &problem) == KDM_INVALID_ARGUMENT);
      CHECK(problem.kind == KDM_PROBLEM_MISSING_ARGUMENT && strcmp(problem.parameter, "xy") == 0);
      CHECK(kdm_query_classes_compact(builtin, &q, densities, 0, xy, keys, compact_classes, 4096, &compact,
                                      &cursor, &problem) == KDM_INVALID_ARGUMENT);
      CHECK(problem.kind == KDM_PROBLEM_BAD_CLASS_COUNT);
    }
  }
  /* Classes of images by their sums: the union is kdm_query_points at the summed image, class 0 the query
   * at the first image (stable mode); compact output and two workers give the same classes. */
  {
    static kdm_point points[8192], single[8192];
    static uint8_t classes[8192], compact_classes[8192];
    static float xy[2 * 8192], texels[3][16 * 16], sum[16 * 16];
    kdm_density_image *images[3] = {NULL, NULL, NULL}, *summed = NULL, *other = NULL, *kept = NULL;
    kdm_class_images* class_images = NULL;
    kdm_cursor cursor;
    size_t written = 0, alone = 0, compact = 0, zeros = 0, i;
    int k;
    for (i = 0; i < 16 * 16; ++i) {
      texels[0][i] = (float)(0.2 + 0.05 * (double)(i % 16));
      texels[1][i] = (float)(0.3 + 0.04 * (double)(i / 16));
      texels[2][i] = (float)(1.0 + 0.5 * sin((double)i));
      sum[i] = texels[0][i] + texels[1][i] + texels[2][i];
    }
    for (k = 0; k < 3; ++k)
      CHECK(kdm_density_image_create(16, 16, texels[k], 0, 0, 2, 2, &images[k]) == KDM_OK);
    CHECK(kdm_density_image_create(16, 16, sum, 0, 0, 2, 2, &summed) == KDM_OK);
    CHECK(kdm_class_images_create((const kdm_density_image* const*)images, 3, &class_images) == KDM_OK);
    q = uniform_query();
    q.scale = 400;
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_class_images(builtin, &q, class_images, points, classes, 8192, &written, &cursor,
                                 &problem) == KDM_OK);
    q.density_image = summed;
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_points(builtin, &q, single, 8192, &alone, &cursor, NULL) == KDM_OK && alone == written);
    CHECK(memcmp(points, single, written * sizeof(kdm_point)) == 0);
    q.density_image = images[0];
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_points(builtin, &q, single, 8192, &alone, &cursor, NULL) == KDM_OK);
    for (i = 0; i < written; ++i)
      if (classes[i] == 0) CHECK(memcmp(&points[i], &single[zeros++], sizeof(kdm_point)) == 0);
    CHECK(zeros == alone && alone > 500 && written > 2 * alone);
    q.density_image = NULL;
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_class_images_compact(builtin, &q, class_images, xy, NULL, compact_classes, 8192, &compact,
                                         &cursor, NULL) == KDM_OK &&
          compact == written);
    CHECK(memcmp(classes, compact_classes, written) == 0);
    /* Refusals: no images, images on different grids. */
    CHECK(kdm_query_class_images(builtin, &q, NULL, points, classes, 8192, &written, &cursor, &problem) ==
          KDM_INVALID_ARGUMENT);
    CHECK(problem.kind == KDM_PROBLEM_MISSING_ARGUMENT && strcmp(problem.parameter, "images") == 0);
    kdm_class_images_free(class_images);
    class_images = NULL;
    CHECK(kdm_density_image_create(16, 16, sum, 0, 0, 3, 2, &other) == KDM_OK);
    kept = images[1], images[1] = other;
    CHECK(kdm_class_images_create((const kdm_density_image* const*)images, 3, &class_images) ==
              KDM_INVALID_ARGUMENT &&
          class_images == NULL);
    CHECK(kdm_class_images_create((const kdm_density_image* const*)images, 0, &class_images) ==
          KDM_INVALID_ARGUMENT);
    CHECK(kdm_class_images_create(NULL, 3, &class_images) == KDM_INVALID_ARGUMENT);
    { /* _detail names the image and its grid against images[0]'s, cut to the buffer */
      char why[200], short_why[12];
      CHECK(kdm_class_images_create_detail((const kdm_density_image* const*)images, 3, &class_images, why,
                                           sizeof why) == KDM_INVALID_ARGUMENT);
      CHECK(strstr(why, "images[1] is 16 x 16 texels over (0, 0)-(3, 2)") != NULL);
      CHECK(kdm_class_images_create_detail((const kdm_density_image* const*)images, 9, &class_images, why,
                                           sizeof why) == KDM_INVALID_ARGUMENT);
      CHECK(strcmp(why, "count is 9, not 1 to 8") == 0);
      CHECK(kdm_class_images_create_detail((const kdm_density_image* const*)images, 3, &class_images,
                                           short_why, sizeof short_why) == KDM_INVALID_ARGUMENT);
      CHECK(strlen(short_why) == sizeof short_why - 1);
    }
    images[1] = NULL;
    CHECK(kdm_class_images_create((const kdm_density_image* const*)images, 3, &class_images) ==
          KDM_INVALID_ARGUMENT);
    kdm_class_images_free(NULL);
    images[1] = kept;
    for (k = 0; k < 3; ++k) kdm_density_image_free(images[k]);
    kdm_density_image_free(other);
    kdm_density_image_free(summed);
  }
  /* A callback's bounds: the same points, far fewer calls. */
  {
    static kdm_point with[8192], without[8192];
    kdm_cursor cursor;
    size_t a = 0, b = 0;
    long calls_without;
    q = uniform_query();
    q.x1 = 8, q.y1 = 1, q.scale = 800, q.density_callback = ramp, q.density_max = 1;
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_points(builtin, &q, without, 8192, &a, &cursor, NULL) == KDM_OK && a > 2000);
    calls_without = g_ramp_calls, g_ramp_calls = 0;
    q.density_bounds = ramp_bounds;
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_points(builtin, &q, with, 8192, &b, &cursor, NULL) == KDM_OK);
    CHECK(a == b && memcmp(with, without, a * sizeof(kdm_point)) == 0);
    CHECK(g_ramp_calls < calls_without / 10); /* measured: a fortieth (tile and cell bounds) */
    /* Bounds that write nothing are no bounds: the points and calls of none. */
    q.density_bounds = silent_bounds, g_ramp_calls = 0;
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_points(builtin, &q, with, 8192, &b, &cursor, NULL) == KDM_OK);
    CHECK(a == b && memcmp(with, without, a * sizeof(kdm_point)) == 0);
    CHECK(g_bounds_preset_nan && g_ramp_calls == calls_without);
    /* A binding whose callback failed gives bounds of 0: the query ends without calling it again. */
    q.density_bounds = given_up_bounds, g_ramp_calls = 0;
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_points(builtin, &q, with, 8192, &b, &cursor, NULL) == KDM_OK);
    CHECK(b == 0 && g_ramp_calls == 0);
    q.density_bounds = ramp_bounds;
    /* The ramp as a batch callback: the same points, the same values read, many a call. */
    {
      kdm_query_problem problem;
      memset(&problem, 0, sizeof problem);
      problem.struct_size = sizeof problem;
      q.density_bounds = NULL, q.density_batch_callback = ramp_batch;
      memset(&cursor, 0, sizeof cursor);
      CHECK(kdm_query_points(builtin, &q, with, 8192, &b, &cursor, &problem) == KDM_INVALID_ARGUMENT);
      CHECK(problem.kind == KDM_PROBLEM_BAD_DENSITY &&
            strcmp(problem.parameter, "density_batch_callback") == 0);
      q.density_callback = NULL;
      memset(&cursor, 0, sizeof cursor);
      CHECK(kdm_query_points(builtin, &q, with, 8192, &b, &cursor, NULL) == KDM_OK);
      CHECK(a == b && memcmp(with, without, a * sizeof(kdm_point)) == 0);
      CHECK(g_batch_values == calls_without && g_batch_calls * 20 < g_batch_values);
      q.density_callback = ramp, q.density_batch_callback = NULL;
    }
    /* Smooth mode, glide_together: the same points glide elsewhere (about as many are emitted: the region
     * keeps those that glide into it); a batch callback gives the scalar one's positions; a cursor started
     * without it does not continue with it. */
    {
      static kdm_point together[8192];
      size_t c = 0, d = 0, moved = 0, i;
      q.mode = KDM_MODE_SMOOTH;
      memset(&cursor, 0, sizeof cursor);
      CHECK(kdm_query_points(builtin, &q, without, 8192, &a, &cursor, NULL) == KDM_OK && a > 2000);
      q.glide_together = 1;
      memset(&cursor, 0, sizeof cursor);
      CHECK(kdm_query_points(builtin, &q, together, 8192, &c, &cursor, NULL) == KDM_OK);
      CHECK(c > a - a / 50 && c < a + a / 50);
      for (i = 0; i < a && i < c; ++i) moved += together[i].x != without[i].x;
      CHECK(moved > a / 10);
      q.density_callback = NULL, q.density_batch_callback = ramp_batch;
      memset(&cursor, 0, sizeof cursor);
      CHECK(kdm_query_points(builtin, &q, with, 8192, &d, &cursor, NULL) == KDM_OK);
      CHECK(c == d && memcmp(with, together, c * sizeof(kdm_point)) == 0);
      q.density_callback = ramp, q.density_batch_callback = NULL, q.glide_together = 0;
      memset(&cursor, 0, sizeof cursor);
      CHECK(kdm_query_points(builtin, &q, with, 256, &d, &cursor, NULL) == KDM_BUFFER_FULL);
      q.glide_together = 1;
      CHECK(kdm_query_points(builtin, &q, with, 256, &d, &cursor, NULL) == KDM_INVALID_ARGUMENT);
      q.glide_together = 0, q.mode = KDM_MODE_STABLE;
    }
    /* Classes of callback densities: their bounds keep the points and classes and save calls. */
    {
      static uint8_t with_classes[8192], without_classes[8192];
      kdm_class_density ramps[2];
      memset(ramps, 0, sizeof ramps);
      ramps[0].density_callback = ramps[1].density_callback = ramp;
      ramps[0].density_max = ramps[1].density_max = 1;
      q.scale = 400, q.density_bounds = NULL;
      g_ramp_calls = 0;
      memset(&cursor, 0, sizeof cursor);
      CHECK(kdm_query_classes(builtin, &q, ramps, 2, without, without_classes, 8192, &a, &cursor, NULL) ==
            KDM_OK);
      calls_without = g_ramp_calls, g_ramp_calls = 0;
      ramps[0].density_bounds = ramps[1].density_bounds = ramp_bounds;
      memset(&cursor, 0, sizeof cursor);
      CHECK(kdm_query_classes(builtin, &q, ramps, 2, with, with_classes, 8192, &b, &cursor, NULL) == KDM_OK);
      CHECK(a == b && a > 2000 && memcmp(with, without, a * sizeof(kdm_point)) == 0);
      CHECK(memcmp(with_classes, without_classes, a) == 0);
      CHECK(g_ramp_calls < calls_without / 10); /* measured: a thirtieth */
      /* The classes as batch callbacks: the same points and classes, many positions a call. */
      ramps[0].density_callback = ramps[1].density_callback = NULL;
      ramps[0].density_batch_callback = ramps[1].density_batch_callback = ramp_batch;
      g_batch_values = 0, g_batch_calls = 0;
      memset(&cursor, 0, sizeof cursor);
      CHECK(kdm_query_classes(builtin, &q, ramps, 2, with, with_classes, 8192, &b, &cursor, NULL) == KDM_OK);
      CHECK(a == b && memcmp(with, without, a * sizeof(kdm_point)) == 0);
      /* With bounds few candidates of a block are read: measured 16 values a call. */
      CHECK(memcmp(with_classes, without_classes, a) == 0 && g_batch_calls * 8 < g_batch_values);
      ramps[0].density_callback = ramps[1].density_callback = ramp;
      ramps[0].density_batch_callback = ramps[1].density_batch_callback = NULL;
      /* The same two classes from one joint call: the same points and classes, a call per candidate. */
      {
        static float xy[2 * 8192];
        static uint8_t compact_classes[8192];
        kdm_joint_class_density joint;
        size_t c = 0;
        memset(&joint, 0, sizeof joint);
        joint.densities = two_ramps;
        joint.density_max[0] = joint.density_max[1] = 1;
        g_ramp_calls = 0;
        memset(&cursor, 0, sizeof cursor);
        CHECK(kdm_query_classes_joint(builtin, &q, &joint, 2, with, with_classes, 8192, &b, &cursor, NULL) ==
              KDM_OK);
        CHECK(a == b && memcmp(with, without, a * sizeof(kdm_point)) == 0);
        CHECK(memcmp(with_classes, without_classes, a) == 0);
        CHECK(g_ramp_calls <
              calls_without * 2 / 3); /* two ramps a call; separately, two a candidate and more */
        joint.density_bounds = two_ramp_bounds;
        memset(&cursor, 0, sizeof cursor);
        CHECK(kdm_query_classes_joint_compact(builtin, &q, &joint, 2, xy, NULL, compact_classes, 8192, &c,
                                              &cursor, NULL) == KDM_OK);
        CHECK(c == a && memcmp(compact_classes, without_classes, a) == 0);
        for (c = 0; c < a; ++c) /* floats within 2^-21 of the tile-relative double (region 8 wide) */
          CHECK(fabs(xy[2 * c] - without[c].x) < 1e-5 && fabs(xy[2 * c + 1] - without[c].y) < 1e-5);
        /* The joint densities at many positions a call: the same points and classes. */
        joint.densities = NULL, joint.batch_densities = two_ramps_batch;
        g_batch_calls = g_batch_values = 0;
        memset(&cursor, 0, sizeof cursor);
        CHECK(kdm_query_classes_joint(builtin, &q, &joint, 2, with, with_classes, 8192, &b, &cursor, NULL) ==
              KDM_OK);
        CHECK(a == b && memcmp(with, without, a * sizeof(kdm_point)) == 0);
        CHECK(memcmp(with_classes, without_classes, a) == 0 && g_batch_calls * 8 < g_batch_values);
        /* Both functions: which one is meant is unclear. */
        joint.densities = two_ramps;
        memset(&cursor, 0, sizeof cursor);
        CHECK(kdm_query_classes_joint(builtin, &q, &joint, 2, with, with_classes, 8192, &b, &cursor,
                                      &problem) == KDM_INVALID_ARGUMENT &&
              strcmp(problem.parameter, "joint.batch_densities") == 0);
        {
          char line[512];
          kdm_query_problem_describe(&problem, line, sizeof line);
          CHECK(strstr(line, "('joint.batch_densities')") != NULL && strstr(line, "= ") == NULL);
        }
        joint.batch_densities = NULL;
        /* Neither function: the density is missing, not the argument. */
        joint.densities = NULL;
        CHECK(kdm_query_classes_joint(builtin, &q, &joint, 2, with, with_classes, 8192, &b, &cursor,
                                      &problem) == KDM_INVALID_ARGUMENT &&
              problem.kind == KDM_PROBLEM_BAD_DENSITY && strcmp(problem.parameter, "joint.densities") == 0);
        joint.densities = two_ramps;
        /* Refused by name: no joint density, a bad maximum. */
        memset(&cursor, 0, sizeof cursor);
        CHECK(kdm_query_classes_joint(builtin, &q, NULL, 2, with, with_classes, 8192, &b, &cursor,
                                      &problem) == KDM_INVALID_ARGUMENT &&
              strcmp(problem.parameter, "joint") == 0);
        joint.density_max[1] = -1;
        CHECK(kdm_query_classes_joint(builtin, &q, &joint, 2, with, with_classes, 8192, &b, &cursor,
                                      &problem) == KDM_INVALID_ARGUMENT &&
              strcmp(problem.parameter, "joint.density_max[1]") == 0);
        joint.density_max[1] = 0; /* a zeroed struct's, left unset: not a class left out in silence */
        CHECK(kdm_query_classes_joint(builtin, &q, &joint, 2, with, with_classes, 8192, &b, &cursor,
                                      &problem) == KDM_INVALID_ARGUMENT &&
              problem.kind == KDM_PROBLEM_NOT_POSITIVE &&
              strcmp(problem.parameter, "joint.density_max[1]") == 0);
        joint.density_max[0] = NAN; /* the first bad maximum is named, whatever is wrong with it */
        CHECK(kdm_query_classes_joint(builtin, &q, &joint, 2, with, with_classes, 8192, &b, &cursor,
                                      &problem) == KDM_INVALID_ARGUMENT &&
              problem.kind == KDM_PROBLEM_NOT_FINITE &&
              strcmp(problem.parameter, "joint.density_max[0]") == 0);
      }
    }
  }
  /* The compact output: the same points as floats and keys, through a small buffer with resumes. */
  {
    static kdm_point points[4096];
    static float xy[2 * 100];
    static uint64_t keys[100];
    kdm_cursor cursor;
    size_t written = 0, all = 0, total = 0, i;
    kdm_status s;
    q = uniform_query();
    q.origin_x = 0.5, q.mode = KDM_MODE_SMOOTH;
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_points(builtin, &q, points, 4096, &all, &cursor, NULL) == KDM_OK && all > 1000);
    memset(&cursor, 0, sizeof cursor);
    do {
      s = kdm_query_compact(builtin, &q, xy, keys, 100, &written, &cursor, &problem);
      CHECK(total + written <= all);
      for (i = 0; i < written; ++i) {
        const kdm_point* p = &points[total + i];
        CHECK(fabs(xy[2 * i] - p->x) <= ldexp(fabs(p->x) + 1, -21) &&
              fabs(xy[2 * i + 1] - p->y) <= ldexp(fabs(p->y) + 1, -21));
        CHECK((keys[i] & 0x1FFFFF) == ((uint64_t)p->tile_x & 0x1FFFFF) &&
              (keys[i] >> 42 & 0x7FFFF) == p->rank);
      }
      total += written;
    } while (s == KDM_BUFFER_FULL);
    CHECK(s == KDM_OK && total == all);
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_compact(builtin, &q, NULL, keys, 100, &written, &cursor, &problem) ==
          KDM_INVALID_ARGUMENT);
    CHECK(problem.kind == KDM_PROBLEM_MISSING_ARGUMENT && strcmp(problem.parameter, "xy") == 0);
    CHECK(kdm_query_compact(builtin, &q, xy, NULL, 100, &written, &cursor, NULL) == KDM_BUFFER_FULL);
    CHECK(written == 100);
  }
  {
    kdm_tileset* bad = NULL;
    CHECK(kdm_tileset_load_memory("not a tile set", 14, &bad) == KDM_BAD_MAGIC && bad == NULL);
    CHECK(kdm_tileset_load_file("/nonexistent.kdmt", &bad) == KDM_IO_ERROR && bad == NULL);
    CHECK(kdm_tileset_load_file(".", &bad) == KDM_IO_ERROR && bad == NULL); /* a directory */
    bad = (kdm_tileset*)&q; /* set to NULL on every failure, a missing path too */
    CHECK(kdm_tileset_load_file(NULL, &bad) == KDM_INVALID_ARGUMENT && bad == NULL);
  }
  {
    /* Why a load failed, for a log: the C++ loader's line, cut to the caller's buffer. */
    kdm_tileset* bad = NULL;
    char detail[64], tiny[8];
    CHECK(kdm_tileset_load_file_detail("/nonexistent.kdmt", &bad, detail, sizeof detail) == KDM_IO_ERROR);
    CHECK(bad == NULL && strstr(detail, "No such file") != NULL);
    CHECK(kdm_tileset_load_file_detail(".", &bad, detail, sizeof detail) == KDM_IO_ERROR);
    CHECK(strstr(detail, "directory") != NULL);
    CHECK(kdm_tileset_load_file_detail("/nonexistent.kdmt", &bad, tiny, sizeof tiny) == KDM_IO_ERROR);
    CHECK(strlen(tiny) == sizeof tiny - 1);
    CHECK(kdm_tileset_load_file_detail("/nonexistent.kdmt", &bad, NULL, 0) == KDM_IO_ERROR);
    CHECK(kdm_tileset_load_file_detail(NULL, &bad, detail, sizeof detail) == KDM_INVALID_ARGUMENT);
    CHECK(strstr(detail, "path") != NULL);
    CHECK(kdm_tileset_load_file_detail(argv[1], &bad, detail, sizeof detail) == KDM_OK && bad != NULL);
    CHECK(detail[0] == '\0');
    kdm_tileset_free(bad);
    CHECK(kdm_tileset_load_file_detail(argv[1], NULL, detail, sizeof detail) == KDM_INVALID_ARGUMENT);
    CHECK(strstr(detail, "out is NULL") != NULL);
  }
  {
    /* The same from memory, for sets an engine reads itself: the bytes whole, cut, and none. */
    FILE* f = fopen(argv[1], "rb");
    long size = 0;
    unsigned char* bytes = NULL;
    kdm_tileset* set = NULL;
    char detail[128];
    CHECK(f != NULL && fseek(f, 0, SEEK_END) == 0 && (size = ftell(f)) > 0 && fseek(f, 0, SEEK_SET) == 0);
    bytes = (unsigned char*)malloc((size_t)size);
    CHECK(bytes != NULL && fread(bytes, 1, (size_t)size, f) == (size_t)size);
    fclose(f);
    CHECK(kdm_tileset_load_memory_detail(bytes, (size_t)size, &set, detail, sizeof detail) == KDM_OK);
    CHECK(set != NULL && detail[0] == '\0');
    {
      /* The set keeps nothing of the bytes: overwritten after the load, they change no point. */
      static kdm_point before[4096], after[4096];
      const kdm_query one = uniform_query();
      kdm_cursor cursor;
      size_t a = 0, b = 0;
      memset(&cursor, 0, sizeof cursor);
      CHECK(kdm_query_points(set, &one, before, 4096, &a, &cursor, NULL) == KDM_OK && a > 1000);
      memset(bytes, 0, (size_t)size);
      memset(&cursor, 0, sizeof cursor);
      CHECK(kdm_query_points(set, &one, after, 4096, &b, &cursor, NULL) == KDM_OK);
      CHECK(a == b && memcmp(before, after, a * sizeof(kdm_point)) == 0);
      f = fopen(argv[1], "rb");
      CHECK(f != NULL && fread(bytes, 1, (size_t)size, f) == (size_t)size);
      fclose(f);
    }
    kdm_tileset_free(set);
    CHECK(kdm_tileset_load_memory_detail(bytes, (size_t)size / 2, &set, detail, sizeof detail) != KDM_OK);
    CHECK(set == NULL && strlen(detail) > 0); /* the decoder's line: what is cut */
    CHECK(kdm_tileset_load_memory_detail(bytes, 0, &set, detail, sizeof detail) == KDM_TRUNCATED);
    CHECK(kdm_tileset_load_memory_detail(NULL, 5, &set, detail, sizeof detail) == KDM_INVALID_ARGUMENT);
    CHECK(strstr(detail, "data is NULL") != NULL);
    CHECK(kdm_tileset_load_memory_detail(bytes, (size_t)size, NULL, detail, sizeof detail) ==
          KDM_INVALID_ARGUMENT);
    CHECK(strstr(detail, "out is NULL") != NULL);
    free(bytes);
  }
  CHECK(strlen(kdm_status_message(KDM_TRUNCATED)) > 0);
  kdm_tileset_free(loaded);
  kdm_tileset_free((kdm_tileset*)builtin); /* ignored for the built-in set */

  /* An engine's allocator holds a loaded set's arrays and gets them all back. */
  kdm_set_tileset_allocator(hooked_allocate, hooked_deallocate, &g_hooked_bytes);
  CHECK(kdm_tileset_load_file(argv[1], &loaded) == KDM_OK);
  kdm_set_tileset_allocator(NULL, NULL, NULL);
  CHECK(g_hooked_bytes > 4000000 && g_hooked_bytes <= kdm_tileset_resident_bytes(loaded));
  kdm_tileset_free(loaded);
  CHECK(g_hooked_bytes == 0);
  /* An allocator that runs out is said as such, not as a damaged file. */
  kdm_set_tileset_allocator(failing_allocate, hooked_deallocate, &g_hooked_bytes);
  CHECK(kdm_tileset_load_file(argv[1], &loaded) == KDM_OUT_OF_MEMORY && loaded == NULL);
  kdm_set_tileset_allocator(NULL, NULL, NULL);
  /* So does one that runs out at any later allocation, the query tables built last included, and what
   * the load had taken goes back. (A table trimmed to size keeps its spare room when the trimmed copy is
   * refused: that load succeeds.) Every allocation near the end, a sample of the rest, since each load
   * decodes the whole set. */
  {
    long count, k, refused = 0;
    kdm_set_tileset_allocator(refusing_allocate, hooked_deallocate, &g_hooked_bytes);
    g_allocations = 0, g_refuse_at = -1;
    CHECK(kdm_tileset_load_file(argv[1], &loaded) == KDM_OK);
    count = g_allocations;
    kdm_tileset_free(loaded);
    CHECK(count > 16 && g_hooked_bytes == 0);
    for (k = 0; k < count; k += (k < 4 || k + 40 >= count) ? 1 : count / 16) {
      kdm_status s;
      g_allocations = 0, g_refuse_at = k;
      s = kdm_tileset_load_file(argv[1], &loaded);
      CHECK((s == KDM_OUT_OF_MEMORY && loaded == NULL) || (s == KDM_OK && loaded != NULL));
      refused += s == KDM_OUT_OF_MEMORY;
      kdm_tileset_free(loaded);
      CHECK(g_hooked_bytes == 0);
    }
    CHECK(refused > 20);
    kdm_set_tileset_allocator(NULL, NULL, NULL);
  }
  printf("c api ok\n");
  return 0;
}
