// Files written whole or not at all: a temporary file beside the output, renamed over it once every write
// succeeded, and removed if the command line is interrupted.
#include "atomic_file.h"

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>

#include <sys/stat.h>
#include <unistd.h>

namespace kdm::tools {
namespace {

std::string temp_path_for(const std::string& path) {
  return path + ".tmp~";
}

// The temporary file being written, for a signal handler to remove: marked only where the handlers are
// installed (one writing thread), so that a library's threads never share it.
std::atomic<bool> signals_handled{false};
char marked_path[4096];
std::atomic<bool> marked{false};  // lock-free: a handler on any thread reads it; the path is whole once set
static_assert(std::atomic<bool>::is_always_lock_free, "a signal handler may only read lock-free atomics");

extern "C" void remove_marked_and_reraise(int signal) {
  if (marked.load(std::memory_order_acquire)) unlink(marked_path);  // async-signal-safe
  struct sigaction fallback = {};
  fallback.sa_handler = SIG_DFL;
  sigaction(signal, &fallback, nullptr);
  raise(signal);
}

/// Marks `path` (or nothing, for null) as the temporary file being written.
void mark(const std::string* path) {
  if (!signals_handled.load(std::memory_order_relaxed)) return;
  marked.store(false, std::memory_order_release);
  if (!path || path->size() >= sizeof marked_path) return;
  std::memcpy(marked_path, path->c_str(), path->size() + 1);
  marked.store(true, std::memory_order_release);
}

bool commit_temp(const std::string& tmp, const std::string& path, std::string& error) {
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    error = "cannot write '" + path + "': " + std::strerror(errno);
    std::remove(tmp.c_str());
    return false;
  }
  return true;
}

}  // namespace

bool write_text_file_atomic(const std::string& given_path, const std::string& text, std::string& error) {
  if (given_path == "-") {  // standard output (point_io.h's kStandardOutput): a pipe's reader sees it all
    const bool written = std::fwrite(text.data(), 1, text.size(), stdout) == text.size();
    if (written && std::fflush(stdout) == 0) return true;
    error = std::string("cannot write to standard output: ") + std::strerror(errno);
    return false;
  }
  // A device or a pipe (/dev/null, /dev/stdout, a FIFO) is written into, as a shell's > does: a rename
  // would replace it with a regular file.
  struct stat info;
  const bool special =
      stat(given_path.c_str(), &info) == 0 && !S_ISREG(info.st_mode) && !S_ISDIR(info.st_mode);
  // A symbolic link is written through, as cp and a shell's > do: the rename replaces its target.
  std::string path = given_path;
  std::error_code ec;
  if (!special && std::filesystem::is_symlink(std::filesystem::symlink_status(path, ec))) {
    const std::filesystem::path target = std::filesystem::weakly_canonical(path, ec);
    if (!ec) path = target.string();
  }
  const std::string tmp = special ? path : temp_path_for(path);
  if (!special) mark(&tmp);
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) {
    mark(nullptr);
    error = "cannot write '" + path + "': " + std::strerror(errno);
    return false;
  }
  // fclose too can fail (delayed write errors); either failure leaves no file behind.
  const bool written = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  const int write_errno = errno;
  if (std::fclose(f) != 0 || !written) {
    error = "cannot write '" + path + "': " + std::strerror(written ? errno : write_errno);
    if (!special) std::remove(tmp.c_str());
    mark(nullptr);
    return false;
  }
  const bool done = special || commit_temp(tmp, path, error);
  mark(nullptr);
  return done;
}

void remove_temporary_files_on_signals() {
  signals_handled.store(true);
  for (int signal : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction current = {};
    // A signal the process was started ignoring (nohup, a script's background job) stays ignored.
    if (sigaction(signal, nullptr, &current) != 0 || current.sa_handler == SIG_IGN) continue;
    struct sigaction handler = {};
    handler.sa_handler = remove_marked_and_reraise;
    sigemptyset(&handler.sa_mask);
    sigaction(signal, &handler, nullptr);
  }
}

void detail::mark_temporary_file(const char* path) {
  const std::string text = path ? path : "";
  mark(path ? &text : nullptr);
}

}  // namespace kdm::tools
