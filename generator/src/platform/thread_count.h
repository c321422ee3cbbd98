// How many threads "0 = the default" means, in every kdm library and command: the first number in
// OMP_NUM_THREADS if set, else the CPUs of the process's affinity mask, capped by its cgroup CPU quota.
#pragma once

namespace kdm::gen {

/// The default thread count (at least 1), read once per process. Also declared in kdm/generator/sampler.h.
int default_thread_count();

/// The threads to use when a caller requests `requested` (0 or less: default_thread_count()).
inline int thread_count(int requested) {
  return requested > 0 ? requested : default_thread_count();
}

}  // namespace kdm::gen
