// --threads, the same in every command that runs worker threads: one limit, checked as the command line
// is parsed.
#pragma once

#include <string>

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace kdm::cli {

/// The most worker threads --threads accepts: more than the cores of today's largest machines, yet few
/// enough that a typo cannot exhaust memory or time (each worker has its own stack and megabytes of
/// scratch).
inline constexpr int kMaxThreads = 256;

/// Adds --threads to `cmd`, bound to `threads`: 0 (the default count) or 1 to kMaxThreads, anything else
/// refused by name. `independence` ends the help text (e.g. "output does not depend on it").
CLI::Option* add_threads_option(CLI::App* cmd, int& threads, const std::string& independence);

}  // namespace kdm::cli
