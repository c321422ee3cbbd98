// The generator's thread team: every part runs once, and an exception in any thread (a worker out of
// memory) reaches the caller after every thread has finished, instead of ending the process.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <stdexcept>
#include <vector>

#include "platform/parallel.h"
#include "platform/thread_team.h"

namespace kdm::gen {
namespace {

TEST(ThreadTeamTest, EveryPartRunsOnce) {
  std::vector<std::atomic<int>> runs(37);
  for_each_part(37, true, [&](int part, int) { ++runs[part]; });
  for (const auto& r : runs) EXPECT_EQ(r.load(), 1);
}

TEST(ThreadTeamTest, AWorkersExceptionReachesTheCallerAfterTheOthersFinish) {
  ThreadTeam team;
  std::atomic<int> finished{0};
  int size = 0;
  EXPECT_THROW(team.run(4,
                        [&](int thread, int threads) {
                          size = threads;
                          if (thread == threads - 1) throw std::bad_alloc();
                          ++finished;
                        }),
               std::bad_alloc);
  ASSERT_GT(size, 1) << "no worker thread could be started";
  EXPECT_EQ(finished.load(), size - 1);
  // The team stays usable: the next run sees no stale exception.
  std::atomic<int> calls{0};
  team.run(4, [&](int, int) { ++calls; });
  EXPECT_EQ(calls.load(), size);
}

TEST(ThreadTeamTest, TheCallersOwnExceptionWaitsForTheWorkers) {
  ThreadTeam team;
  std::atomic<int> finished{0};
  EXPECT_THROW(team.run(3,
                        [&](int thread, int) {
                          if (thread == 0) throw std::runtime_error("caller");
                          for (volatile int i = 0; i < 1000000; ++i) {
                          }
                          ++finished;
                        }),
               std::runtime_error);
  // run() returned only after the workers left the body, so none is still counting.
  const int seen = finished.load();
  EXPECT_GE(seen, 1);
  std::atomic<int> calls{0};
  team.run(3, [&](int, int) { ++calls; });
  EXPECT_EQ(finished.load(), seen);
}

/// The exit status of a child forked from here that runs `body` and leaves with its result, or -signal
/// when it does not exit (a hang ends it with SIGALRM).
template <class Body>
int in_forked_child(Body&& body) {
  std::fflush(nullptr);  // the parent's buffered output is not written twice
  const pid_t child = fork();
  if (child < 0) return -1000;
  if (child == 0) {
    alarm(30);
    _exit(body());
  }
  int status = 0;
  if (waitpid(child, &status, 0) != child) return -1001;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
}

/// How many threads `team` runs a body on with 3 asked for, and whether each ran once.
int team_size(ThreadTeam& team, bool* each_once) {
  std::atomic<int> calls{0};
  int size = 0;
  team.run(3, [&](int, int threads) {
    size = threads;
    ++calls;
  });
  *each_once = calls.load() == size;
  return size;
}

// Python's multiprocessing forks a process whose team has workers: the child's team starts its own (the
// parent's threads are not there to wait for), runs, and ends without waiting for them either.
TEST(ThreadTeamTest, AForkedChildRunsWithoutItsParentsWorkers) {
  ThreadTeam team;
  bool once = false;
  const int size = team_size(team, &once);
  ASSERT_GT(size, 1) << "no worker thread could be started";
  auto run_then_end = [&] {
    bool child_once = false;
    const int child_size = team_size(team, &child_once);
    team.~ThreadTeam();  // joins the child's workers only
    new (&team) ThreadTeam;
    return child_size > 1 && child_once ? 0 : 1;
  };
  EXPECT_EQ(in_forked_child(run_then_end), 0) << "the child hung (-14), crashed, or ran on no workers (1)";
  auto only_end = [&] {  // a child that never samples still ends
    team.~ThreadTeam();
    new (&team) ThreadTeam;
    return 0;
  };
  EXPECT_EQ(in_forked_child(only_end), 0) << "ending the team waited for the parent's workers";
  // The calling thread's own team (what the sampler uses), ended by exit() with the thread's objects.
  EXPECT_GT(team_size(ThreadTeam::for_this_thread(), &once), 1);
  auto own_team_then_exit = [] {
    bool child_once = false;
    if (team_size(ThreadTeam::for_this_thread(), &child_once) < 2 || !child_once) return 1;
    std::exit(0);
  };
  EXPECT_EQ(in_forked_child(own_team_then_exit), 0);
  EXPECT_EQ(team_size(team, &once), size);  // the parent's team is untouched
  EXPECT_TRUE(once);
}

}  // namespace
}  // namespace kdm::gen
