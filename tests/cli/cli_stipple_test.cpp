// kdm stipple end to end: its pictures' geometry, the images it reads (standard input, Radiance, NumPy)
// and what it says of its options and tile sets.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "cli_fixture.h"

namespace {

using namespace kdm_cli_test;

const std::string kSphere = "'" + std::string(KDM_SOURCE_DIR) + "/examples/sphere.png'";

// A dot size that is no number is refused as one, not as a negative number.
TEST_F(CliTest, StippleDotSizeMustBeAFiniteNumber) {
  for (const char* size : {"inf", "nan", "-1"}) {
    SCOPED_TRACE(size);
    expect_error("stipple " + kSphere + " --dot-size " + size + " -o '" + path("s.png") + "'",
                 "--dot-size must be a finite number >= 0");
    expect_error("sample -n 10 --dot-size " + std::string(size) + " -o '" + path("s.png") + "'",
                 "--dot-size must be a finite number >= 0");
  }
}

}  // namespace
