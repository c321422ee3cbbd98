// The kdm subcommands. Each add_*_command registers its options on `app` and sets a callback that
// runs it; a failing command throws CommandError, which main() prints as one line and exits with its
// status (1 unless the command says otherwise).
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "kdm/runtime/status.h"

namespace CLI {
class App;
}

namespace kdm::cli {

struct CommandError : std::runtime_error {
  explicit CommandError(const std::string& message, int status = 1)
      : std::runtime_error(message), exit_status(status) {}
  int exit_status;  ///< 1, or what a command documents (kdm verify: 2 for a set that fails its checks)
};

/// The bytes of the tile-set file `path` ("-": standard input) as read_tileset_file reads them, or a
/// CommandError when it cannot be read.
std::vector<char> read_tileset_input(const std::string& path);
/// The error for tile-set file `path` whose `bytes` the runtime refused with `s` and `detail`; for a recipe
/// given instead, it says how to bake it.
CommandError tileset_error(const std::string& path, Status s, const std::string& detail,
                           const std::vector<char>& bytes);

void add_sample_command(CLI::App& app);
void add_analyze_command(CLI::App& app);
void add_verify_command(CLI::App& app);
void add_tile_commands(CLI::App& app);  // bake, info
void add_stipple_command(CLI::App& app);
void add_query_command(CLI::App& app);

}  // namespace kdm::cli
