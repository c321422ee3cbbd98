// KDM_CHECK (kdm/runtime/check.h): a failed internal check names its condition and place, then aborts;
// a passing one has no effect. Checks are switched on here as the sanitizer builds switch them on.
#define KDM_ENABLE_CHECKS 1
#include "kdm/runtime/check.h"

#include <gtest/gtest.h>

namespace {

TEST(CheckTest, AFailedCheckNamesItsConditionAndAborts) {
  const int left = 0;
  EXPECT_DEATH(KDM_CHECK(left > 0), "kdm: internal check failed: left > 0 \\(.*check_test.cpp:[0-9]+\\)");
}

TEST(CheckTest, APassingCheckEvaluatesItsConditionOnce) {
  int evaluated = 0;
  KDM_CHECK(++evaluated == 1);
  EXPECT_EQ(evaluated, 1);
}

}  // namespace
