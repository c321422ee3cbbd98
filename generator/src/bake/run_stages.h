// The bake's schedule of sampler runs, shared by its pyramid levels and its keyframes.
//
// Thread safety: for_each_run calls `sample` from up to `threads` threads at once (for runs of one stage,
// which read only what earlier stages wrote) and `keep` from the calling thread, in run order.
#pragma once

#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

#include "bake/corner_layout.h"
#include "kdm/generator/sampler.h"
#include "platform/thread_count.h"

namespace kdm::gen {

/// Runs sample(r, threads_for_it) for every run r, the runs of one stage concurrently in batches of up to
/// `threads` (0 = default_thread_count()) with one thread each, and keep(r, result) after each batch in run
/// order, so the result is the same for any thread count. A lone run gets all `threads`.
template <class Sample, class Keep>
void for_each_run(const std::vector<BakeRun>& runs, int threads, Sample&& sample, Keep&& keep) {
  using Result = decltype(sample(std::size_t{}, int{}));
  const int workers = thread_count(threads);
  for (std::size_t first = 0; first < runs.size();) {
    std::size_t last = first;
    while (last < runs.size() && runs[last].stage == runs[first].stage &&
           last - first < static_cast<std::size_t>(workers))
      ++last;
    std::vector<Result> batch(last - first);
    if (batch.size() == 1) {
      batch[0] = sample(first, threads);
    } else {
      std::vector<std::exception_ptr> errors(batch.size());
      std::vector<std::thread> pool;
      for (std::size_t i = 0; i < batch.size(); ++i)
        pool.emplace_back([&, i] {
          try {
            batch[i] = sample(first + i, 1);
          } catch (...) {
            errors[i] = std::current_exception();
          }
        });
      for (std::thread& t : pool) t.join();
      for (const std::exception_ptr& e : errors)
        if (e) std::rethrow_exception(e);
    }
    for (std::size_t i = 0; i < batch.size(); ++i) keep(first + i, batch[i]);
    first = last;
  }
}

}  // namespace kdm::gen
