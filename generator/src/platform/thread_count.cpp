// The default thread count (platform/thread_count.h).
#include "platform/thread_count.h"

#include <sched.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>

#include "kdm/generator/sampler.h"

namespace kdm::gen {
namespace {

/// The CPU quota of this process's cgroup in CPUs (rounded up), or 0 if it has none or none can be read.
int cgroup_cpu_quota() {
  double quota = 0, period = 0;
  std::ifstream v2("/sys/fs/cgroup/cpu.max");  // cgroup v2: "max 100000" or "200000 100000"
  std::string first;
  if (v2 >> first >> period) {
    if (first == "max" || !(period > 0)) return 0;
    quota = std::strtod(first.c_str(), nullptr);
  } else {
    std::ifstream q("/sys/fs/cgroup/cpu/cpu.cfs_quota_us"), p("/sys/fs/cgroup/cpu/cpu.cfs_period_us");
    if (!(q >> quota && p >> period) || quota <= 0 || period <= 0) return 0;
  }
  return quota > 0 ? std::max(1, static_cast<int>(std::ceil(quota / period))) : 0;
}

}  // namespace

int default_thread_count() {
  static const int count = [] {
    if (const char* env = std::getenv("OMP_NUM_THREADS")) {
      const long n = std::strtol(env, nullptr, 10);  // "4" or a nesting list "4,2": the first level
      if (n > 0) return static_cast<int>(std::min(n, long(kMaxThreads)));  // as --threads is capped
    }
    int cpus = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    cpu_set_t mask;
    if (sched_getaffinity(0, sizeof mask, &mask) == 0) cpus = std::max(1, CPU_COUNT(&mask));
    const int quota = cgroup_cpu_quota();
    return quota > 0 ? std::min(cpus, quota) : cpus;
  }();
  return count;
}

}  // namespace kdm::gen
