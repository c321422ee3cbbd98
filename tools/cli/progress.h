// Progress on stderr: a bar with ETA redrawn in place on a terminal; elsewhere (a build log, a pipe) a line
// every half minute, whether or not the figure moved (a step of a bake can take minutes), so a long run
// shows it is alive and a short one prints nothing.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <string>
#include <thread>

namespace kdm::cli {

class ProgressBar {
 public:
  /// `out` is stderr but for tests; a log line every `line_every_seconds` where it is no terminal (from a
  /// thread of its own when that is 1 s or more, so that a line comes even while no update does).
  explicit ProgressBar(std::string label, std::FILE* out = stderr, double line_every_seconds = 30);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;
  /// fraction in [0, 1]. Cheap when nothing needs redrawing. Call from one thread.
  void update(double fraction);
  /// Clears the bar and stops the log's lines; the command's own last line follows.
  void finish();

 private:
  void log_line(double elapsed);  // with mutex_ held
  double elapsed() const;

  std::string label_;
  std::FILE* out_;
  double line_every_seconds_;
  bool terminal_;
  int last_permille_ = -1;
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;  // what follows, shared with the heartbeat
  double fraction_ = 0;
  double last_line_seconds_ = 0;
  bool finished_ = false;
  std::condition_variable finishing_;
  std::thread heartbeat_;
};

}  // namespace kdm::cli
