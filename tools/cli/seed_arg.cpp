#include "seed_arg.h"

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstdlib>

namespace kdm::cli {

CLI::Option* add_seed_option(CLI::App* cmd, std::uint64_t& seed, const std::string& description) {
  // A validator sees the text before conversion: strtoull accepts a sign and wraps it, so digits only.
  auto in_range = [](std::string& text) -> std::string {
    const std::string problem = "must be an integer from 0 to 18446744073709551615, got " + text;
    if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos) return problem;
    errno = 0;
    std::strtoull(text.c_str(), nullptr, 10);
    return errno == ERANGE ? problem : "";
  };
  return cmd->add_option("--seed", seed, description)
      ->capture_default_str()
      ->check(CLI::Validator(in_range, ""));
}

}  // namespace kdm::cli
