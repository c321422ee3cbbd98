// The one shape of parallel region the generator uses: a team of OpenMP threads that shares out its work
// by the team's actual size, which may be smaller than asked for (OMP_THREAD_LIMIT, nesting).
#pragma once

#ifdef _OPENMP
#include <omp.h>
#endif

namespace kdm::gen {

/// Runs body(thread, team) on each thread of a team of up to `threads` (one thread without OpenMP, or when
/// `parallel` is false).
template <class Body>
void run_team(int threads, bool parallel, Body&& body) {
#pragma omp parallel num_threads(threads) if (parallel && threads > 1)
  {
#ifdef _OPENMP
    body(omp_get_thread_num(), omp_get_num_threads());
#else
    body(0, 1);
#endif
  }
}

/// Calls part(p, thread) for every p in 0 .. parts - 1 on a team of up to `parts` threads, thread t taking
/// p = t, t + team, ...
template <class Part>
void for_each_part(int parts, bool parallel, Part&& part) {
  run_team(parts, parallel, [&](int thread, int team) {
    for (int p = thread; p < parts; p += team) part(p, thread);
  });
}

}  // namespace kdm::gen
