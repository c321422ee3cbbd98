#include "platform/thread_team.h"

#include <pthread.h>

#include <algorithm>
#include <chrono>
#include <new>
#include <system_error>
#include <utility>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace kdm::gen {
namespace {

constexpr std::uint64_t kTeamBits = 16;
constexpr std::uint64_t kTeamMask = (std::uint64_t(1) << kTeamBits) - 1;

inline void cpu_relax() {
#if defined(__x86_64__) || defined(__i386__)
  _mm_pause();
#endif
}

/// Spins until pred() holds or kSpinMicroseconds pass; returns whether it holds.
template <class Pred>
bool spin_until(Pred&& pred) {
  const auto end =
      std::chrono::steady_clock::now() + std::chrono::microseconds(ThreadTeam::kSpinMicroseconds);
  for (unsigned i = 1;; ++i) {
    if (pred()) return true;
    cpu_relax();
    if (i % 64 == 0 && std::chrono::steady_clock::now() >= end) return pred();
  }
}

/// How many times this process's ancestors forked into it (a child's atfork handler counts).
std::atomic<unsigned> forks{0};

}  // namespace

ThreadTeam& ThreadTeam::for_this_thread() {
  thread_local ThreadTeam team;
  return team;
}

ThreadTeam::ThreadTeam() {
  static const bool counting = [] { return pthread_atfork(nullptr, nullptr, [] { ++forks; }) == 0; }();
  static_cast<void>(counting);
  forks_seen_ = forks.load();
}

void ThreadTeam::forget_forked_workers() {
  if (forks_seen_ == forks.load()) return;
  forks_seen_ = forks.load();
  if (workers_.empty()) return;
  // Only the forking thread lives on in a child. Its workers' std::thread objects name threads that do not
  // exist here (joining them would wait forever, destroying them ends the process), so they are leaked; the
  // locks and counters may hold a worker's state at the fork, so they start afresh.
  static std::vector<std::thread>* const lost = new std::vector<std::thread>;  // reachable: no leak reported
  for (std::thread& t : workers_) lost->push_back(std::move(t));
  workers_.clear();
  new (&mutex_) std::mutex;
  new (&error_mutex_) std::mutex;
  new (&wake_) std::condition_variable;
  new (&done_) std::condition_variable;
  running_.store(0);
  sleepers_.store(0);
}

ThreadTeam::~ThreadTeam() {
  forget_forked_workers();
  if (workers_.empty()) return;
  publish(0);
  for (std::thread& t : workers_) t.join();
}

void ThreadTeam::notify(std::condition_variable& cv) {
  // Whoever checked its condition under the lock before our change is asleep by now or sees the change.
  if (sleepers_.load() > 0) {
    { std::lock_guard<std::mutex> lock(mutex_); }
    cv.notify_all();
  }
}

void ThreadTeam::publish(std::uint64_t team) {
  const std::uint64_t generation = (job_.load() >> kTeamBits) + 1;
  job_.store(generation << kTeamBits | team);
  notify(wake_);
}

void ThreadTeam::run(int threads, const std::function<void(int, int)>& body) {
  threads = std::min(threads, static_cast<int>(kTeamMask));
  forget_forked_workers();
  while (static_cast<int>(workers_.size()) < threads - 1) {
    try {
      workers_.emplace_back(&ThreadTeam::work, this, static_cast<int>(workers_.size()) + 1, job_.load());
    } catch (const std::system_error&) {
      break;  // no more threads to be had: a smaller team
    }
  }
  const int team = std::min(threads, static_cast<int>(workers_.size()) + 1);
  if (team <= 1) return body(0, 1);
  body_ = &body;
  error_ = nullptr;
  running_.store(team - 1);
  publish(static_cast<std::uint64_t>(team));
  call(0, team);
  auto finished = [&] { return running_.load() == 0; };
  if (!spin_until(finished)) {
    std::unique_lock<std::mutex> lock(mutex_);
    ++sleepers_;
    done_.wait(lock, finished);
    --sleepers_;
  }
  if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
}

void ThreadTeam::call(int index, int team) noexcept {
  // An exception must not leave a worker's thread (that ends the process) nor the caller before the
  // workers are done with `body`.
  try {
    (*body_)(index, team);
  } catch (...) {
    std::lock_guard<std::mutex> lock(error_mutex_);
    if (!error_) error_ = std::current_exception();
  }
}

void ThreadTeam::work(int index, std::uint64_t seen) {
  for (;;) {
    auto changed = [&] { return job_.load() != seen; };
    if (!spin_until(changed)) {
      std::unique_lock<std::mutex> lock(mutex_);
      ++sleepers_;
      wake_.wait(lock, changed);
      --sleepers_;
    }
    // A worker that was not in a run may miss it for a later one; one that was is always waited for.
    seen = job_.load();
    const int team = static_cast<int>(seen & kTeamMask);
    if (team == 0) return;
    if (index >= team) continue;
    call(index, team);
    if (--running_ == 0) notify(done_);
  }
}

}  // namespace kdm::gen
