// --seed, the same in every command that takes one: a 64-bit unsigned integer, checked as the command line
// is parsed (CLI11 alone wraps -1 and saturates a larger number, which would silently reuse a seed).
#pragma once

#include <cstdint>
#include <string>

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace kdm::cli {

/// Adds --seed to `cmd`, bound to `seed`: 0 to 2^64 - 1, anything else refused by name.
CLI::Option* add_seed_option(CLI::App* cmd, std::uint64_t& seed, const std::string& description);

}  // namespace kdm::cli
