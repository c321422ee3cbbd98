// Progress on stderr: a bar with ETA redrawn in place on a terminal; elsewhere (a build log, a pipe) a line
// every half minute, so a long bake shows it is alive and a short one prints nothing.
#pragma once

#include <chrono>
#include <cstdio>
#include <string>

namespace kdm::cli {

class ProgressBar {
 public:
  /// `out` is stderr but for tests; a log line at most every `line_every_seconds` where it is no terminal.
  explicit ProgressBar(std::string label, std::FILE* out = stderr, double line_every_seconds = 30);
  ~ProgressBar();
  /// fraction in [0, 1]. Cheap when nothing needs redrawing. Call from one thread.
  void update(double fraction);
  void finish();

 private:
  std::string label_;
  std::FILE* out_;
  double line_every_seconds_;
  bool terminal_;
  int last_permille_ = -1;
  double last_line_seconds_ = 0;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace kdm::cli
