// Options that every command taking them checks alike, as the command line is parsed: --threads (one
// limit) and --seed (CLI11 alone wraps -1 and saturates a larger number, which would silently reuse a seed).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace kdm::cli {

/// Adds --threads to `cmd`, bound to `threads`: 0 (the default count) or 1 to gen::kMaxThreads, anything else
/// refused by name. `independence` ends the help text (e.g. "output does not depend on it").
CLI::Option* add_threads_option(CLI::App* cmd, int& threads, const std::string& independence);

/// Adds --seed to `cmd`, bound to `seed`: 0 to 2^64 - 1, anything else refused by name.
CLI::Option* add_seed_option(CLI::App* cmd, std::uint64_t& seed, const std::string& description);

/// Adds --tileset to `cmd`, bound to `path`: a file, or '-' for standard input; an empty path (an unset
/// shell variable) refused by name, where it would silently mean the built-in set.
CLI::Option* add_tileset_option(CLI::App* cmd, std::string& path, const std::string& description);

/// Adds a count option (`names`, e.g. "-n,--n") to `cmd`, bound to `count`: an integer, also written as a
/// whole number in float notation (1e5, 20000.0); a fraction or a number past 2^63 refused by name.
CLI::Option* add_count_option(CLI::App* cmd, const std::string& names, std::int64_t& count,
                              const std::string& description);

/// A domain's shape as --aspect gives it (kdm sample, kdm analyze): one number A, the x side over the others,
/// two sides W:H (A = W / H), or three sides X:Y:Z, each > 0 and finite. Returns the one (for W:H, W / H)
/// or three numbers; `what` names the source in
/// the error ("--aspect", a file's header). Throws CommandError.
std::vector<double> parse_sides(const std::string& text, const std::string& what);

/// Refuses, before any long work, an output path that write would refuse later: a format (`format`, the
/// --format option, else the path's extension) not among `extensions` (".csv", ".png", …), a directory, a
/// directory that does not exist, or "-" (standard output) without a format. Throws CommandError.
/// Returns the format (".csv").
std::string check_output_option(const std::string& path, const std::vector<const char*>& extensions,
                                const std::string& format = "");

/// Adds --format to `cmd`, bound to `format`: the output's format where -o does not name it (-o -,
/// standard output), one of `extensions` without the dot.
CLI::Option* add_format_option(CLI::App* cmd, std::string& format,
                               const std::vector<const char*>& extensions);

/// The options among `picture_only` (--width, --dot-size, …) given on `cmd`'s command line, in that order.
std::vector<std::string> options_given(const CLI::App* cmd, const std::vector<const char*>& picture_only);

/// Refuses picture options that were `given` (options_given) while the output `format` (".csv") is no
/// picture (.png, .svg): a points file would silently ignore them. Throws CommandError naming the first.
void refuse_picture_options(const std::vector<std::string>& given, const std::string& format);

}  // namespace kdm::cli
