// The command line's progress report where stderr is no terminal (a build log, a pipe): a line every so
// often, even when the figure has not moved, and nothing for a run shorter than that.
#include "progress.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

namespace {

std::string written(std::FILE* file) {
  std::string text(static_cast<std::size_t>(std::ftell(file)), '\0');
  std::rewind(file);
  text.resize(std::fread(text.data(), 1, text.size(), file));
  return text;
}

TEST(ProgressTest, AFileGetsALinePerIntervalAndAShortRunNone) {
  std::FILE* log = std::tmpfile();
  ASSERT_NE(log, nullptr);
  {
    kdm::cli::ProgressBar every_time("baking", log, 0.0);
    every_time.update(0.25);
    every_time.update(0.25);  // unchanged, but the interval has passed: a line, to show it is alive
    every_time.update(0.5);
    every_time.update(1.0);  // done: the command's own last line follows
  }
  {
    kdm::cli::ProgressBar hourly("sampling", log, 3600.0);
    for (int k = 1; k <= 100; ++k) hourly.update(k / 100.0);
  }
  const std::string text = written(log);
  std::fclose(log);
  EXPECT_EQ(text.find('\r'), std::string::npos) << "a log got a terminal's bar: " << text;
  EXPECT_NE(text.find("baking: 25% after "), std::string::npos) << text;
  EXPECT_NE(text.find(" s left\n"), std::string::npos) << text;
  EXPECT_NE(text.find("baking: 50% after"), std::string::npos) << text;
  EXPECT_EQ(text.find("baking: 100%"), std::string::npos) << text;
  EXPECT_EQ(text.find("sampling"), std::string::npos) << text;
  int lines = 0;
  for (char c : text) lines += c == '\n';
  EXPECT_EQ(lines, 3) << text;
}

// A step that takes minutes calls no update: the log still gets its line each interval.
TEST(ProgressTest, ALogGetsItsLinesWhileNoUpdateComes) {
  std::FILE* log = std::tmpfile();
  ASSERT_NE(log, nullptr);
  {
    kdm::cli::ProgressBar bar("baking", log, 1.0);
    bar.update(0.005);
    std::this_thread::sleep_for(std::chrono::milliseconds(3500));  // three intervals and a half
  }
  const std::string text = written(log);
  std::fclose(log);
  EXPECT_NE(text.find("baking: 0% after "), std::string::npos) << text;
  EXPECT_EQ(text.find("left"), std::string::npos) << "an estimate before 1%: " << text;
}

}  // namespace
