// The analysis's parallel loop: every index once, and an exception in a worker (out of memory) reaches
// the caller instead of ending the process.
#include <gtest/gtest.h>

#include <atomic>
#include <new>
#include <vector>

#include "parallel.h"

namespace kdm::analysis::detail {
namespace {

TEST(AnalysisParallelTest, EveryIndexOnceAndExceptionsReachTheCaller) {
  std::vector<std::atomic<int>> runs(100);
  parallel_for(100, 3, [&](std::ptrdiff_t i, int) { ++runs[i]; });
  for (const auto& r : runs) EXPECT_EQ(r.load(), 1);

  std::atomic<int> done{0};
  EXPECT_THROW(parallel_for(100, 3,
                            [&](std::ptrdiff_t i, int) {
                              if (i == 17) throw std::bad_alloc();
                              ++done;
                            }),
               std::bad_alloc);
  EXPECT_EQ(done.load(), 99);  // the other indices still ran
}

}  // namespace
}  // namespace kdm::analysis::detail
