// The shapes of parallel work the generator uses, all on the calling thread's ThreadTeam: a team that
// shares out its work by the team's actual size (which may be smaller than asked for).
#pragma once

#include <algorithm>
#include <cstdint>

#include "platform/thread_count.h"
#include "platform/thread_team.h"

namespace kdm::gen {

/// Runs body(thread, team) on each thread of a team of up to `threads` (one thread when `parallel` is
/// false).
template <class Body>
void run_team(int threads, bool parallel, Body&& body) {
  if (!parallel || threads <= 1) return body(0, 1);
  ThreadTeam::for_this_thread().run(threads, body);
}

/// Calls part(p, thread) for every p in 0 .. parts - 1 on a team of up to `parts` threads, thread t taking
/// p = t, t + team, ...
template <class Part>
void for_each_part(int parts, bool parallel, Part&& part) {
  run_team(parts, parallel, [&](int thread, int team) {
    for (int p = thread; p < parts; p += team) part(p, thread);
  });
}

/// Calls each(j) for j in 0 .. count - 1, in contiguous stretches, one per thread of a team of up to
/// `threads` (one thread when `parallel` is false). Only for loops whose iterations are independent.
template <class Each>
void parallel_for(std::int64_t count, int threads, bool parallel, Each&& each) {
  run_team(threads, parallel && count > 1, [&](int thread, int team) {
    const std::int64_t end = count * (thread + 1) / team;
    for (std::int64_t j = count * thread / team; j < end; ++j) each(j);
  });
}

}  // namespace kdm::gen
