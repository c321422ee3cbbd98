// The generator's worker threads: a team per calling thread, which waits politely.
//
// The sampler synchronises several times per sweep. OpenMP's default wait (libgomp spins for
// milliseconds before it sleeps) makes every wait for a descheduled partner burn a core that the partner
// needs, so on a loaded machine (a parallel build) two threads ran slower than one. Here a waiting thread
// spins only briefly (kSpinMicroseconds: longer than most waits on an idle machine, far shorter than a
// scheduler time slice), then sleeps until it is woken.
//
// Thread safety: each calling thread has its own team (ThreadTeam::for_this_thread), so concurrent
// samplers on different threads never share workers; a team is used by its owner only. A process forked
// from one whose team had workers (Python's multiprocessing) starts new ones: the parent's are not there.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace kdm::gen {

class ThreadTeam {
 public:
  /// How long a waiting thread spins before it sleeps.
  static constexpr int kSpinMicroseconds = 50;

  /// The team owned by the calling thread (made on first use, its workers started as needed and joined
  /// when the calling thread ends).
  static ThreadTeam& for_this_thread();

  ThreadTeam();
  ThreadTeam(const ThreadTeam&) = delete;
  ThreadTeam& operator=(const ThreadTeam&) = delete;
  ~ThreadTeam();

  /// Runs body(thread, threads) for thread = 0 .. threads - 1, thread 0 on the caller, and returns when all
  /// have returned. `threads` <= 1 calls body(0, 1) directly. If a worker cannot be started, the team is
  /// smaller (body sees the actual size). If bodies throw (a worker out of memory), the others still run
  /// to their end, and the first exception caught is rethrown here once all have returned.
  void run(int threads, const std::function<void(int, int)>& body);

 private:
  void work(int index, std::uint64_t seen);
  void call(int index, int team) noexcept;
  void publish(std::uint64_t team);
  void notify(std::condition_variable& cv);
  void forget_forked_workers();  // in a forked child, the parent's workers

  std::vector<std::thread> workers_;
  unsigned forks_seen_ = 0;  // the process's fork count when workers_ were started
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  // The current job: a generation count (bumped once per run) above the team size in the low 16 bits, in
  // one word so that a worker never pairs one run's generation with another run's size. Size 0: stop.
  std::atomic<std::uint64_t> job_{0};
  std::atomic<int> running_{0};   // workers still in the current body
  std::atomic<int> sleepers_{0};  // threads asleep, or about to be, on wake_ or done_
  const std::function<void(int, int)>* body_ = nullptr;
  std::mutex error_mutex_;
  std::exception_ptr error_;  // the first exception a body threw in the current run
};

}  // namespace kdm::gen
