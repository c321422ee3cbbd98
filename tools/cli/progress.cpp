#include "progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace kdm::cli {

ProgressBar::ProgressBar(std::string label)
    : label_(std::move(label)),
      enabled_(isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()) {}

ProgressBar::~ProgressBar() {
  finish();
}

void ProgressBar::update(double fraction) {
  if (!enabled_) return;
  fraction = std::clamp(fraction, 0.0, 1.0);
  const int permille = static_cast<int>(fraction * 1000);
  if (permille == last_permille_) return;
  last_permille_ = permille;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double eta = fraction > 0.01 ? elapsed * (1 - fraction) / fraction : 0;
  const int width = 30, filled = static_cast<int>(fraction * width);
  std::fprintf(stderr, "\r%s [%.*s%*s] %5.1f%%  ETA %4.0fs ", label_.c_str(), filled,
               "##############################", width - filled, "", fraction * 100, eta);
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (enabled_ && last_permille_ >= 0)
    std::fprintf(stderr, "\r%*s\r", 70 + static_cast<int>(label_.size()), "");
  last_permille_ = -1;
}

}  // namespace kdm::cli
