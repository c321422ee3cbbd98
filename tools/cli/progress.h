// A progress bar with ETA on stderr, drawn only when stderr is a terminal.
#pragma once

#include <chrono>
#include <string>

namespace kdm::cli {

class ProgressBar {
 public:
  explicit ProgressBar(std::string label);
  ~ProgressBar();
  /// fraction in [0, 1]. Cheap when nothing needs redrawing. Call from one thread.
  void update(double fraction);
  void finish();

 private:
  std::string label_;
  bool enabled_;
  int last_permille_ = -1;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace kdm::cli
