#include "threads_arg.h"

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstdlib>

namespace kdm::cli {

CLI::Option* add_threads_option(CLI::App* cmd, int& threads, const std::string& independence) {
  const std::string range = "0 (automatic) or 1 to " + std::to_string(kMaxThreads);
  // A validator sees the text before conversion: text that is no integer is left to CLI11's own message.
  auto in_range = [range](std::string& text) -> std::string {
    char* end = nullptr;
    errno = 0;
    const long long n = std::strtoll(text.c_str(), &end, 10);
    if (end == text.c_str() || *end != '\0') return "";
    if (errno == ERANGE || n < 0 || n > kMaxThreads) return "must be " + range + ", got " + text;
    return "";
  };
  return cmd
      ->add_option("--threads", threads,
                   "Worker threads, at most " + std::to_string(kMaxThreads) +
                       " (0: OMP_NUM_THREADS, else the CPUs this process may use); " + independence)
      ->capture_default_str()
      ->check(CLI::Validator(in_range, ""));
}

}  // namespace kdm::cli
