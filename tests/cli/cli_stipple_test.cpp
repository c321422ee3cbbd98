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

// Header numbers are the shortest that read back: a 4:5 picture's aspect is 0.8, not 0.80000000000000004.
TEST_F(CliTest, StippleHeadersPrintTheShortestNumbers) {
  write_bytes(path("portrait.png"), grey_png(40, 50, 8, std::vector<std::uint16_t>(40 * 50, 100)));
  const std::string image = " '" + path("portrait.png") + "' --points 500";
  for (const std::string format : {"txt", "svg"}) {
    const Outcome run = kdm("stipple" + image + " -o '" + path("s." + format) + "'");
    ASSERT_EQ(run.status, 0) << run.err;
    const std::string text = slurp(path("s." + format));
    EXPECT_NE(text.find(format == "txt" ? "# domain box, aspect 0.8\n" : "<!-- domain box, aspect 0.8 -->"),
              std::string::npos)
        << text.substr(0, 400);
  }
  const Outcome zoom = kdm("stipple" + image + " --region 0.1,0.3,0.7,0.9 -o '" + path("z.txt") + "'");
  ASSERT_EQ(zoom.status, 0) << zoom.err;
  EXPECT_NE(slurp(path("z.txt")).find("# region 0.1,0.3,0.7,0.9\n"), std::string::npos);
}

}  // namespace
