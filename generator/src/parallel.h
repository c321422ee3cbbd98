// The one shape of parallel region the generator uses: a team of OpenMP threads that shares out its work
// by the team's actual size, which may be smaller than asked for (OMP_THREAD_LIMIT, nesting).
#pragma once

#ifdef _OPENMP
#include <omp.h>
#endif

namespace kdm::gen {

/// The threads to ask for when a caller requests `requested` (0 or less: as many as OpenMP would use);
/// 1 without OpenMP.
inline int thread_count(int requested) {
#ifdef _OPENMP
  return requested > 0 ? requested : (omp_get_max_threads() > 0 ? omp_get_max_threads() : 1);
#else
  (void)requested;
  return 1;
#endif
}

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
