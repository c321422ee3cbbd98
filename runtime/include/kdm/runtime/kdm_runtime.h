/* kdm runtime, C interface: load a baked tile set and query blue-noise points, for engines and FFI
 * (C#, Rust, Godot). Same library and semantics as kdm/runtime/query.h.
 *
 * Growing structs: kdm_query, kdm_query_problem and kdm_tileset_info begin with `struct_size`, which the
 * caller sets to sizeof(the struct) as its header declares it. A newer library reads only that many bytes
 * (later fields keep their defaults) and writes only that many, so programs built against an older header
 * keep working. An older library given a larger struct_size reads the fields it knows and ignores the rest
 * (any larger size is taken: only one below the struct's first version is refused; the first versions end
 * just before kdm_query's `mode`, at offsetof(kdm_query, mode), just before kdm_tileset_info's `keyframes`,
 * and at the end of kdm_query_problem, whose fields have not grown): a program that sets a
 * field newer than the library it runs with should check kdm_version_number(). The other structs (kdm_cursor,
 * kdm_class_density, kdm_joint_class_density, kdm_task_runner, kdm_point) carry no size: where one grows,
 * as kdm_class_density did in 0.4, callers are rebuilt with the new header (0.x minor versions may change
 * the ABI; the shared library's soname carries MAJOR.MINOR).
 *
 * Thread safety: a loaded kdm_tileset and a kdm_density_image are immutable; queries on them may run
 * concurrently. No function here throws; every failure is a status code. Queries allocate nothing.
 *
 * For bindings (Rust, C#, ctypes): kdm_status and kdm_problem_kind are C enums, int-sized on x86-64 (the
 * platform kdm is tested on), and their lists grow from version to version: read them as int and take a
 * value you do not know as a failure. Fields typed int (mode, flags, sizes)
 * are C ints; there are no bitfields. Every struct has the C compiler's natural layout; on x86-64 (and any
 * LP64 platform) sizeof is 40 for kdm_point, 144 for kdm_query (its first version 112), 56 for kdm_cursor
 * (4 bytes of padding after `finished` and after `depth`), 56 for kdm_query_problem, 144 for
 * kdm_tileset_info (its first version 120), 56 for kdm_class_density and 96 for kdm_joint_class_density
 * (c_api_test checks these). Pointers a binding hands to the library must stay valid as long as each
 * function's comment says it keeps them: the allocator hooks while any set loaded under them lives (the
 * built-in set's: until the process ends), the callbacks and `user` for the call they are passed to.
 * A callback cannot fail or stop a query: one that hits an error should record it, return 0 from then on
 * (and lo = hi = 0 from density_bounds, which skips whole tiles), and the caller discards the result. */
#ifndef KDM_RUNTIME_H
#define KDM_RUNTIME_H

#include <stddef.h>
#include <stdint.h>

#include "kdm/runtime/export.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What every call returns (kdm::Status, value for value). */
typedef enum kdm_status {
  KDM_OK = 0,
  KDM_IO_ERROR = 1,                  /* a file could not be opened or read */
  KDM_BAD_MAGIC = 2,                 /* not a kdm tile set */
  KDM_UNSUPPORTED_VERSION = 3,       /* written in a format version this library does not read */
  KDM_TRUNCATED = 4,                 /* shorter than its header says */
  KDM_TRAILING_BYTES = 5,            /* longer than its header says */
  KDM_HEADER_CHECKSUM_MISMATCH = 6,  /* header bytes damaged */
  KDM_PAYLOAD_CHECKSUM_MISMATCH = 7, /* payload bytes damaged */
  KDM_TOO_LARGE = 8,                 /* a size past the reader's caps */
  KDM_DECOMPRESSION_FAILED = 9,      /* the payload is not one zstd frame of its stated size */
  KDM_INVALID_CONTENT = 10,          /* checksums match but the content is inconsistent */
  KDM_INVALID_ARGUMENT = 11, /* a caller's error; queries say which argument and limit in kdm_query_problem */
  KDM_BUFFER_FULL = 12,      /* a query filled the buffer, or examined its most candidates and tiles
                                (2^24) in one call: call again with the same cursor; a parallel query's
                                output was too small: call again with room for the count it gave */
  KDM_OUT_OF_MEMORY = 13     /* an allocation was refused (by the tile-set allocator's hooks too) */
} kdm_status;

typedef struct kdm_tileset kdm_tileset;             /* a loaded tile set */
typedef struct kdm_density_image kdm_density_image; /* a density image with its max-mip, ready to query */

typedef struct kdm_point {
  double x, y;            /* world position minus the query origin */
  int64_t tile_x, tile_y; /* stable id: tile coordinates ... */
  uint32_t rank;          /* ... and rank within the tile (emitted in rank order: a tile's first points
                             are its coarsest level's) */
  uint32_t depth;         /* past the top level (smooth mode): tiles m^depth times smaller (kdm::PointId) */
} kdm_point;

typedef struct kdm_query {
  size_t struct_size;        /* sizeof(kdm_query) */
  double x0, y0, x1, y1;     /* half-open world region [x0, x1) x [y0, y1): no points if x1 <= x0 */
  double origin_x, origin_y; /* subtracted from every output position */
  double tile_size;          /* world units per tile side (> 0) */
  double scale;              /* points per unit area at density 1 (>= 0) */
  double density;            /* constant density (finite, >= 0), used without an image or a callback */
  /* Optional: density at world (x, y); NaN, negative and infinite values count as 0. */
  double (*density_callback)(void* user, double x, double y);
  void* user;                             /* passed to the density and bounds callbacks */
  double density_max;                     /* upper bound of the callback's values: > 0 with a callback
                                             (0, a zeroed struct's, is refused: it would call nothing).
                                             Values above it break that promise: stable mode emits as if
                                             they were density_max, smooth mode glides by them, and a
                                             class query gives such a class more than its share, at the
                                             later classes' expense (kdm::QueryDensity::callback_max) */
  const kdm_density_image* density_image; /* optional; takes precedence over the callback */
  /* Added in 0.2 (callers built before it have a smaller struct_size and get KDM_MODE_STABLE): */
  int mode; /* KDM_MODE_STABLE: points never move once they appear; KDM_MODE_SMOOTH: they glide with the
               density, so every density is good blue noise (tile sets with a glide track) */
  /* Added in 0.4: optional bounds of the callback's density over a world rectangle (*lo <= density <= *hi
   * there), asked once per tile (and, in stable mode, per sixteenth of a tile) so that the callback is
   * called only where emission is in doubt (kdm::QueryDensity::bounds). NaN bounds, and *lo > *hi, are
   * ignored; bounds that do not hold make points appear or vanish as if the density were *lo or *hi.
   * Bounds with neither a callback nor an image are refused (KDM_PROBLEM_BAD_DENSITY, "density_callback"). */
  /* *lo and *hi hold NaN when it is called: a callback that writes neither gives no bounds there. */
  void (*density_bounds)(void* user, double x0, double y0, double x1, double y1, double* lo, double* hi);
  /* Added in 0.4: instead of density_callback (set one of the two), the density at n positions at once,
   * out[i] at (x[i], y[i]), 1 <= n <= KDM_DENSITY_BATCH, for vectorised functions: a query gathers each
   * tile's reads into such calls (kdm::QueryDensity::batch_callback). The same points as density_callback
   * giving the same values. */
  void (*density_batch_callback)(void* user, size_t n, const double* x, const double* y, double* out);
  /* Added in 0.5 (callers built before it get 0): nonzero, in smooth mode with a varying density, makes
   * each point glide by the most density around it, so that neighbours do not close up where the density
   * changes from one dot to the next; about 8 density reads more per emitted point
   * (kdm::QueryParams::glide_together). */
  int glide_together;
} kdm_query;

#define KDM_DENSITY_BATCH 128 /* kdm::kDensityBatch */

enum { KDM_MODE_STABLE = 0, KDM_MODE_SMOOTH = 1 };

typedef struct kdm_cursor {
  int64_t tile_x, tile_y; /* the tile the query stopped in */
  uint32_t rank;          /* the next rank to examine there */
  int started, finished;  /* set by the first call, and once the region is complete */
  uint64_t fingerprint;   /* of the query and tile set that started it: refused with others */
  uint32_t depth;         /* where in the tile's subtiles it stopped (past the top level) */
  uint64_t path;          /* the subtiles it went through; at depth 0, the tile's cell it stopped in + 1 */
} kdm_cursor;             /* zero-initialise before the first call */

/* Why kdm_query_points returned KDM_INVALID_ARGUMENT (mirrors kdm::QueryProblem). */
typedef enum kdm_problem_kind {
  KDM_PROBLEM_NONE = 0,
  KDM_PROBLEM_MISSING_ARGUMENT = 1,  /* `parameter` is NULL (or the tile set is empty) */
  KDM_PROBLEM_NOT_FINITE = 2,        /* `parameter` is NaN or infinite; `value` holds it */
  KDM_PROBLEM_NOT_POSITIVE = 3,      /* `parameter` must be > 0 ("query.struct_size": at least `limit`) */
  KDM_PROBLEM_NEGATIVE = 4,          /* `parameter` must be >= 0 */
  KDM_PROBLEM_BAD_DENSITY = 5,       /* the density image or callback is missing, or both callbacks are set */
  KDM_PROBLEM_TOO_MANY_TILES = 6,    /* `value` tiles, more than `limit`: split the region */
  KDM_PROBLEM_DENSITY_TOO_HIGH = 7,  /* `value` points per tile > `limit`; see largest_valid (scale) and
                                        largest_tile_size */
  KDM_PROBLEM_CURSOR_MISMATCH = 8,   /* the cursor was started by another query or on another tile set */
  KDM_PROBLEM_BAD_MODE = 9,          /* `mode` is neither KDM_MODE_STABLE nor KDM_MODE_SMOOTH */
  KDM_PROBLEM_BAD_CLASS_COUNT = 10,  /* kdm_query_classes: `value` classes, not 1 ... KDM_MAX_CLASSES */
  KDM_PROBLEM_KEYS_UNSUPPORTED = 11, /* kdm_query_compact: keys asked of a set whose tiles hold `value`
                                        points, more than a key's ranks (`limit`) */
  KDM_PROBLEM_TOO_FAR_FROM_ORIGIN = 12, /* the region lies `value` from the world origin ("x0", "y0"),
                                           farther than `limit`, where doubles cannot place its points; or
                                           from the query's origin ("origin_x", "origin_y"), where the
                                           output's doubles or floats cannot keep its densest points apart */
  KDM_PROBLEM_RUNNER_INCOMPLETE = 13    /* a parallel query's runner ("runner.run") returned before its tasks
                                           had done the query: `value` of its `limit` units were taken (0: it
                                           ran no task). Added in 0.5 */
} kdm_problem_kind;

typedef struct kdm_query_problem {
  size_t struct_size; /* sizeof(kdm_query_problem); a problem whose struct_size is below its first version
                         (left 0, say) is not written at all: kind stays what the caller put there */
  kdm_problem_kind kind;
  const char* parameter;    /* the kdm_query field ("x0", "density_max", "mode", ...), the function's argument
                               ("xy", "out_classes", "cursor", ...) or its field ("classes[2].density",
                               "joint.density_max[1]", "query.struct_size") at fault; a static string */
  double value;             /* the value refused, where it is a number */
  double limit;             /* the limit it broke, where there is one (see each kind) */
  double largest_valid;     /* KDM_PROBLEM_DENSITY_TOO_HIGH: the largest scale that fits */
  double largest_tile_size; /* KDM_PROBLEM_DENSITY_TOO_HIGH: the largest tile size that fits this scale */
} kdm_query_problem;

typedef struct kdm_tileset_info {
  size_t struct_size;              /* sizeof(kdm_tileset_info) */
  uint32_t format_version;         /* the format version the set is written in (4 without a hand-over) */
  uint32_t colours, tiles, levels; /* corner colours C, tiles (C^4) and density levels */
  uint32_t max_points_per_tile;    /* the densest query: scale * density * tile_size^2 up to this */
  uint32_t level_points[16];       /* nominal points per tile of levels 0 .. levels - 1 */
  size_t resident_bytes;           /* heap bytes the loaded set occupies */
  const char* generator_version;   /* the kdm version that baked it; valid while the tile set lives */
  const char* recipe;              /* the recipe text that rebakes it; valid while the tile set lives */
  /* Added in 0.2: */
  uint32_t keyframes; /* keyframes of its glide track (0: none; smooth queries emit stable positions) */
  /* Added in 0.3: */
  uint32_t subtiles_per_side;   /* m of its hand-over to subtiles past the top level (0: none) */
  double smooth_limit_per_tile; /* the densest smooth query (max_points_per_tile * m^8 with a hand-over) */
  /* Added in 0.4: */
  uint32_t handover_level; /* the subtiles' level its hand-over glides onto (m^2 * its count = the top's) */
  uint32_t handover_slack; /* keyframes past their first above that level at which they are handed over */
} kdm_tileset_info;

/* Where tile sets loaded from now on keep their arrays (positions, keys, tables, thresholds), the built-in
 * set too if its first kdm_tileset_builtin() call comes after (it is kept until the process ends: call that
 * first where hooks are torn down before then), and parallel queries their scratch. Not through them: a
 * tile set's handle (a few hundred bytes), density images (kdm_density_image_create: their mips, a
 * quarter of the texels' bytes) and class images (kdm_class_images_create: the texels of their running
 * sums), which use malloc. `allocate`
 * returns `bytes` bytes aligned to `alignment` (a power of two, at most alignof(max_align_t)) or NULL,
 * which the load returns as KDM_OUT_OF_MEMORY; `deallocate` frees them. Either NULL: operator new and
 * delete again. Memory always returns to the functions it came from. Call it while no other thread is
 * loading a tile set. A load asks them for everything sizeable it takes: besides the set's arrays, the
 * file's bytes (kdm_tileset_load_file), zstd's window (the frame's, at most the body's size; the body is
 * parsed as it is decompressed, never held whole) and the checks' scratch, so a hook with a budget bounds
 * what a set from elsewhere costs, a decompression bomb's window included: it is refused with
 * KDM_OUT_OF_MEMORY before the memory is touched, and nothing stays allocated. At its peak a load of the
 * built-in set takes 33.0 MB through them from memory and 47.3 MB from its file (the file's 14.3 MB and
 * zstd's 8.8 MB beside the arrays as they fill; loaded, the set holds 31.9 MB). */
KDM_RUNTIME_API void kdm_set_tileset_allocator(void* (*allocate)(size_t bytes, size_t alignment, void* user),
                                               void (*deallocate)(void* p, size_t bytes, size_t alignment,
                                                                  void* user),
                                               void* user);

/* The library version, "MAJOR.MINOR.PATCH" (static string). */
KDM_RUNTIME_API const char* kdm_version(void);
/* The same as a number to compare, MAJOR * 10000 + MINOR * 100 + PATCH (0.5.0: 500): what a program that
 * sets a struct's newer fields checks, as `if (kdm_version_number() >= 500)`. Added in 0.5. */
KDM_RUNTIME_API uint32_t kdm_version_number(void);
/* The newest tile-set format version this library reads and writes (it reads 2 and up). */
KDM_RUNTIME_API uint32_t kdm_tileset_format_version(void);

/* Loads a tile-set file / memory buffer (untrusted input is validated). *out receives a new handle to
 * free with kdm_tileset_free, or NULL on failure: KDM_INVALID_ARGUMENT for a NULL `path` or `out` (or NULL
 * `data` with `size` > 0), KDM_IO_ERROR for a file that cannot be read, the format's statuses
 * (KDM_BAD_MAGIC ... KDM_INVALID_CONTENT) for a damaged or foreign one (KDM_TRUNCATED for one shorter than
 * its header, an empty buffer too), KDM_OUT_OF_MEMORY. The set keeps nothing of `data`: it may be freed
 * (or a managed buffer unpinned) once the call returns. */
KDM_RUNTIME_API kdm_status kdm_tileset_load_file(const char* path, kdm_tileset** out);
KDM_RUNTIME_API kdm_status kdm_tileset_load_memory(const void* data, size_t size, kdm_tileset** out);
/* kdm_tileset_load_file, and on failure why in `detail` (if not NULL): one line ("No such file or
 * directory", "payload CRC-32 mismatch", ...), cut to `detail_size` bytes with its terminating NUL; "" on
 * success. The status says what kind of failure; this, what a person reading a log needs. Added in 0.5. */
KDM_RUNTIME_API kdm_status kdm_tileset_load_file_detail(const char* path, kdm_tileset** out, char* detail,
                                                        size_t detail_size);
/* kdm_tileset_load_memory with the same `detail` (for sets read through an engine's own file system).
 * An empty buffer (size 0) is KDM_TRUNCATED, as is any buffer shorter than the file header. Added in
 * 0.5. */
KDM_RUNTIME_API kdm_status kdm_tileset_load_memory_detail(const void* data, size_t size, kdm_tileset** out,
                                                          char* detail, size_t detail_size);
/* The default tile set compiled into the library: decoded on first use (about 0.1 s; call it
 * once at start-up to keep that out of a frame), then shared with kdm::Tileset::builtin(). NULL when
 * memory runs out while it is decoded (a later call tries again). Never free it. */
KDM_RUNTIME_API const kdm_tileset* kdm_tileset_builtin(void);
/* Frees a loaded set; NULL and the built-in set are ignored. */
KDM_RUNTIME_API void kdm_tileset_free(kdm_tileset* tileset);
/* Heap bytes a loaded set occupies (positions, keys, emission thresholds, tables); 0 for NULL. */
KDM_RUNTIME_API size_t kdm_tileset_resident_bytes(const kdm_tileset* tileset);
/* Fills `info` (set info->struct_size first). KDM_INVALID_ARGUMENT for NULL or a struct_size too small. */
KDM_RUNTIME_API kdm_status kdm_tileset_get_info(const kdm_tileset* tileset, kdm_tileset_info* info);
/* The expected count per tile above which `point` is emitted (kdm::emission_threshold): to fade objects in
   as the density rises, weigh each by (count / threshold - 1) / f clamped to [0, 1], count being
   density * scale * (tile_size / m^depth)^2 at the point. KDM_INVALID_ARGUMENT for a NULL argument or a
   point the set does not have (a depth it does not reach, a rank past its tile's points). Added in 0.4. */
KDM_RUNTIME_API kdm_status kdm_point_threshold(const kdm_tileset* tileset, const kdm_point* point,
                                               double* threshold);
/* Where `point` lies unmoved (kdm::stable_position), for tiles of side tile_size, less (origin_x,
   origin_y): where a stable query puts it, and where the density deciding its emission is read, so that a
   fade weight by kdm_point_threshold read there follows the query's rule in smooth mode too.
   KDM_INVALID_ARGUMENT for a NULL argument, a point the set does not have or a tile_size not finite and > 0.
   Added in 0.5. */
KDM_RUNTIME_API kdm_status kdm_point_stable_position(const kdm_tileset* tileset, const kdm_point* point,
                                                     double tile_size, double origin_x, double origin_y,
                                                     double* x, double* y);
/* The same for a point of the compact output known by its key (kdm::point_id_of_key): the key's tile is the
   one nearest (near_tile_x, near_tile_y), in tiles of side tile_size, such as floor(x0 / tile_size) and
   floor(y0 / tile_size) of the query's region (under 2^20 tiles across). Statuses as kdm_point_threshold's.
   Added in 0.5. */
KDM_RUNTIME_API kdm_status kdm_key_threshold(const kdm_tileset* tileset, uint64_t key, int64_t near_tile_x,
                                             int64_t near_tile_y, double* threshold);

/* How evenly `tileset` serves a density of at most `max_density` (a constant's value, an image's or the
 * classes' summed maximum, a callback's density_max) at `scale` on tiles of `tile_size` (kdm::
 * tile_size_advice): where a tile expects fewer points than the set's coarsest level holds it gives part of
 * it, less even, and below one point its count rounds to steps of 1/tiles of a point (0.05 points per
 * tile of the built-in set give 25% too many). A map whose sparse parts fall there is no mistake; its
 * densest value there is a tile size too small. Call it once when choosing a tile size. Added in 0.5. */
enum {
  KDM_TILE_SIZE_EVEN = 0,                 /* the densest value fills at least the coarsest level */
  KDM_TILE_SIZE_UNDER_COARSEST_LEVEL = 1, /* less even everywhere */
  KDM_TILE_SIZE_UNDER_ONE_POINT = 2       /* counts off by up to tens of percent */
};
typedef struct kdm_tile_size_advice {
  int kind;               /* KDM_TILE_SIZE_* (EVEN where an argument is not a positive finite number) */
  double points_per_tile; /* the densest value's expected points per tile */
  double coarsest;        /* the set's coarsest level's points per tile */
  double tile_size;       /* the smallest tile size whose tiles hold the coarsest level at that density */
  size_t tiles;           /* the set's tile count */
} kdm_tile_size_advice;
/* KDM_OK, or KDM_INVALID_ARGUMENT for a NULL tileset or `advice`. */
KDM_RUNTIME_API kdm_status kdm_tile_size_advise(const kdm_tileset* tileset, double max_density, double scale,
                                                double tile_size, kdm_tile_size_advice* advice);

/* A density image over the world rectangle [x0, x1) x [y0, y1) (world units): `width` x `height` texels
 * of density (as kdm_query's `density`: multiplied by `scale`), row-major, row 0 at y0, bilinear between
 * texel centres and clamped at the edges. The values are copied and an 8x8 max-mip is built, so queries
 * skip what cannot be emitted. KDM_INVALID_ARGUMENT for an empty image, a side longer than 2^30 texels, a
 * NULL or negative or non-finite value, or a rectangle that is empty, not finite, or so narrow that its
 * texels per unit overflow (make_density_max_mip's rule); KDM_OUT_OF_MEMORY when its copy does not fit in
 * memory. Free with kdm_density_image_free. */
KDM_RUNTIME_API kdm_status kdm_density_image_create(int width, int height, const float* values, double x0,
                                                    double y0, double x1, double y1, kdm_density_image** out);
/* kdm_density_image_create, and on failure why in `detail` (if not NULL), as kdm_tileset_load_file_detail
 * gives it: the first fault found ("values[17] (column 1, row 2) is -1: values must be finite and >= 0");
 * "" on success. Added in 0.5. */
KDM_RUNTIME_API kdm_status kdm_density_image_create_detail(int width, int height, const float* values,
                                                           double x0, double y0, double x1, double y1,
                                                           kdm_density_image** out, char* detail,
                                                           size_t detail_size);
/* Frees an image (NULL is ignored); no query may be using it. */
KDM_RUNTIME_API void kdm_density_image_free(kdm_density_image* image);
/* The image's density at world (x, y) as a query reads it (bilinear between texel centres, clamped at the
 * edges): what a caller weighing points by their thresholds needs. 0 for a NULL image or a NaN or infinite
 * coordinate. Added in 0.5. */
KDM_RUNTIME_API double kdm_density_image_at(const kdm_density_image* image, double x, double y);

/* Writes up to `capacity` points into `out` (NULL only with capacity 0), *written = count (`written` and
 * `cursor` are required). Capacity 0 checks the query: KDM_INVALID_ARGUMENT, or KDM_BUFFER_FULL at its first
 * point (so a loop resuming while KDM_BUFFER_FULL needs room for a point). KDM_OK when the region is
 * complete, KDM_BUFFER_FULL to be resumed with the same
 * cursor and query (also with room left, after 2^24 candidates in one call, a tile
 * visited counting as 16: kdm::kMaxQueryCandidates), KDM_INVALID_ARGUMENT for bad
 * parameters, with `problem` (optional: NULL, or with struct_size set) saying which and why. A refused
 * call sets *written to 0 and leaves the cursor as it was: the query corrected, the cursor resumes. */
KDM_RUNTIME_API kdm_status kdm_query_points(const kdm_tileset* tileset, const kdm_query* query,
                                            kdm_point* out, size_t capacity, size_t* written,
                                            kdm_cursor* cursor, kdm_query_problem* problem);
/* How many points kdm_query_points would write, into *count, writing none (kdm::count_points): KDM_OK;
 * KDM_BUFFER_FULL after 2^24 candidates, with the count so far: call again with the same cursor and query
 * and add; KDM_INVALID_ARGUMENT as kdm_query_points refuses (a NULL `count` too), with `problem`. A
 * counting cursor is one of its own: kdm_query_points refuses it, and this a query's. Added in 0.5. */
KDM_RUNTIME_API kdm_status kdm_count_points(const kdm_tileset* tileset, const kdm_query* query, size_t* count,
                                            kdm_cursor* cursor, kdm_query_problem* problem);

/* kdm_query_points into a compact output (kdm/runtime/compact_query.h): the same points in the same order
 * (positions computed in float, within 2^-21 * (|position| + tile_size) of the records' doubles, not
 * those doubles rounded: join the two outputs by key, not by position),
 * point i at xy[2i], xy[2i + 1] (floats, relative to the query's origin: keep it near the region) and, if
 * `keys` is not NULL, keys[i] = its 64-bit point key (tile x and y modulo 2^21, rank, depth; unique within
 * any region less than 2^21 tiles across). Statuses and resumption as kdm_query_points (a cursor serves
 * both); KDM_INVALID_ARGUMENT also for a NULL `xy` with room in it, and for keys asked of a set whose tiles
 * hold more than 2^19 points (KDM_PROBLEM_KEYS_UNSUPPORTED). */
KDM_RUNTIME_API kdm_status kdm_query_compact(const kdm_tileset* tileset, const kdm_query* query, float* xy,
                                             uint64_t* keys, size_t capacity, size_t* written,
                                             kdm_cursor* cursor, kdm_query_problem* problem);

/* One class's density for kdm_query_classes: as kdm_query's density fields (an image takes precedence
 * over a callback, a callback over the constant). Zero the struct before filling it. */
typedef struct kdm_class_density {
  double density;
  double (*density_callback)(void* user, double x, double y);
  void* user;
  double density_max; /* > 0 with a callback, as kdm_query's */
  const kdm_density_image* density_image;
  /* Added in 0.4 (the struct grew: rebuild callers; arrays of it have a new stride): optional bounds of
   * the callback's density, as kdm_query's density_bounds; the union takes their sum, and a tile's
   * bounds settle most points' classes without a call. */
  /* *lo and *hi hold NaN when it is called: a callback that writes neither gives no bounds there. */
  void (*density_bounds)(void* user, double x0, double y0, double x1, double y1, double* lo, double* hi);
  /* Added in 0.4: instead of density_callback, the density at n positions at once, as kdm_query's
   * density_batch_callback: a class query reads the classes where it would read their sum, up to
   * KDM_DENSITY_BATCH positions a call. */
  void (*density_batch_callback)(void* user, size_t n, const double* x, const double* y, double* out);
} kdm_class_density;

#define KDM_MAX_CLASSES 8

/* Several classes in one query (kdm/runtime/class_query.h): the points of a query at the sum of the
 * classes' densities, each with its class (0 ... class_count - 1) in out_classes[i]. `query` gives the
 * region, scale and mode (its density fields are not read); `classes` the densities, class 0 first. In
 * stable mode class 0 alone is exactly kdm_query_points at class 0's density, and classes 0 ... k together
 * at their summed density. Statuses and resumption as kdm_query_points; KDM_INVALID_ARGUMENT also for a
 * class count of 0 or more than KDM_MAX_CLASSES, a NULL `classes`, or a NULL `out_classes` with room in
 * `out`. */
KDM_RUNTIME_API kdm_status kdm_query_classes(const kdm_tileset* tileset, const kdm_query* query,
                                             const kdm_class_density* classes, uint32_t class_count,
                                             kdm_point* out, uint8_t* out_classes, size_t capacity,
                                             size_t* written, kdm_cursor* cursor, kdm_query_problem* problem);

/* kdm_query_classes into a compact output, as kdm_query_compact writes one: the same points, order and
 * classes, positions as float pairs in xy[2i], xy[2i + 1] (those kdm_query_compact writes at the sum of
 * the densities), keys in keys[i] when `keys` is not NULL, classes in out_classes[i]. Statuses, resumption
 * and refusals as kdm_query_classes' and kdm_query_compact's. */
KDM_RUNTIME_API kdm_status kdm_query_classes_compact(const kdm_tileset* tileset, const kdm_query* query,
                                                     const kdm_class_density* classes, uint32_t class_count,
                                                     float* xy, uint64_t* keys, uint8_t* out_classes,
                                                     size_t capacity, size_t* written, kdm_cursor* cursor,
                                                     kdm_query_problem* problem);

/* Every class's density from one call (kdm::JointClassDensity), for classes that share their inputs:
 * `densities` writes the class_count densities at (x, y), class 0 first, into values[0 ... class_count);
 * `density_bounds` (optional) each class's bounds over the rectangle into lo[k], hi[k]; density_max[k] an
 * upper bound of class k's density (finite, > 0: 0, a zeroed struct's, is refused as a callback's
 * density_max is). Zero the struct before filling it. */
typedef struct kdm_joint_class_density {
  void (*densities)(void* user, double x, double y, double* values);
  /* *lo and *hi hold NaN when it is called: a callback that writes neither gives no bounds there. */
  void (*density_bounds)(void* user, double x0, double y0, double x1, double y1, double* lo, double* hi);
  void* user;
  double density_max[KDM_MAX_CLASSES];
  /* Added in 0.4: instead of `densities` (set one of the two), the densities at n positions at once,
   * class k's at (x[i], y[i]) into values[k * n + i], n <= KDM_DENSITY_BATCH, read as a class query reads
   * a density_batch_callback. */
  void (*batch_densities)(void* user, size_t n, const double* x, const double* y, double* values);
} kdm_joint_class_density;

/* kdm_query_classes and kdm_query_classes_compact with the classes' densities from one call: the same
 * points and classes as separate callbacks giving the same values, one call per candidate instead of one
 * per class. KDM_INVALID_ARGUMENT also for a NULL `joint` ("joint", KDM_PROBLEM_MISSING_ARGUMENT),
 * neither of its two density functions ("joint.densities") or both of them ("joint.batch_densities", both
 * KDM_PROBLEM_BAD_DENSITY) and a bad density_max ("joint.density_max[k]"). Added in 0.4. */
KDM_RUNTIME_API kdm_status kdm_query_classes_joint(const kdm_tileset* tileset, const kdm_query* query,
                                                   const kdm_joint_class_density* joint, uint32_t class_count,
                                                   kdm_point* out, uint8_t* out_classes, size_t capacity,
                                                   size_t* written, kdm_cursor* cursor,
                                                   kdm_query_problem* problem);
KDM_RUNTIME_API kdm_status kdm_query_classes_joint_compact(const kdm_tileset* tileset, const kdm_query* query,
                                                           const kdm_joint_class_density* joint,
                                                           uint32_t class_count, float* xy, uint64_t* keys,
                                                           uint8_t* out_classes, size_t capacity,
                                                           size_t* written, kdm_cursor* cursor,
                                                           kdm_query_problem* problem);

/* Classes whose densities are images on one grid (kdm::ClassImageSums, kdm/runtime/class_image_sums.h):
 * the running sums of `count` density images (1 ... KDM_MAX_CLASSES, class 0 first, all of one size and
 * world rectangle), added texel by texel in float, each with its max-mip, into *out. A query then reads one
 * image where kdm_query_classes reads every class's at every candidate: its points are exactly
 * kdm_query_points' at the images' summed texels, and in stable mode classes 0 ... k together exactly those
 * at the first k + 1 images' sum. KDM_INVALID_ARGUMENT for a NULL `out`, `images` or image, a count out of
 * range, images on different grids, or a sum that overflows a float; KDM_OUT_OF_MEMORY. The images may be
 * freed once it is built. kdm_query_classes given the same images sums their bilinear values in double
 * at every candidate instead: stable mode emits the same points, smooth mode the same ids at positions that
 * may differ in their last bits: under 3 * 10^-7 of a tile side (at most 1.5 * 10^-7 measured over 11 million
 * points, tile sides 0.25 to 4, 4 to 4 * 10^5 points per tile; most at 10 to 200, where a glide is fastest
 * against the count; ClassImageSumsTest checks). `kdm query --class` uses these sums when every
 * class is an image, all of one size, holding at most 2^20 texels in all. Free it with
 * kdm_class_images_free. Added in 0.4. */
typedef struct kdm_class_images kdm_class_images;
KDM_RUNTIME_API kdm_status kdm_class_images_create(const kdm_density_image* const* images, uint32_t count,
                                                   kdm_class_images** out);
/* The same, and on KDM_INVALID_ARGUMENT one line into `detail` (if not NULL, `detail_size` bytes with its
 * terminating zero, cut to fit) saying which argument or image is at fault. Added in 0.5. */
KDM_RUNTIME_API kdm_status kdm_class_images_create_detail(const kdm_density_image* const* images,
                                                          uint32_t count, kdm_class_images** out,
                                                          char* detail, size_t detail_size);
/* Frees the sums (NULL is ignored); no query may be using them. */
KDM_RUNTIME_API void kdm_class_images_free(kdm_class_images* images);

/* kdm_query_classes and kdm_query_classes_compact with the classes of `images` (their count is its own):
 * statuses, resumption and refusals as theirs, and KDM_INVALID_ARGUMENT for a NULL `images` ("images").
 * Added in 0.4. */
KDM_RUNTIME_API kdm_status kdm_query_class_images(const kdm_tileset* tileset, const kdm_query* query,
                                                  const kdm_class_images* images, kdm_point* out,
                                                  uint8_t* out_classes, size_t capacity, size_t* written,
                                                  kdm_cursor* cursor, kdm_query_problem* problem);
KDM_RUNTIME_API kdm_status kdm_query_class_images_compact(const kdm_tileset* tileset, const kdm_query* query,
                                                          const kdm_class_images* images, float* xy,
                                                          uint64_t* keys, uint8_t* out_classes,
                                                          size_t capacity, size_t* written,
                                                          kdm_cursor* cursor, kdm_query_problem* problem);

/* One query over several threads (kdm::ParallelQuery, kdm/runtime/parallel_query.h), for callers that fill
 * a large region at once: the region is cut into units fixed by the parameters, so any number of workers
 * gives the same bits, the region's points in kdm_query_points' order (in the units' order where a tile
 * holds more points than a unit: 262,144 at a constant density in stable mode, else 16,384). The library
 * starts no threads: runner->run(context, task, task_context, count) calls task(task_context, i) for i in
 * [0, count) and returns when all it started have returned. Each task takes the region's units in order
 * from a shared counter and may wait for the task holding the unit before its own, which is running, so
 * any schedule works in which a started task runs to its end: concurrently, in turn on one thread, or some
 * tasks not at all so long as one runs (the others take their units); not one that suspends a task to run
 * another of the same call on its thread (fibers that switch while a task waits), which can wait forever.
 * Density callbacks are called from the tasks' threads at once. Added in 0.4. */
typedef struct kdm_task_runner {
  void (*run)(void* context, void (*task)(void* task_context, size_t index), void* task_context,
              size_t count);
  void* context;
} kdm_task_runner;

typedef struct kdm_parallel_query kdm_parallel_query; /* per-worker scratch, allocated once */

/* Scratch for `workers` workers (1 ... 64; about 1.9 MB each, through kdm_set_tileset_allocator's hooks)
 * into *out: KDM_OK, KDM_INVALID_ARGUMENT for a count out of range or a NULL `out`, KDM_OUT_OF_MEMORY (the
 * hooks refused it). One kdm_parallel_query serves one run at a time. */
KDM_RUNTIME_API kdm_status kdm_parallel_query_create(uint32_t workers, kdm_parallel_query** out);
/* Frees the scratch (NULL is ignored); no run may be using it. */
KDM_RUNTIME_API void kdm_parallel_query_free(kdm_parallel_query* parallel);

/* The region's points into out[0 ... capacity) (kdm_query_points' points, in the order above), *written
 * (if not NULL) the count: KDM_OK when all fit; KDM_BUFFER_FULL when there were more (out holds the first
 * `capacity`, *needed, if not NULL, the full count: call again with room for it; capacity 0 and a NULL out
 * only count; with `needed` NULL the run stops soon after the buffer is full); KDM_INVALID_ARGUMENT as
 * kdm_query_points refuses the query, for a NULL parallel query ("parallel") or runner or runner->run
 * ("runner.run", KDM_PROBLEM_MISSING_ARGUMENT), or a runner that returned before its tasks had done the
 * query (KDM_PROBLEM_RUNNER_INCOMPLETE). Allocates nothing. */
KDM_RUNTIME_API kdm_status kdm_parallel_query_points(kdm_parallel_query* parallel,
                                                     const kdm_task_runner* runner,
                                                     const kdm_tileset* tileset, const kdm_query* query,
                                                     kdm_point* out, size_t capacity, size_t* written,
                                                     size_t* needed, kdm_query_problem* problem);
/* The same into the compact output (kdm_query_compact's xy and optional keys). */
KDM_RUNTIME_API kdm_status kdm_parallel_query_compact(kdm_parallel_query* parallel,
                                                      const kdm_task_runner* runner,
                                                      const kdm_tileset* tileset, const kdm_query* query,
                                                      float* xy, uint64_t* keys, size_t capacity,
                                                      size_t* written, size_t* needed,
                                                      kdm_query_problem* problem);
/* Several classes (kdm_query_classes_compact's points and classes) the same way. */
KDM_RUNTIME_API kdm_status kdm_parallel_query_classes_compact(
    kdm_parallel_query* parallel, const kdm_task_runner* runner, const kdm_tileset* tileset,
    const kdm_query* query, const kdm_class_density* classes, uint32_t class_count, float* xy, uint64_t* keys,
    uint8_t* out_classes, size_t capacity, size_t* written, size_t* needed, kdm_query_problem* problem);
/* Several classes from one joint density (kdm_query_classes_joint_compact's points and classes) the same
 * way. */
KDM_RUNTIME_API kdm_status kdm_parallel_query_classes_joint_compact(
    kdm_parallel_query* parallel, const kdm_task_runner* runner, const kdm_tileset* tileset,
    const kdm_query* query, const kdm_joint_class_density* joint, uint32_t class_count, float* xy,
    uint64_t* keys, uint8_t* out_classes, size_t capacity, size_t* written, size_t* needed,
    kdm_query_problem* problem);

/* Classes of images by their sums (kdm_query_class_images_compact's points and classes) the same way. */
KDM_RUNTIME_API kdm_status kdm_parallel_query_class_images_compact(
    kdm_parallel_query* parallel, const kdm_task_runner* runner, const kdm_tileset* tileset,
    const kdm_query* query, const kdm_class_images* images, float* xy, uint64_t* keys, uint8_t* out_classes,
    size_t capacity, size_t* written, size_t* needed, kdm_query_problem* problem);

/* A debugging aid for density callbacks (kdm::DensityCheck). A query counts a callback's NaN, infinite and
 * negative values as 0, treats values above density_max as density_max and trusts density_bounds, so a
 * bug in a density function, its bound or its bounds shows only as missing or extra points. A check routes
 * one density's functions through itself and records the first value that is not finite, >= 0 and <=
 * density_max, or bounds that the density breaks (checked at 9 points of each rectangle asked), with where.
 * It costs a comparison and an extra call per value read, 9 reads per bounds call; the points are
 * unchanged. Thread-safe (parallel queries may use it). Added in 0.5. */
typedef struct kdm_density_check kdm_density_check;

/* A new check into *out: KDM_OK, KDM_INVALID_ARGUMENT for a NULL `out`, KDM_OUT_OF_MEMORY. */
KDM_RUNTIME_API kdm_status kdm_density_check_create(kdm_density_check** out);
/* Frees the check (NULL is ignored); no query may be using a density it wraps. */
KDM_RUNTIME_API void kdm_density_check_free(kdm_density_check* check);
/* Routes `query`'s density_callback, density_batch_callback and density_bounds through `check`, which keeps
 * a copy of them, query->user and density_max as they are now: wrap last, once they are final (a user set
 * afterwards reaches the check's functions in place of the check). Wrapping the same density again (a new
 * kdm_query per chunk with the same functions and user, or the wrapped query itself) takes its
 * density_max. A query whose density is not a callback (a constant, or an image, which takes precedence)
 * is left as it is. KDM_OK; KDM_INVALID_ARGUMENT for a NULL argument, a query->struct_size older than the
 * first, or another density than the one the check wraps: one check per density (each class its own),
 * until kdm_density_check_reset. */
KDM_RUNTIME_API kdm_status kdm_density_check_wrap_query(kdm_density_check* check, kdm_query* query);
/* The same for one class's density of kdm_query_classes. */
KDM_RUNTIME_API kdm_status kdm_density_check_wrap_class(kdm_density_check* check, kdm_class_density* density);
/* The same for the joint density of kdm_query_classes_joint, of `class_count` classes: each class's values
 * against its density_max[k], its density_bounds at the 9 points too; the finding names the class. Also
 * KDM_INVALID_ARGUMENT for a class_count outside 1 ... KDM_MAX_CLASSES. Added in 0.5. */
KDM_RUNTIME_API kdm_status kdm_density_check_wrap_joint(kdm_density_check* check,
                                                        kdm_joint_class_density* joint, uint32_t class_count);
/* 1 once the check found something, with the first finding's value and position in *value, *x, *y (each
 * optional): a value that does not fit, or one outside the bounds given for a rectangle that holds it; 0
 * otherwise (and for a NULL check). */
KDM_RUNTIME_API int kdm_density_check_failed(const kdm_density_check* check, double* value, double* x,
                                             double* y);
/* The largest finite value the check has read (-1 before any, and for a NULL check): far under
 * density_max, a tighter bound lets queries skip more candidates. */
KDM_RUNTIME_API double kdm_density_check_largest(const kdm_density_check* check);
/* The finding in one line ("density callback returned nan at (2.5, 7)", "... returned 3 at (1, 1), above
 * its bound callback_max 2", "density bounds gave [0.3, 0.9] over (0, 0) to (8, 8), but the density is
 * 0.05 at (4, 8)", or "no bad density value", with a hint where the largest value read is under half of
 * density_max), as kdm_query_problem_describe writes its line. */
KDM_RUNTIME_API size_t kdm_density_check_describe(const kdm_density_check* check, char* text, size_t size);
/* Forgets the finding and the density wrapped, so that the check can wrap another (densities wrapped before
 * must no longer be queried). Not while a query using the check runs. */
KDM_RUNTIME_API void kdm_density_check_reset(kdm_density_check* check);

/* A static English description of `status` / of a problem kind ("unknown ..." for a value not listed). */
KDM_RUNTIME_API const char* kdm_status_message(kdm_status status);
KDM_RUNTIME_API const char* kdm_problem_message(kdm_problem_kind kind);
/* `problem` (as a refused query filled it) in one line for a log: the field at fault, the limit it broke
 * and what would be accepted ("... 409600 points per tile where it serves at most 32768; use scale 0.08 or
 * less, or tile_size 18.1019 or less"). Writes at most `size` bytes into `text`, its NUL included (cut to
 * fit; nothing with size 0), and returns the whole line's length without the NUL, as snprintf does; a NULL
 * or too short problem is described as such. Allocates nothing. Added in 0.5. */
KDM_RUNTIME_API size_t kdm_query_problem_describe(const kdm_query_problem* problem, char* text, size_t size);

#ifdef __cplusplus
}
#endif

#endif /* KDM_RUNTIME_H */
