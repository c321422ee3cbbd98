// The generator's thread team: every part runs once, and an exception in any thread (a worker out of
// memory) reaches the caller after every thread has finished, instead of ending the process.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
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

// Python's multiprocessing forks a process whose team has workers: the child's team starts its own (the
// parent's threads are not there to wait for), runs, and ends without waiting for them either.
TEST(ThreadTeamTest, AForkedChildRunsWithoutItsParentsWorkers) {
  ThreadTeam team;
  std::atomic<int> calls{0};
  int size = 0;
  team.run(3, [&](int, int threads) {
    size = threads;
    ++calls;
  });
  ASSERT_GT(size, 1) << "no worker thread could be started";
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    alarm(30);  // a hang ends the child with SIGALRM, which the parent reports
    std::atomic<int> child_calls{0};
    int child_size = 0;
    team.run(3, [&](int, int threads) {
      child_size = threads;
      ++child_calls;
    });
    team.~ThreadTeam();  // joins the child's workers only
    new (&team) ThreadTeam;
    _exit(child_size > 1 && child_calls.load() == child_size ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << "the child hung or crashed (signal " << WTERMSIG(status) << ")";
  EXPECT_EQ(WEXITSTATUS(status), 0) << "the child's team did not run on workers of its own";
  calls = 0;
  team.run(3, [&](int, int) { ++calls; });  // the parent's team is untouched
  EXPECT_EQ(calls.load(), size);
}

}  // namespace
}  // namespace kdm::gen
