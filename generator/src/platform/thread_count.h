// How many threads "0 = the default" means, in every kdm library and command: the first number in
// OMP_NUM_THREADS if set, else the CPUs of the process's affinity mask, capped by its cgroup CPU quota.
#pragma once

#include <string>

#include "kdm/generator/sampler.h"

namespace kdm::gen {

/// The default thread count (at least 1), read once per process. Also declared in kdm/generator/sampler.h.
int default_thread_count();

/// The threads to use when a caller requests `requested` (0: default_thread_count()).
inline int thread_count(int requested) {
  return requested > 0 ? requested : default_thread_count();
}

/// Throws InvalidArgument unless `requested` is 0 or 1 to kMaxThreads.
inline void check_thread_count(int requested) {
  if (requested < 0 || requested > kMaxThreads)
    throw InvalidArgument("threads must be 0 (the default count) or 1 to " + std::to_string(kMaxThreads) +
                          ", got " + std::to_string(requested));
}

}  // namespace kdm::gen
