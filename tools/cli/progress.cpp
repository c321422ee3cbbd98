#include "progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <string>

namespace kdm::cli {

namespace {

/// "42 s", "3.5 min": a duration for a log line.
std::string duration_text(double seconds) {
  char text[32];
  if (seconds < 100)
    std::snprintf(text, sizeof text, "%.0f s", seconds);
  else
    std::snprintf(text, sizeof text, "%.1f min", seconds / 60);
  return text;
}

}  // namespace

ProgressBar::ProgressBar(std::string label, std::FILE* out, double line_every_seconds)
    : label_(std::move(label)),
      out_(out),
      line_every_seconds_(line_every_seconds),
      terminal_(isatty(fileno(out)) != 0),
      start_(std::chrono::steady_clock::now()) {}

ProgressBar::~ProgressBar() {
  finish();
}

void ProgressBar::update(double fraction) {
  fraction = std::clamp(fraction, 0.0, 1.0);
  const int permille = static_cast<int>(fraction * 1000);
  if (permille == last_permille_) return;
  last_permille_ = permille;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double eta = fraction > 0.01 ? elapsed * (1 - fraction) / fraction : 0;
  if (!terminal_) {
    if (elapsed - last_line_seconds_ < line_every_seconds_ || fraction >= 1) return;
    last_line_seconds_ = elapsed;
    std::fprintf(out_, "%s: %.0f%% after %s%s\n", label_.c_str(), fraction * 100,
                 duration_text(elapsed).c_str(),
                 fraction > 0.01 ? (", about " + duration_text(eta) + " left").c_str() : "");
    return;
  }
  const int width = 30, filled = static_cast<int>(fraction * width);
  std::fprintf(out_, "\r%s [%.*s%*s] %5.1f%%  ETA %4.0fs ", label_.c_str(), filled,
               "##############################", width - filled, "", fraction * 100, eta);
  std::fflush(out_);
}

void ProgressBar::finish() {
  if (terminal_ && last_permille_ >= 0)
    std::fprintf(out_, "\r%*s\r", 70 + static_cast<int>(label_.size()), "");
  last_permille_ = -1;
}

}  // namespace kdm::cli
