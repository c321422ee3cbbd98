// The kdm subcommands. Each add_*_command registers its options on `app` and sets a callback that
// runs it; a failing command throws CommandError, which main() prints as one line and exits with its
// status (1 unless the command says otherwise).
#pragma once

#include <stdexcept>
#include <string>

namespace CLI {
class App;
}

namespace kdm::cli {

struct CommandError : std::runtime_error {
  explicit CommandError(const std::string& message, int status = 1)
      : std::runtime_error(message), exit_status(status) {}
  int exit_status;  ///< 1, or what a command documents (kdm verify: 2 for a set that fails its checks)
};

void add_sample_command(CLI::App& app);
void add_analyze_command(CLI::App& app);
void add_verify_command(CLI::App& app);
void add_tile_commands(CLI::App& app);  // bake, info
void add_stipple_command(CLI::App& app);
void add_query_command(CLI::App& app);

}  // namespace kdm::cli
