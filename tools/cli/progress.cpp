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

/// Before 1% an estimate would be noise: none is given.
bool estimated(double fraction) {
  return fraction > 0.01;
}

}  // namespace

ProgressBar::ProgressBar(std::string label, std::FILE* out, double line_every_seconds)
    : label_(std::move(label)),
      out_(out),
      line_every_seconds_(line_every_seconds),
      terminal_(isatty(fileno(out)) != 0),
      start_(std::chrono::steady_clock::now()) {
  if (terminal_ || line_every_seconds_ < 1) return;
  try {
    heartbeat_ = std::thread([this] {
      std::unique_lock<std::mutex> lock(mutex_);
      while (!finished_) {
        const auto next =
            start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                         std::chrono::duration<double>(last_line_seconds_ + line_every_seconds_));
        if (finishing_.wait_until(lock, next, [this] { return finished_; })) break;
        const double now = elapsed();
        if (now - last_line_seconds_ >= line_every_seconds_ && fraction_ < 1) log_line(now);
      }
    });
  } catch (const std::system_error&) {
    // no thread to be had: lines come with the updates alone
  }
}

ProgressBar::~ProgressBar() {
  finish();
}

double ProgressBar::elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void ProgressBar::log_line(double now) {
  last_line_seconds_ = now;
  const std::string left =
      estimated(fraction_) ? ", about " + duration_text(now * (1 - fraction_) / fraction_) + " left" : "";
  std::fprintf(out_, "%s: %.0f%% after %s%s\n", label_.c_str(), fraction_ * 100, duration_text(now).c_str(),
               left.c_str());
  std::fflush(out_);
}

void ProgressBar::update(double fraction) {
  fraction = std::clamp(fraction, 0.0, 1.0);
  const double now = elapsed();
  if (!terminal_) {
    std::lock_guard<std::mutex> lock(mutex_);
    fraction_ = fraction;
    if (now - last_line_seconds_ >= line_every_seconds_ && fraction < 1 && !finished_) log_line(now);
    return;
  }
  const int permille = static_cast<int>(fraction * 1000);
  if (permille == last_permille_ && now - last_line_seconds_ < 1) return;  // the clock redrawn each second
  last_permille_ = permille;
  last_line_seconds_ = now;
  const int width = 30, filled = static_cast<int>(fraction * width);
  char eta[32] = "    ?";
  if (estimated(fraction)) std::snprintf(eta, sizeof eta, "%4.0fs", now * (1 - fraction) / fraction);
  std::fprintf(out_, "\r%s [%.*s%*s] %5.1f%%  ETA %s after %s ", label_.c_str(), filled,
               "##############################", width - filled, "", fraction * 100, eta,
               duration_text(now).c_str());
  std::fflush(out_);
}

void ProgressBar::finish() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    finished_ = true;
  }
  finishing_.notify_all();
  if (heartbeat_.joinable()) heartbeat_.join();
  if (terminal_ && last_permille_ >= 0)
    std::fprintf(out_, "\r%*s\r", 90 + static_cast<int>(label_.size()), "");
  last_permille_ = -1;
}

}  // namespace kdm::cli
