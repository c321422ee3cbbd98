// Internal: a blocking parallel loop over [0, count) on `threads` workers, started for the call. Each index
// is handled exactly once; the body must only write data owned by its index (or by its worker slot `w`,
// 0 <= w < workers) so results never depend on the thread count. Threads of the call's own, not a pool
// kept between calls: a pool's threads do not survive fork(), so a forked child (Python's multiprocessing)
// would wait on them forever.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

#include "kdm/generator/sampler.h"

namespace kdm::analysis::detail {

/// Number of worker slots parallel_for will use for `threads` (0 = gen::default_thread_count(), as in
/// every kdm library) and `count` items.
inline int worker_count(int threads, std::ptrdiff_t count) {
  int t = threads > 0 ? threads : gen::default_thread_count();
  if (count < t) t = static_cast<int>(std::max<std::ptrdiff_t>(1, count));
  return t;
}

/// Calls body(i, w) for every i in [0, count); w is the worker slot. Dynamic scheduling, blocking. If bodies
/// throw (out of memory), the rest still run and the first exception is rethrown here: one must not leave a
/// worker (that ends the process).
template <class Body>
void parallel_for(std::ptrdiff_t count, int threads, Body&& body) {
  const int workers = worker_count(threads, count);
  if (workers <= 1) {
    for (std::ptrdiff_t i = 0; i < count; ++i) body(i, 0);
    return;
  }
  std::mutex error_mutex;
  std::exception_ptr error;
  auto guarded = [&](std::ptrdiff_t i, int w) noexcept {
    try {
      body(i, w);
    } catch (...) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
    }
  };
  std::atomic<std::ptrdiff_t> next{0};
  std::vector<std::thread> pool;
  auto work = [&](int w) {
    for (std::ptrdiff_t i; (i = next.fetch_add(1)) < count;) guarded(i, w);
  };
  try {
    pool.reserve(static_cast<std::size_t>(workers - 1));
    for (int w = 1; w < workers; ++w) pool.emplace_back(work, w);
  } catch (...) {
    // no more threads (or memory for them) to be had: the started ones and this one share the work
  }
  work(0);
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace kdm::analysis::detail
