// The C interface (kdm_runtime.h) over kdm/runtime/query.h. Nothing here throws: every function that
// allocates returns KDM_OUT_OF_MEMORY when an allocation is refused, and queries allocate nothing.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <vector>

#include "image_sampler.h"
#include "kdm/runtime/class_image_sums.h"
#include "kdm/runtime/class_query.h"
#include "kdm/runtime/compact_query.h"
#include "kdm/runtime/density_check.h"
#include "kdm/runtime/kdm_runtime.h"
#include "kdm/runtime/parallel_query.h"
#include "kdm/runtime/query.h"
#include "tileset_handle.h"

struct kdm_density_image {
  kdm::DensityImageView view;
  // malloc'd: a caller's size may not fit in memory, or even in what operator new[] accepts, and that is
  // a status here, not an exception.
  std::unique_ptr<float, decltype(&std::free)> values{nullptr, std::free};
  std::vector<float> mip;
};

struct kdm_parallel_query {
  kdm::ParallelQuery parallel;
};

struct kdm_density_check {
  kdm::DensityCheck check;
};

struct kdm_class_images {
  kdm::ClassImageSums sums;
};

namespace {

// A C caller may hand any int in an enum; in C++ loading one outside the enumerators' range is
// undefined, so the value is read as the int it is.
template <typename Enum>
int enum_as_int(const Enum& value) {
  static_assert(sizeof(Enum) == sizeof(int), "C enums are int-sized here");
  int number;
  std::memcpy(&number, &value, sizeof number);
  return number;
}

kdm_status to_c(kdm::Status s) {
  return static_cast<kdm_status>(static_cast<int>(s));
}

/// build()'s status, KDM_OUT_OF_MEMORY where it throws std::bad_alloc (this file keeps exceptions in an
/// engine's -fno-exceptions build: runtime/CMakeLists.txt).
template <class Build>
kdm_status unless_out_of_memory(Build build) {
#if defined(__cpp_exceptions) || defined(__EXCEPTIONS)
  try {
    return to_c(build());
  } catch (const std::bad_alloc&) {
    return KDM_OUT_OF_MEMORY;
  }
#else
  return to_c(build());
#endif
}

/// A new handle whose building returned `status`: into *out when KDM_OK, else freed. Returns `status`.
template <class Handle>
kdm_status hand_over(Handle* handle, kdm_status status, Handle** out) {
  if (status != KDM_OK) {
    delete handle;
    return status;
  }
  *out = handle;
  return KDM_OK;
}

template <class Load>
kdm_status load_into(kdm_tileset** out, Load&& load) {
  if (!out) return KDM_INVALID_ARGUMENT;
  *out = nullptr;
  auto* handle = new (std::nothrow) kdm_tileset;
  if (!handle) return KDM_OUT_OF_MEMORY;
  // The load itself says kOutOfMemory; this catches what comes before it (the path made a std::string).
  const kdm_status c = unless_out_of_memory([&] { return load(handle->owned); });
  const kdm::Status s = static_cast<kdm::Status>(static_cast<int>(c));
  if (s != kdm::Status::kOk) {
    delete handle;
    return to_c(s);
  }
  *out = handle;
  return KDM_OK;
}

/// A caller's struct of `size` bytes (its struct_size) as this header's version: the bytes it has, the
/// rest zero. False if it is shorter than the first version that had struct_size.
template <class T>
bool read_grown(const T* in, std::size_t first_version_size, T& out) {
  if (!in || in->struct_size < first_version_size) return false;
  std::memset(&out, 0, sizeof out);
  std::memcpy(&out, in, std::min(in->struct_size, sizeof(T)));
  return true;
}

/// Writes `value` into the caller's struct, no more bytes than its struct_size, which it keeps.
template <class T>
void write_grown(const T& value, T* out) {
  const std::size_t size = out->struct_size;
  std::memcpy(out, &value, std::min(size, sizeof(T)));
  out->struct_size = size;
}

// The sizes of the first versions of the structs: later fields read as zero from older callers.
constexpr std::size_t kQueryV1 = offsetof(kdm_query, mode);
constexpr std::size_t kProblemV1 = sizeof(kdm_query_problem);
constexpr std::size_t kInfoV1 = offsetof(kdm_tileset_info, keyframes);

/// Checks a C query's arguments and reads its region, scale and mode into `q`; false with `why` set.
bool read_query(const kdm_tileset* tileset, const kdm_query* query, const kdm_cursor* cursor, size_t* written,
                kdm::QueryParams& q, kdm::QueryProblem& why) {
  if (written) *written = 0;
  kdm_query c;
  if (!tileset) {
    why.kind = kdm::QueryProblem::Kind::kMissingArgument, why.parameter = "tileset";
  } else if (!query) {
    why.kind = kdm::QueryProblem::Kind::kMissingArgument, why.parameter = "query";
  } else if (!read_grown(query, kQueryV1, c)) {
    why.kind = kdm::QueryProblem::Kind::kNotPositive, why.parameter = "query.struct_size";
    why.value = static_cast<double>(query->struct_size), why.limit = static_cast<double>(kQueryV1);
  } else if (!cursor) {
    why.kind = kdm::QueryProblem::Kind::kMissingArgument, why.parameter = "cursor";
  } else {
    q.x0 = c.x0, q.y0 = c.y0, q.x1 = c.x1, q.y1 = c.y1;
    q.origin_x = c.origin_x, q.origin_y = c.origin_y;
    q.tile_size = c.tile_size, q.scale = c.scale;
    q.mode = static_cast<kdm::QueryMode>(c.mode);  // the query refuses values it does not know
    q.glide_together = c.glide_together != 0;
    return true;
  }
  return false;
}

/// A C density (image first, then callback, then the constant) as a QueryDensity.
kdm::QueryDensity to_density(double constant, double (*callback)(void*, double, double), void* user,
                             double callback_max, const kdm_density_image* image) {
  kdm::QueryDensity d;
  if (image) {
    d.kind = kdm::QueryDensity::Kind::kImage;
    d.image = &image->view;
  } else if (callback) {
    d.kind = kdm::QueryDensity::Kind::kCallback;
    d.callback = callback, d.user = user, d.callback_max = callback_max;
  } else {
    d.constant = constant;
  }
  return d;
}

/// A C batch callback (if not NULL and no image takes precedence) into `d`, made by to_density.
void with_batch_callback(kdm::QueryDensity& d,
                         void (*batch)(void*, size_t, const double*, const double*, double*), void* user,
                         double callback_max, const kdm_density_image* image) {
  if (!batch || image) return;
  d.kind = kdm::QueryDensity::Kind::kCallback;
  d.batch_callback = batch, d.user = user, d.callback_max = callback_max;
}

/// A C callback bounded by 0 would never be called: its struct was zeroed and density_max left unset (C++'s
/// default bound is 1). Refused as `name`, where C++ takes 0 as an empty density.
bool unset_callback_bound(const kdm::QueryDensity& d, const char* name, kdm::QueryProblem& why) {
  // Negative too: "must be > 0" names what is wanted, where "must not be negative" would allow 0.
  if (d.kind != kdm::QueryDensity::Kind::kCallback || !(d.callback_max <= 0)) return false;
  why.kind = kdm::QueryProblem::Kind::kNotPositive, why.parameter = name, why.value = d.callback_max;
  return true;
}

/// Bounds given with neither a callback to bound nor an image: the density would silently be the struct's
/// constant, most often a zeroed struct's 0. Refused as `name`, the callback missing (C++ names the kind).
bool bounds_without_callback(const kdm::QueryDensity& d, const char* name, kdm::QueryProblem& why) {
  if (!d.bounds || d.kind != kdm::QueryDensity::Kind::kConstant) return false;
  why.kind = kdm::QueryProblem::Kind::kBadDensity, why.parameter = name;
  return true;
}

/// kdm_point and QueryPoint share their layout: queries write straight into the caller's buffer.
kdm::QueryPoint* as_points(kdm_point* out) {
  static_assert(sizeof(kdm_point) == sizeof(kdm::QueryPoint), "kdm_point mirrors QueryPoint");
  return reinterpret_cast<kdm::QueryPoint*>(out);
}

/// Runs `query` with the C cursor as a QueryCursor, written back afterwards.
template <class Query>
kdm_status with_cursor(kdm_cursor* cursor, Query&& query) {
  kdm::QueryCursor k{cursor->tile_x,        cursor->tile_y,      cursor->rank,  cursor->started != 0,
                     cursor->finished != 0, cursor->fingerprint, cursor->depth, cursor->path};
  const kdm::Status status = query(&k);
  *cursor = kdm_cursor{k.tile_x,           k.tile_y,      k.rank,  k.started ? 1 : 0,
                       k.finished ? 1 : 0, k.fingerprint, k.depth, k.path};
  return to_c(status);
}

static_assert(static_cast<int>(kdm::Status::kOutOfMemory) == KDM_OUT_OF_MEMORY, "one code for running out");
static_assert(KDM_DENSITY_BATCH == kdm::kDensityBatch, "the C and C++ batch sizes agree");
static_assert(static_cast<int>(kdm::TileSizeAdvice::Kind::kUnderOnePoint) == KDM_TILE_SIZE_UNDER_ONE_POINT,
              "kdm_tile_size_advice's kinds mirror TileSizeAdvice::Kind");
static_assert(static_cast<int>(kdm::QueryProblem::Kind::kRunnerIncomplete) == KDM_PROBLEM_RUNNER_INCOMPLETE,
              "kdm_problem_kind mirrors QueryProblem::Kind, the last kind included");

// C's names for class k's density fields (kdm_class_density's, not kdm::QueryDensity's) and the joint
// density's maxima.
#define KDM_CLASS_NAMES(field)                                                                               \
  {                                                                                                          \
    "classes[0]." field, "classes[1]." field, "classes[2]." field, "classes[3]." field, "classes[4]." field, \
        "classes[5]." field, "classes[6]." field, "classes[7]." field                                        \
  }
constexpr const char* kClassDensityNames[][KDM_MAX_CLASSES] = {
    KDM_CLASS_NAMES("density"), KDM_CLASS_NAMES("density_max"), KDM_CLASS_NAMES("density_image"),
    KDM_CLASS_NAMES("density_callback"), KDM_CLASS_NAMES("density_batch_callback")};
#undef KDM_CLASS_NAMES
constexpr const char* kJointMaxNames[KDM_MAX_CLASSES] = {
    "joint.density_max[0]", "joint.density_max[1]", "joint.density_max[2]", "joint.density_max[3]",
    "joint.density_max[4]", "joint.density_max[5]", "joint.density_max[6]", "joint.density_max[7]"};

/// The C spelling of a refused parameter (static storage): kdm_query's density fields and the C
/// functions' arguments where C++ names them otherwise (QueryParams' density.*, CompactPoints' out.*,
/// ClassQueryParams' classes[k].* and joint.max[k]).
const char* c_parameter(const char* name) {
  static constexpr const char* kRenamed[][2] = {{"density.constant", "density"},
                                                {"density.callback_max", "density_max"},
                                                {"density.image", "density_image"},
                                                {"density.callback", "density_callback"},
                                                {"density.batch_callback", "density_batch_callback"},
                                                {"out.xy", "xy"},
                                                {"out.keys", "keys"}};
  for (const auto& r : kRenamed)
    if (std::strcmp(name, r[0]) == 0) return r[1];
  static constexpr const char* kClassFields[] = {"constant", "callback_max", "image", "callback",
                                                 "batch_callback"};
  if (std::strncmp(name, "classes[", 8) == 0) {  // "classes[k].field", k one digit
    const unsigned k = static_cast<unsigned>(name[8] - '0');
    if (k < KDM_MAX_CLASSES && std::strncmp(name + 9, "].", 2) == 0)
      for (std::size_t f = 0; f < 5; ++f)
        if (std::strcmp(name + 11, kClassFields[f]) == 0) return kClassDensityNames[f][k];
  }
  if (std::strncmp(name, "joint.max[", 10) == 0) {
    const unsigned k = static_cast<unsigned>(name[10] - '0');
    if (k < KDM_MAX_CLASSES) return kJointMaxNames[k];
  }
  return name;
}

/// Writes `why` into the caller's problem struct, if it gave one.
void report(const kdm::QueryProblem& why, kdm_query_problem* problem) {
  if (!problem || problem->struct_size < kProblemV1) return;
  kdm_query_problem p;
  std::memset(&p, 0, sizeof p);
  p.kind = static_cast<kdm_problem_kind>(static_cast<int>(why.kind));
  p.parameter = c_parameter(why.parameter);
  p.value = why.value, p.limit = why.limit;
  p.largest_valid = why.largest_valid, p.largest_tile_size = why.largest_tile_size;
  write_grown(p, problem);
}

/// A one-density query of the C API: reads its parameters and density, runs `query` (params, cursor,
/// problem) with the C cursor, and reports its problem.
template <class Query>
kdm_status run_query(const kdm_tileset* tileset, const kdm_query* query, size_t* written, kdm_cursor* cursor,
                     kdm_query_problem* problem, Query&& run) {
  kdm::QueryProblem why;
  kdm::QueryParams q;
  kdm_status status = KDM_INVALID_ARGUMENT;
  if (read_query(tileset, query, cursor, written, q, why)) {
    q.density = to_density(query->density, query->density_callback, query->user, query->density_max,
                           query->density_image);
    if (query->struct_size >= offsetof(kdm_query, density_bounds) + sizeof query->density_bounds)
      q.density.bounds = query->density_bounds;
    if (query->struct_size >=
        offsetof(kdm_query, density_batch_callback) + sizeof query->density_batch_callback)
      with_batch_callback(q.density, query->density_batch_callback, query->user, query->density_max,
                          query->density_image);
    if (!unset_callback_bound(q.density, "density_max", why) &&
        !bounds_without_callback(q.density, "density_callback", why))
      status = with_cursor(cursor, [&](kdm::QueryCursor* k) { return run(q, k, &why); });
  }
  report(why, problem);
  return status;
}

/// The densities a C class query reads: separate classes, one joint density, or images by their sums.
struct ClassSource {
  enum Kind { kClasses, kJoint, kImages } kind;
  const kdm_class_density* classes = nullptr;
  const kdm_joint_class_density* joint = nullptr;
  const kdm_class_images* images = nullptr;
};

/// Reads the class densities (`source`) into `q` and runs
/// `run(q, cursor, why)` (a class query) with the C cursor.
template <class Run>
kdm_status run_class_query(const kdm_tileset* tileset, const kdm_query* query, const ClassSource& source,
                           uint32_t class_count, size_t* written, kdm_cursor* cursor,
                           kdm_query_problem* problem, Run run) {
  const kdm_class_density* classes = source.classes;
  const kdm_joint_class_density* joint = source.joint;
  kdm::QueryProblem why;
  kdm::ClassQueryParams q;
  kdm_status status = KDM_INVALID_ARGUMENT;
  if (!read_query(tileset, query, cursor, written, q.query, why)) {
  } else if (source.kind == ClassSource::kJoint && joint && !joint->densities && !joint->batch_densities) {
    why.kind = kdm::QueryProblem::Kind::kBadDensity, why.parameter = "joint.densities";  // no function set
  } else if (source.kind == ClassSource::kJoint    ? !joint
             : source.kind == ClassSource::kImages ? !source.images
                                                   : !classes) {
    why.kind = kdm::QueryProblem::Kind::kMissingArgument;
    why.parameter = source.kind == ClassSource::kJoint    ? "joint"
                    : source.kind == ClassSource::kImages ? "images"
                                                          : "classes";
  } else if (class_count < 1 || class_count > kdm::kMaxQueryClasses) {
    why.kind = kdm::QueryProblem::Kind::kBadClassCount, why.parameter = "class_count";
    why.value = class_count, why.limit = kdm::kMaxQueryClasses;
  } else {
    q.class_count = class_count;
    bool unset = false;
    for (uint32_t k = 0; k < class_count && source.kind == ClassSource::kClasses && !unset; ++k) {
      const kdm_class_density& c = classes[k];
      q.classes[k] = to_density(c.density, c.density_callback, c.user, c.density_max, c.density_image);
      q.classes[k].bounds = c.density_bounds;
      with_batch_callback(q.classes[k], c.density_batch_callback, c.user, c.density_max, c.density_image);
      unset = unset_callback_bound(q.classes[k], kClassDensityNames[1][k], why) ||
              bounds_without_callback(q.classes[k], kClassDensityNames[3][k], why);
    }
    if (source.kind == ClassSource::kImages) q.image_sums = &source.images->sums;
    if (source.kind == ClassSource::kJoint) {
      q.joint.densities = joint->densities, q.joint.bounds = joint->density_bounds,
      q.joint.user = joint->user, q.joint.batch_densities = joint->batch_densities;
      std::copy(joint->density_max, joint->density_max + class_count, q.joint.max);
      for (uint32_t k = 0; k < class_count && !unset; ++k) {
        if (!(std::isfinite(q.joint.max[k]) && q.joint.max[k] >= 0)) break;  // C++ names it, in order
        if (q.joint.max[k] == 0) {  // a zeroed struct's: it would silently leave class k out
          why.kind = kdm::QueryProblem::Kind::kNotPositive, why.parameter = kJointMaxNames[k];
          why.value = q.joint.max[k], unset = true;
        }
      }
    }
    if (!unset) status = with_cursor(cursor, [&](kdm::QueryCursor* k) { return run(q, k, &why); });
  }
  report(why, problem);
  return status;
}

/// The C name of a class query's refused argument: C++'s output `classes` is `out_classes` here, where
/// `classes` names the densities.
kdm::Status with_c_names(kdm::Status status, kdm::QueryProblem* why) {
  if (why->kind == kdm::QueryProblem::Kind::kMissingArgument && std::strcmp(why->parameter, "classes") == 0)
    why->parameter = "out_classes";
  return status;
}

/// The class queries into records and into the compact output, for any kind of densities.
kdm_status class_records(const kdm_tileset* tileset, const kdm_query* query, const ClassSource& source,
                         uint32_t class_count, kdm_point* out, uint8_t* out_classes, size_t capacity,
                         size_t* written, kdm_cursor* cursor, kdm_query_problem* problem) {
  return run_class_query(tileset, query, source, class_count, written, cursor, problem,
                         [&](const kdm::ClassQueryParams& q, kdm::QueryCursor* k, kdm::QueryProblem* why) {
                           return with_c_names(kdm::query_classes(*tileset->set, q, as_points(out),
                                                                  out_classes, capacity, written, k, why),
                                               why);
                         });
}
kdm_status class_compact(const kdm_tileset* tileset, const kdm_query* query, const ClassSource& source,
                         uint32_t class_count, float* xy, uint64_t* keys, uint8_t* out_classes,
                         size_t capacity, size_t* written, kdm_cursor* cursor, kdm_query_problem* problem) {
  return run_class_query(tileset, query, source, class_count, written, cursor, problem,
                         [&](const kdm::ClassQueryParams& q, kdm::QueryCursor* k, kdm::QueryProblem* why) {
                           return with_c_names(
                               kdm::query_classes_compact(*tileset->set, q, kdm::CompactPoints{xy, keys},
                                                          out_classes, capacity, written, k, why),
                               why);
                         });
}

/// A parallel query of the C API: checks the parallel query and the runner, then returns run(task_runner,
/// cursor), whose cursor only satisfies the query readers (a run has none).
template <class Run>
kdm_status run_parallel(const kdm_parallel_query* parallel, const kdm_task_runner* runner, size_t* written,
                        kdm_query_problem* problem, Run&& run) {
  if (written) *written = 0;
  kdm::QueryProblem why;
  why.kind = kdm::QueryProblem::Kind::kMissingArgument;
  if (!parallel) {
    why.parameter = "parallel";
  } else if (!runner || !runner->run) {
    why.parameter = "runner.run";
  } else {
    kdm_cursor unused{};
    return run(kdm::TaskRunner{runner->run, runner->context}, &unused);
  }
  report(why, problem);
  return KDM_INVALID_ARGUMENT;
}

/// The parallel class queries, for any kind of densities (run_class_query's `source`).
kdm_status parallel_classes(kdm_parallel_query* parallel, const kdm_task_runner* runner,
                            const kdm_tileset* tileset, const kdm_query* query, const ClassSource& source,
                            uint32_t class_count, float* xy, uint64_t* keys, uint8_t* out_classes,
                            size_t capacity, size_t* written, size_t* needed, kdm_query_problem* problem) {
  return run_parallel(parallel, runner, written, problem, [&](const kdm::TaskRunner& r, kdm_cursor* cursor) {
    return run_class_query(tileset, query, source, class_count, written, cursor, problem,
                           [&](const kdm::ClassQueryParams& q, kdm::QueryCursor*, kdm::QueryProblem* why) {
                             return with_c_names(
                                 parallel->parallel.run(*tileset->set, q, kdm::CompactPoints{xy, keys},
                                                        out_classes, capacity, written, r, needed, why),
                                 why);
                           });
  });
}

}  // namespace

kdm_tileset& kdm::detail::builtin_handle() {
  static kdm_tileset handle;
  return handle;
}

extern "C" {

kdm_status kdm_parallel_query_create(uint32_t workers, kdm_parallel_query** out) {
  if (!out) return KDM_INVALID_ARGUMENT;
  *out = nullptr;
  if (workers < 1 || workers > kdm::kMaxParallelWorkers) return KDM_INVALID_ARGUMENT;
  auto* handle = new (std::nothrow) kdm_parallel_query;
  if (!handle) return KDM_OUT_OF_MEMORY;
  return hand_over(handle, unless_out_of_memory([&] { return handle->parallel.init(workers); }), out);
}

void kdm_parallel_query_free(kdm_parallel_query* parallel) {
  delete parallel;
}

kdm_status kdm_parallel_query_points(kdm_parallel_query* parallel, const kdm_task_runner* runner,
                                     const kdm_tileset* tileset, const kdm_query* query, kdm_point* out,
                                     size_t capacity, size_t* written, size_t* needed,
                                     kdm_query_problem* problem) {
  return run_parallel(parallel, runner, written, problem, [&](const kdm::TaskRunner& r, kdm_cursor* cursor) {
    return run_query(tileset, query, written, cursor, problem,
                     [&](const kdm::QueryParams& q, kdm::QueryCursor*, kdm::QueryProblem* why) {
                       return parallel->parallel.run(*tileset->set, q, as_points(out), capacity, written, r,
                                                     needed, why);
                     });
  });
}

kdm_status kdm_parallel_query_compact(kdm_parallel_query* parallel, const kdm_task_runner* runner,
                                      const kdm_tileset* tileset, const kdm_query* query, float* xy,
                                      uint64_t* keys, size_t capacity, size_t* written, size_t* needed,
                                      kdm_query_problem* problem) {
  return run_parallel(parallel, runner, written, problem, [&](const kdm::TaskRunner& r, kdm_cursor* cursor) {
    return run_query(tileset, query, written, cursor, problem,
                     [&](const kdm::QueryParams& q, kdm::QueryCursor*, kdm::QueryProblem* why) {
                       return parallel->parallel.run(*tileset->set, q, kdm::CompactPoints{xy, keys}, capacity,
                                                     written, r, needed, why);
                     });
  });
}

kdm_status kdm_parallel_query_classes_compact(kdm_parallel_query* parallel, const kdm_task_runner* runner,
                                              const kdm_tileset* tileset, const kdm_query* query,
                                              const kdm_class_density* classes, uint32_t class_count,
                                              float* xy, uint64_t* keys, uint8_t* out_classes,
                                              size_t capacity, size_t* written, size_t* needed,
                                              kdm_query_problem* problem) {
  return parallel_classes(parallel, runner, tileset, query, ClassSource{ClassSource::kClasses, classes},
                          class_count, xy, keys, out_classes, capacity, written, needed, problem);
}

kdm_status kdm_parallel_query_classes_joint_compact(kdm_parallel_query* parallel,
                                                    const kdm_task_runner* runner, const kdm_tileset* tileset,
                                                    const kdm_query* query,
                                                    const kdm_joint_class_density* joint,
                                                    uint32_t class_count, float* xy, uint64_t* keys,
                                                    uint8_t* out_classes, size_t capacity, size_t* written,
                                                    size_t* needed, kdm_query_problem* problem) {
  return parallel_classes(parallel, runner, tileset, query, ClassSource{ClassSource::kJoint, nullptr, joint},
                          class_count, xy, keys, out_classes, capacity, written, needed, problem);
}

kdm_status kdm_parallel_query_class_images_compact(kdm_parallel_query* parallel,
                                                   const kdm_task_runner* runner, const kdm_tileset* tileset,
                                                   const kdm_query* query, const kdm_class_images* images,
                                                   float* xy, uint64_t* keys, uint8_t* out_classes,
                                                   size_t capacity, size_t* written, size_t* needed,
                                                   kdm_query_problem* problem) {
  return parallel_classes(
      parallel, runner, tileset, query, ClassSource{ClassSource::kImages, nullptr, nullptr, images},
      images ? images->sums.count() : 0, xy, keys, out_classes, capacity, written, needed, problem);
}

kdm_status kdm_class_images_create(const kdm_density_image* const* images, uint32_t count,
                                   kdm_class_images** out) {
  return kdm_class_images_create_detail(images, count, out, nullptr, 0);
}

kdm_status kdm_class_images_create_detail(const kdm_density_image* const* images, uint32_t count,
                                          kdm_class_images** out, char* detail, size_t detail_size) {
  char why[512] = "";  // room for any two grids' numbers; cut to the caller's buffer below
  const auto refuse = [&](kdm_status s) {  // the reason in the caller's buffer, cut to fit; nothing throws
    if (detail && detail_size) {
      const std::size_t n = std::min(std::strlen(why), detail_size - 1);
      std::memcpy(detail, why, n);
      detail[n] = '\0';
    }
    return s;
  };
  if (!out) return std::snprintf(why, sizeof why, "out is NULL"), refuse(KDM_INVALID_ARGUMENT);
  *out = nullptr;
  if (!images) return std::snprintf(why, sizeof why, "images is NULL"), refuse(KDM_INVALID_ARGUMENT);
  if (count < 1 || count > kdm::kMaxQueryClasses)
    return std::snprintf(why, sizeof why, "count is %u, not 1 to %u", unsigned(count),
                         unsigned(kdm::kMaxQueryClasses)),
           refuse(KDM_INVALID_ARGUMENT);
  const kdm::DensityImageView* views[kdm::kMaxQueryClasses];
  for (uint32_t k = 0; k < count; ++k) {
    if (!images[k])
      return std::snprintf(why, sizeof why, "images[%u] is NULL", unsigned(k)), refuse(KDM_INVALID_ARGUMENT);
    views[k] = &images[k]->view;
    const kdm::DensityImageView &a = *views[0], &b = *views[k];
    if (b.width != a.width || b.height != a.height || b.x0 != a.x0 || b.y0 != a.y0 || b.x1 != a.x1 ||
        b.y1 != a.y1)
      return std::snprintf(
                 why, sizeof why,
                 "images[%u] is %d x %d texels over (%g, %g)-(%g, %g), not images[0]'s %d x %d over "
                 "(%g, %g)-(%g, %g)",
                 unsigned(k), b.width, b.height, b.x0, b.y0, b.x1, b.y1, a.width, a.height, a.x0, a.y0, a.x1,
                 a.y1),
             refuse(KDM_INVALID_ARGUMENT);
  }
  auto* handle = new (std::nothrow) kdm_class_images;
  if (!handle) return KDM_OUT_OF_MEMORY;
  const char* problem = nullptr;
  const kdm_status s = hand_over(
      handle, unless_out_of_memory([&] { return handle->sums.build(views, count, &problem); }), out);
  if (s == KDM_INVALID_ARGUMENT && problem) std::snprintf(why, sizeof why, "%s", problem);
  return s == KDM_INVALID_ARGUMENT ? refuse(s) : s;
}

void kdm_class_images_free(kdm_class_images* images) {
  delete images;
}

void kdm_set_tileset_allocator(void* (*allocate)(size_t, size_t, void*),
                               void (*deallocate)(void*, size_t, size_t, void*), void* user) {
  kdm::set_tileset_allocator(kdm::AllocatorHooks{allocate, deallocate, user});
}

const char* kdm_version(void) {
  return kdm::version_string();
}

uint32_t kdm_version_number(void) {
  return kdm::version_number();
}

uint32_t kdm_tileset_format_version(void) {
  return kdm::kTilesetFormatVersion;
}

kdm_status kdm_tileset_load_file(const char* path, kdm_tileset** out) {
  if (out) *out = nullptr;
  if (!path) return KDM_INVALID_ARGUMENT;
  return load_into(out, [&](kdm::Tileset& t) { return kdm::Tileset::load_file(path, t); });
}

/* A load's status, with `line` (else the status's message) in `detail` on failure and "" on success; *out
 * is NULL on failure. No copy of the line: nothing here may throw. */
static kdm_status with_detail(kdm_status s, const char* line, kdm_tileset** out, char* detail,
                              size_t detail_size) {
  if (s != KDM_OK && out) *out = nullptr;
  if (!detail || !detail_size) return s;
  if (s == KDM_OK || !*line) line = s == KDM_OK ? "" : kdm_status_message(s);
  const std::size_t n = std::min(std::strlen(line), detail_size - 1);
  std::memcpy(detail, line, n);
  detail[n] = '\0';
  return s;
}

kdm_status kdm_tileset_load_memory(const void* data, size_t size, kdm_tileset** out) {
  if (out) *out = nullptr;
  if (!data && size) return KDM_INVALID_ARGUMENT;
  return load_into(out, [&](kdm::Tileset& t) { return kdm::Tileset::load_memory(data, size, t); });
}

kdm_status kdm_tileset_load_file_detail(const char* path, kdm_tileset** out, char* detail,
                                        size_t detail_size) {
  std::string why;
  const kdm_status s =
      !path ? KDM_INVALID_ARGUMENT
            : load_into(out, [&](kdm::Tileset& t) { return kdm::Tileset::load_file(path, t, &why); });
  return with_detail(s,
                     !path  ? "path is NULL"
                     : !out ? "out is NULL"
                            : why.c_str(),
                     out, detail, detail_size);
}

kdm_status kdm_tileset_load_memory_detail(const void* data, size_t size, kdm_tileset** out, char* detail,
                                          size_t detail_size) {
  std::string why;
  const bool missing = !data && size;
  const kdm_status s = missing ? KDM_INVALID_ARGUMENT : load_into(out, [&](kdm::Tileset& t) {
    return kdm::Tileset::load_memory(data, size, t, &why);
  });
  return with_detail(s,
                     missing ? "data is NULL with size > 0"
                     : !out  ? "out is NULL"
                             : why.c_str(),
                     out, detail, detail_size);
}

void kdm_tileset_free(kdm_tileset* tileset) {
  if (tileset != &kdm::detail::builtin_handle()) delete tileset;
}

size_t kdm_tileset_resident_bytes(const kdm_tileset* tileset) {
  return tileset ? tileset->set->resident_bytes() : 0;
}

kdm_status kdm_point_threshold(const kdm_tileset* tileset, const kdm_point* point, double* threshold) {
  if (!tileset || !point || !threshold) return KDM_INVALID_ARGUMENT;
  const double t = kdm::emission_threshold(
      *tileset->set, kdm::PointId{point->tile_x, point->tile_y, point->rank, point->depth});
  if (t < 0) return KDM_INVALID_ARGUMENT;
  *threshold = t;
  return KDM_OK;
}

kdm_status kdm_point_stable_position(const kdm_tileset* tileset, const kdm_point* point, double tile_size,
                                     double origin_x, double origin_y, double* x, double* y) {
  if (!tileset || !point) return KDM_INVALID_ARGUMENT;
  const kdm::PointId id{point->tile_x, point->tile_y, point->rank, point->depth};
  return kdm::stable_position(*tileset->set, id, tile_size, origin_x, origin_y, x, y) ? KDM_OK
                                                                                      : KDM_INVALID_ARGUMENT;
}

kdm_status kdm_key_threshold(const kdm_tileset* tileset, uint64_t key, int64_t near_tile_x,
                             int64_t near_tile_y, double* threshold) {
  if (!tileset || !threshold) return KDM_INVALID_ARGUMENT;
  const double t = kdm::emission_threshold(
      *tileset->set, kdm::point_id_of_key(*tileset->set, key, near_tile_x, near_tile_y));
  if (t < 0) return KDM_INVALID_ARGUMENT;
  *threshold = t;
  return KDM_OK;
}

kdm_status kdm_tile_size_advise(const kdm_tileset* tileset, double max_density, double scale,
                                double tile_size, kdm_tile_size_advice* advice) {
  if (!tileset || !advice) return KDM_INVALID_ARGUMENT;
  const kdm::TileSizeAdvice a = kdm::tile_size_advice(*tileset->set, max_density, scale, tile_size);
  *advice =
      kdm_tile_size_advice{static_cast<int>(a.kind), a.points_per_tile, a.coarsest, a.tile_size, a.tiles};
  return KDM_OK;
}

kdm_status kdm_tileset_get_info(const kdm_tileset* tileset, kdm_tileset_info* info) {
  kdm_tileset_info v;
  if (!tileset || !read_grown(info, kInfoV1, v)) return KDM_INVALID_ARGUMENT;
  const kdm::TilesetData& d = tileset->set->data();
  v.format_version = kdm::tileset_format_version_for(d);
  v.colours = d.colours;
  v.tiles = static_cast<uint32_t>(d.tiles.size());
  v.levels = d.levels;
  v.max_points_per_tile = tileset->set->max_points_per_tile();
  for (std::size_t k = 0; k < d.level_nominal.size() && k < 16; ++k) v.level_points[k] = d.level_nominal[k];
  v.resident_bytes = tileset->set->resident_bytes();
  v.generator_version = d.generator_version.c_str();
  v.recipe = d.recipe.c_str();
  v.keyframes = static_cast<uint32_t>(d.keyframe_nominal.size());
  v.subtiles_per_side = d.handover_zone ? d.subtiles_per_side() : 0;
  v.handover_level = d.handover_level;
  v.handover_slack = d.handover_slack;
  v.smooth_limit_per_tile = kdm::query_density_limit(*tileset->set, kdm::QueryMode::kSmooth);
  write_grown(v, info);
  return KDM_OK;
}

kdm_status kdm_density_image_create(int width, int height, const float* values, double x0, double y0,
                                    double x1, double y1, kdm_density_image** out) {
  return kdm_density_image_create_detail(width, height, values, x0, y0, x1, y1, out, nullptr, 0);
}

kdm_status kdm_density_image_create_detail(int width, int height, const float* values, double x0, double y0,
                                           double x1, double y1, kdm_density_image** out, char* detail,
                                           size_t detail_size) {
  // The reason in a fixed buffer, first fault first: nothing here may throw.
  char why[256] = "";
  const auto refuse = [&](kdm_status s) {
    if (detail && detail_size) {
      const std::size_t n = std::min(std::strlen(why), detail_size - 1);
      std::memcpy(detail, why, n);
      detail[n] = '\0';
    }
    return s;
  };
  if (out) *out = nullptr;
  if (!out) return std::snprintf(why, sizeof why, "out is NULL"), refuse(KDM_INVALID_ARGUMENT);
  if (width <= 0 || height <= 0 || width > kdm::kMaxDensityImageSide || height > kdm::kMaxDensityImageSide)
    return std::snprintf(why, sizeof why, "the image is %d x %d texels: each side must be 1 to 2^30", width,
                         height),
           refuse(KDM_INVALID_ARGUMENT);  // before copying the texels
  if (!values) return std::snprintf(why, sizeof why, "values is NULL"), refuse(KDM_INVALID_ARGUMENT);
  kdm::DensityImageView probe;
  probe.width = width, probe.height = height, probe.x0 = x0, probe.y0 = y0, probe.x1 = x1, probe.y1 = y1;
  if (!kdm::detail::image_rect_usable(probe))
    return std::snprintf(why, sizeof why,
                         "the rectangle (%g, %g, %g, %g) must be finite with x0 < x1 and y0 < y1, and wide "
                         "enough that its texels per unit are finite",
                         x0, y0, x1, y1),
           refuse(KDM_INVALID_ARGUMENT);
  const std::size_t texels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  auto* image = new (std::nothrow) kdm_density_image;
  if (!image) return std::snprintf(why, sizeof why, "out of memory"), refuse(KDM_OUT_OF_MEMORY);
  image->values.reset(static_cast<float*>(std::malloc(texels * sizeof(float))));  // ≤ 2^62 · 4 bytes
  if (!image->values) {  // before a texel is read: the caller's array may be smaller than it says
    delete image;
    return std::snprintf(why, sizeof why, "out of memory for %zu texels", texels), refuse(KDM_OUT_OF_MEMORY);
  }
  for (std::size_t i = 0; i < texels; ++i) {
    if (!(values[i] >= 0 && std::isfinite(values[i]))) {
      std::snprintf(why, sizeof why,
                    "values[%zu] (column %zu, row %zu) is %g: values must be finite and >= 0", i,
                    i % std::size_t(width), i / std::size_t(width), double(values[i]));
      delete image;
      return refuse(KDM_INVALID_ARGUMENT);
    }
    image->values.get()[i] = values[i];
  }
  kdm::DensityImageView& v = image->view;
  v.width = width, v.height = height, v.x0 = x0, v.y0 = y0, v.x1 = x1, v.y1 = y1;
  v.values = image->values.get();
  const kdm_status s =
      hand_over(image, unless_out_of_memory([&] { return kdm::make_density_max_mip(v, image->mip); }), out);
  if (s != KDM_OK) std::snprintf(why, sizeof why, "%s", kdm_status_message(s));
  return refuse(s);
}

void kdm_density_image_free(kdm_density_image* image) {
  delete image;
}

double kdm_density_image_at(const kdm_density_image* image, double x, double y) {
  return image && std::isfinite(x) && std::isfinite(y) ? image->view.at(x, y) : 0.0;
}

kdm_status kdm_query_points(const kdm_tileset* tileset, const kdm_query* query, kdm_point* out,
                            size_t capacity, size_t* written, kdm_cursor* cursor,
                            kdm_query_problem* problem) {
  return run_query(tileset, query, written, cursor, problem,
                   [&](const kdm::QueryParams& q, kdm::QueryCursor* k, kdm::QueryProblem* why) {
                     return kdm::query_points(*tileset->set, q, as_points(out), capacity, written, k, why);
                   });
}

kdm_status kdm_count_points(const kdm_tileset* tileset, const kdm_query* query, size_t* count,
                            kdm_cursor* cursor, kdm_query_problem* problem) {
  return run_query(tileset, query, count, cursor, problem,
                   [&](const kdm::QueryParams& q, kdm::QueryCursor* k, kdm::QueryProblem* why) {
                     return kdm::count_points(*tileset->set, q, count, k, why);
                   });
}

kdm_status kdm_query_compact(const kdm_tileset* tileset, const kdm_query* query, float* xy, uint64_t* keys,
                             size_t capacity, size_t* written, kdm_cursor* cursor,
                             kdm_query_problem* problem) {
  return run_query(tileset, query, written, cursor, problem,
                   [&](const kdm::QueryParams& q, kdm::QueryCursor* k, kdm::QueryProblem* why) {
                     return kdm::query_points_compact(*tileset->set, q, kdm::CompactPoints{xy, keys},
                                                      capacity, written, k, why);
                   });
}

kdm_status kdm_query_classes(const kdm_tileset* tileset, const kdm_query* query,
                             const kdm_class_density* classes, uint32_t class_count, kdm_point* out,
                             uint8_t* out_classes, size_t capacity, size_t* written, kdm_cursor* cursor,
                             kdm_query_problem* problem) {
  return class_records(tileset, query, ClassSource{ClassSource::kClasses, classes}, class_count, out,
                       out_classes, capacity, written, cursor, problem);
}

kdm_status kdm_query_classes_compact(const kdm_tileset* tileset, const kdm_query* query,
                                     const kdm_class_density* classes, uint32_t class_count, float* xy,
                                     uint64_t* keys, uint8_t* out_classes, size_t capacity, size_t* written,
                                     kdm_cursor* cursor, kdm_query_problem* problem) {
  return class_compact(tileset, query, ClassSource{ClassSource::kClasses, classes}, class_count, xy, keys,
                       out_classes, capacity, written, cursor, problem);
}

kdm_status kdm_query_classes_joint(const kdm_tileset* tileset, const kdm_query* query,
                                   const kdm_joint_class_density* joint, uint32_t class_count, kdm_point* out,
                                   uint8_t* out_classes, size_t capacity, size_t* written, kdm_cursor* cursor,
                                   kdm_query_problem* problem) {
  return class_records(tileset, query, ClassSource{ClassSource::kJoint, nullptr, joint}, class_count, out,
                       out_classes, capacity, written, cursor, problem);
}

kdm_status kdm_query_classes_joint_compact(const kdm_tileset* tileset, const kdm_query* query,
                                           const kdm_joint_class_density* joint, uint32_t class_count,
                                           float* xy, uint64_t* keys, uint8_t* out_classes, size_t capacity,
                                           size_t* written, kdm_cursor* cursor, kdm_query_problem* problem) {
  return class_compact(tileset, query, ClassSource{ClassSource::kJoint, nullptr, joint}, class_count, xy,
                       keys, out_classes, capacity, written, cursor, problem);
}

kdm_status kdm_query_class_images(const kdm_tileset* tileset, const kdm_query* query,
                                  const kdm_class_images* images, kdm_point* out, uint8_t* out_classes,
                                  size_t capacity, size_t* written, kdm_cursor* cursor,
                                  kdm_query_problem* problem) {
  return class_records(tileset, query, ClassSource{ClassSource::kImages, nullptr, nullptr, images},
                       images ? images->sums.count() : 0, out, out_classes, capacity, written, cursor,
                       problem);
}

kdm_status kdm_query_class_images_compact(const kdm_tileset* tileset, const kdm_query* query,
                                          const kdm_class_images* images, float* xy, uint64_t* keys,
                                          uint8_t* out_classes, size_t capacity, size_t* written,
                                          kdm_cursor* cursor, kdm_query_problem* problem) {
  return class_compact(tileset, query, ClassSource{ClassSource::kImages, nullptr, nullptr, images},
                       images ? images->sums.count() : 0, xy, keys, out_classes, capacity, written, cursor,
                       problem);
}

kdm_status kdm_density_check_create(kdm_density_check** out) {
  if (!out) return KDM_INVALID_ARGUMENT;
  *out = new (std::nothrow) kdm_density_check;
  return *out ? KDM_OK : KDM_OUT_OF_MEMORY;
}

void kdm_density_check_free(kdm_density_check* check) {
  delete check;
}

kdm_status kdm_density_check_wrap_query(kdm_density_check* check, kdm_query* query) {
  if (!check || !query || query->struct_size < kQueryV1) return KDM_INVALID_ARGUMENT;
  const bool bounds =
      query->struct_size >= offsetof(kdm_query, density_bounds) + sizeof query->density_bounds;
  const bool batch = query->struct_size >=
                     offsetof(kdm_query, density_batch_callback) + sizeof query->density_batch_callback;
  kdm::QueryDensity d = to_density(query->density, query->density_callback, query->user, query->density_max,
                                   query->density_image);
  if (batch)
    with_batch_callback(d, query->density_batch_callback, query->user, query->density_max,
                        query->density_image);
  if (d.kind != kdm::QueryDensity::Kind::kCallback) return KDM_OK;
  if (bounds) d.bounds = query->density_bounds;
  const kdm::Status status = check->check.wrap(&d);
  query->density_callback = d.callback, query->user = d.user;
  if (bounds) query->density_bounds = d.bounds;
  if (batch) query->density_batch_callback = d.batch_callback;
  return to_c(status);
}

kdm_status kdm_density_check_wrap_class(kdm_density_check* check, kdm_class_density* density) {
  if (!check || !density) return KDM_INVALID_ARGUMENT;
  kdm::QueryDensity d = to_density(density->density, density->density_callback, density->user,
                                   density->density_max, density->density_image);
  with_batch_callback(d, density->density_batch_callback, density->user, density->density_max,
                      density->density_image);
  if (d.kind != kdm::QueryDensity::Kind::kCallback) return KDM_OK;
  d.bounds = density->density_bounds;
  const kdm::Status status = check->check.wrap(&d);
  density->density_callback = d.callback, density->user = d.user;
  density->density_bounds = d.bounds, density->density_batch_callback = d.batch_callback;
  return to_c(status);
}

kdm_status kdm_density_check_wrap_joint(kdm_density_check* check, kdm_joint_class_density* joint,
                                        uint32_t class_count) {
  if (!check || !joint) return KDM_INVALID_ARGUMENT;
  kdm::JointClassDensity j;
  j.densities = joint->densities, j.bounds = joint->density_bounds, j.user = joint->user;
  j.batch_densities = joint->batch_densities;
  std::copy(joint->density_max, joint->density_max + KDM_MAX_CLASSES, j.max);
  const kdm::Status status = check->check.wrap(&j, class_count);
  joint->densities = j.densities, joint->density_bounds = j.bounds, joint->user = j.user;
  joint->batch_densities = j.batch_densities;
  return to_c(status);
}

int kdm_density_check_failed(const kdm_density_check* check, double* value, double* x, double* y) {
  kdm::DensityFinding f;
  if (!check || !check->check.failed(&f)) return 0;
  if (value) *value = f.value;
  if (x) *x = f.x;
  if (y) *y = f.y;
  return 1;
}

double kdm_density_check_largest(const kdm_density_check* check) {
  return check ? check->check.largest() : -1;
}

size_t kdm_density_check_describe(const kdm_density_check* check, char* text, size_t size) {
  if (check) return check->check.describe(text, size);
  const char line[] = "no density check ('check' is NULL)";
  if (size) std::snprintf(text, size, "%s", line);
  return sizeof line - 1;
}

void kdm_density_check_reset(kdm_density_check* check) {
  if (check) check->check.reset();
}

const char* kdm_status_message(kdm_status status) {
  return kdm::status_message(static_cast<kdm::Status>(enum_as_int(status)));
}

const char* kdm_problem_message(kdm_problem_kind kind) {
  return kdm::query_problem_message(static_cast<kdm::QueryProblem::Kind>(enum_as_int(kind)));
}

size_t kdm_query_problem_describe(const kdm_query_problem* problem, char* text, size_t size) {
  kdm::QueryProblem p;
  if (!problem) {
    p.kind = kdm::QueryProblem::Kind::kMissingArgument, p.parameter = "problem";
  } else if (problem->struct_size < kProblemV1) {  // as a short query.struct_size is told
    p.kind = kdm::QueryProblem::Kind::kNotPositive, p.parameter = "problem.struct_size";
    p.value = static_cast<double>(problem->struct_size), p.limit = static_cast<double>(kProblemV1);
  } else {
    p.kind = static_cast<kdm::QueryProblem::Kind>(enum_as_int(problem->kind));
    p.parameter = problem->parameter ? problem->parameter : "";
    p.value = problem->value, p.limit = problem->limit;
    p.largest_valid = problem->largest_valid, p.largest_tile_size = problem->largest_tile_size;
  }
  return kdm::describe_query_problem(
      p, text, size, kdm::QueryParameterNames{"scale", "tile_size", "origin (origin_x, origin_y)"});
}

}  // extern "C"
