/* The C interface's parallel queries from C: the same bits on one thread run in turn and on two POSIX
 * threads, kdm_query_compact's points and kdm_query_classes_compact's classes (separate densities or one
 * joint function), a short buffer's prefix and count, refusals by name. */
#include <kdm/runtime/kdm_runtime.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "c_check.h"

/* Every task in turn on the calling thread. */
static void run_in_turn(void* context, void (*task)(void*, size_t), void* task_context, size_t count) {
  size_t i;
  (void)context;
  for (i = 0; i < count; ++i) task(task_context, i);
}

/* Every task on a thread of its own (at most 8). */
struct task_call {
  void (*task)(void*, size_t);
  void* task_context;
  size_t index;
};
static void* call_task(void* arg) {
  const struct task_call* c = (const struct task_call*)arg;
  c->task(c->task_context, c->index);
  return NULL;
}
static void run_nothing(void* context, void (*task)(void*, size_t), void* task_context, size_t count) {
  (void)context, (void)task, (void)task_context, (void)count;
}
static void run_on_threads(void* context, void (*task)(void*, size_t), void* task_context, size_t count) {
  pthread_t threads[8];
  struct task_call calls[8];
  size_t i;
  (void)context;
  if (count > 8) abort();
  for (i = 0; i < count; ++i) {
    calls[i].task = task, calls[i].task_context = task_context, calls[i].index = i;
    if (pthread_create(&threads[i], NULL, call_task, &calls[i]) != 0) abort();
  }
  for (i = 0; i < count; ++i) pthread_join(threads[i], NULL);
}

static double ramp(void* user, double x, double y) {
  (void)user, (void)y;
  return 0.2 + 0.1 * x;
}

/* The three classes of main's `three` from one call. */
static void three_joint(void* user, double x, double y, double* values) {
  values[0] = 1.0 / 7, values[1] = ramp(user, x, y), values[2] = 4.0 / 7;
}

enum { kCapacity = 1 << 20 };
static float xy[2][2 * kCapacity], one_xy[2 * kCapacity];
static uint64_t keys[2][kCapacity], one_keys[kCapacity];
static uint8_t classes[2][kCapacity], one_classes[kCapacity];

int main(void) {
  const kdm_tileset* builtin = kdm_tileset_builtin();
  kdm_parallel_query* parallel = NULL;
  kdm_task_runner in_turn = {run_in_turn, NULL}, on_threads = {run_on_threads, NULL};
  kdm_query q;
  kdm_query_problem problem;
  kdm_class_density three[3];
  kdm_cursor cursor;
  size_t n[2] = {0, 0}, needed = 0, one = 0, i;
  int mode;
  memset(&q, 0, sizeof q);
  q.struct_size = sizeof q;
  q.x0 = -1.5, q.y0 = 0.25, q.x1 = 4.5, q.y1 = 5, q.origin_x = 1, q.tile_size = 1, q.scale = 20000;
  q.density_callback = ramp, q.density_max = 0.9;
  memset(&problem, 0, sizeof problem);
  problem.struct_size = sizeof problem;
  memset(three, 0, sizeof three);
  three[0].density = 1.0 / 7, three[1].density_callback = ramp, three[1].density_max = 0.9;
  three[2].density = 4.0 / 7;

  CHECK(kdm_parallel_query_create(0, &parallel) == KDM_INVALID_ARGUMENT && parallel == NULL);
  CHECK(kdm_parallel_query_create(65, &parallel) == KDM_INVALID_ARGUMENT);
  CHECK(kdm_parallel_query_create(2, NULL) == KDM_INVALID_ARGUMENT);
  CHECK(kdm_parallel_query_create(2, &parallel) == KDM_OK && parallel != NULL);
  for (mode = 0; mode < 2; ++mode) {
    q.mode = mode ? KDM_MODE_SMOOTH : KDM_MODE_STABLE;
    /* One point at a time of one query, then one and two threads: the same points, keys and bits. */
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_compact(builtin, &q, one_xy, one_keys, kCapacity, &one, &cursor, NULL) == KDM_OK);
    CHECK(kdm_parallel_query_compact(parallel, &in_turn, builtin, &q, xy[0], keys[0], kCapacity, &n[0],
                                     &needed, NULL) == KDM_OK);
    CHECK(kdm_parallel_query_compact(parallel, &on_threads, builtin, &q, xy[1], keys[1], kCapacity, &n[1],
                                     NULL, NULL) == KDM_OK);
    CHECK(n[0] == n[1] && n[0] == needed && n[0] == one && one > 100000);
    CHECK(memcmp(xy[0], xy[1], 2 * n[0] * sizeof(float)) == 0 && memcmp(keys[0], keys[1], n[0] * 8) == 0);
    {
      /* The same keys as one query's, each at the same position (the units' order is their own). */
      uint64_t sum[2] = {0, 0};
      for (i = 0; i < one; ++i) sum[0] += one_keys[i] * 2654435761u, sum[1] += keys[0][i] * 2654435761u;
      CHECK(sum[0] == sum[1]);
    }
    /* Three classes: kdm_query_classes_compact's classes, the same on one thread and two. */
    memset(&cursor, 0, sizeof cursor);
    CHECK(kdm_query_classes_compact(builtin, &q, three, 3, one_xy, one_keys, one_classes, kCapacity, &one,
                                    &cursor, NULL) == KDM_OK);
    CHECK(kdm_parallel_query_classes_compact(parallel, &in_turn, builtin, &q, three, 3, xy[0], keys[0],
                                             classes[0], kCapacity, &n[0], NULL, NULL) == KDM_OK);
    CHECK(kdm_parallel_query_classes_compact(parallel, &on_threads, builtin, &q, three, 3, xy[1], keys[1],
                                             classes[1], kCapacity, &n[1], NULL, NULL) == KDM_OK);
    CHECK(n[0] == n[1] && n[0] == one && memcmp(classes[0], classes[1], n[0]) == 0);
    {
      /* The same three classes from one joint function: the same points and classes. */
      kdm_joint_class_density joint;
      memset(&joint, 0, sizeof joint);
      joint.densities = three_joint;
      joint.density_max[0] = 1.0 / 7, joint.density_max[1] = 0.9, joint.density_max[2] = 4.0 / 7;
      CHECK(kdm_parallel_query_classes_joint_compact(parallel, &on_threads, builtin, &q, &joint, 3, xy[1],
                                                     keys[1], classes[1], kCapacity, &n[1], NULL,
                                                     NULL) == KDM_OK);
      CHECK(n[1] == n[0] && memcmp(xy[0], xy[1], 2 * n[0] * sizeof(float)) == 0 &&
            memcmp(classes[0], classes[1], n[0]) == 0);
    }
    {
      size_t counts[2][3] = {{0, 0, 0}, {0, 0, 0}};
      for (i = 0; i < one; ++i) ++counts[0][one_classes[i]], ++counts[1][classes[0][i]];
      CHECK(memcmp(counts[0], counts[1], sizeof counts[0]) == 0 && counts[0][0] > 10000);
    }
    {
      /* Classes of images by their sums: one query's keys and classes, on two threads. */
      static float texels[3][8 * 8];
      kdm_density_image* images[3];
      kdm_class_images* class_images = NULL;
      uint64_t hash[2] = {0, 0};
      int k;
      for (i = 0; i < 64; ++i)
        texels[0][i] = 1.0f / 7, texels[1][i] = (float)(0.1 + 0.1 * (double)(i % 8)), texels[2][i] = 4.0f / 7;
      for (k = 0; k < 3; ++k)
        CHECK(kdm_density_image_create(8, 8, texels[k], -2, 0, 5, 5, &images[k]) == KDM_OK);
      CHECK(kdm_class_images_create((const kdm_density_image* const*)images, 3, &class_images) == KDM_OK);
      memset(&cursor, 0, sizeof cursor);
      CHECK(kdm_query_class_images_compact(builtin, &q, class_images, one_xy, one_keys, one_classes,
                                           kCapacity, &one, &cursor, NULL) == KDM_OK);
      CHECK(kdm_parallel_query_class_images_compact(parallel, &on_threads, builtin, &q, class_images, xy[1],
                                                    keys[1], classes[1], kCapacity, &n[1], NULL,
                                                    NULL) == KDM_OK);
      for (i = 0; i < one; ++i)
        hash[0] += (one_keys[i] ^ one_classes[i]) * 2654435761u,
            hash[1] += (keys[1][i] ^ classes[1][i]) * 2654435761u;
      CHECK(n[1] == one && one > 100000 && hash[0] == hash[1]);
      CHECK(kdm_parallel_query_class_images_compact(parallel, &on_threads, builtin, &q, NULL, xy[1], keys[1],
                                                    classes[1], kCapacity, &n[1], NULL,
                                                    &problem) == KDM_INVALID_ARGUMENT);
      CHECK(problem.kind == KDM_PROBLEM_MISSING_ARGUMENT && strcmp(problem.parameter, "images") == 0);
      kdm_class_images_free(class_images);
      for (k = 0; k < 3; ++k) kdm_density_image_free(images[k]);
    }
  }
  /* A short buffer: the first points and the full count. */
  CHECK(kdm_parallel_query_compact(parallel, &on_threads, builtin, &q, xy[0], keys[0], kCapacity, &n[0], NULL,
                                   NULL) == KDM_OK);
  CHECK(kdm_parallel_query_compact(parallel, &on_threads, builtin, &q, xy[1], keys[1], 1000, &n[1], &needed,
                                   NULL) == KDM_BUFFER_FULL);
  CHECK(n[1] == 1000 && needed == n[0] && memcmp(xy[1], xy[0], 2000 * sizeof(float)) == 0);
  {
    kdm_point points[16];
    CHECK(kdm_parallel_query_points(parallel, &in_turn, builtin, &q, points, 16, &n[1], &needed, NULL) ==
          KDM_BUFFER_FULL);
    CHECK(n[1] == 16 && needed == n[0]);
  }
  /* Refused by name. */
  CHECK(kdm_parallel_query_compact(NULL, &in_turn, builtin, &q, xy[0], NULL, 16, &n[0], NULL, &problem) ==
        KDM_INVALID_ARGUMENT);
  CHECK(problem.kind == KDM_PROBLEM_MISSING_ARGUMENT && strcmp(problem.parameter, "parallel") == 0);
  CHECK(kdm_parallel_query_compact(parallel, NULL, builtin, &q, xy[0], NULL, 16, &n[0], NULL, &problem) ==
        KDM_INVALID_ARGUMENT);
  CHECK(problem.kind == KDM_PROBLEM_MISSING_ARGUMENT && strcmp(problem.parameter, "runner.run") == 0);
  { /* a runner that returns without running its tasks: an error, not an empty region */
    const kdm_task_runner idle = {run_nothing, NULL};
    CHECK(kdm_parallel_query_compact(parallel, &idle, builtin, &q, xy[0], NULL, 16, &n[0], NULL, &problem) ==
          KDM_INVALID_ARGUMENT);
    CHECK(problem.kind == KDM_PROBLEM_RUNNER_INCOMPLETE && strcmp(problem.parameter, "runner.run") == 0);
    CHECK(problem.value == 0 && problem.limit >= 1);
    {
      char line[300];
      kdm_query_problem_describe(&problem, line, sizeof line);
      CHECK(strstr(line, "returned without running any task") && !strstr(line, "null"));
    }
  }
  q.scale = -1;
  CHECK(kdm_parallel_query_compact(parallel, &in_turn, builtin, &q, xy[0], NULL, 16, &n[0], NULL, &problem) ==
        KDM_INVALID_ARGUMENT);
  CHECK(problem.kind == KDM_PROBLEM_NEGATIVE && strcmp(problem.parameter, "scale") == 0);
  q.scale = 100;
  CHECK(kdm_parallel_query_classes_compact(parallel, &in_turn, builtin, &q, three, 9, xy[0], NULL, classes[0],
                                           16, &n[0], NULL, &problem) == KDM_INVALID_ARGUMENT);
  CHECK(problem.kind == KDM_PROBLEM_BAD_CLASS_COUNT);
  /* A null output is named as the one-call queries name it. */
  CHECK(kdm_parallel_query_compact(parallel, &in_turn, builtin, &q, NULL, NULL, 16, &n[0], NULL, &problem) ==
        KDM_INVALID_ARGUMENT);
  CHECK(problem.kind == KDM_PROBLEM_MISSING_ARGUMENT && strcmp(problem.parameter, "xy") == 0);
  CHECK(kdm_parallel_query_classes_compact(parallel, &in_turn, builtin, &q, three, 3, xy[0], NULL, NULL, 16,
                                           &n[0], NULL, &problem) == KDM_INVALID_ARGUMENT);
  CHECK(problem.kind == KDM_PROBLEM_MISSING_ARGUMENT && strcmp(problem.parameter, "out_classes") == 0);
  kdm_parallel_query_free(parallel);
  kdm_parallel_query_free(NULL);
  printf("c api parallel ok\n");
  return 0;
}
