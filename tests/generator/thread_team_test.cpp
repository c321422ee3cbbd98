// The generator's thread team: every part runs once, and an exception in any thread (a worker out of
// memory) reaches the caller after every thread has finished, instead of ending the process.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace kdm::gen
