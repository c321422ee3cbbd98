#include "checked_options.h"

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "commands.h"
#include "kdm/generator/sampler.h"
#include "point_io.h"

namespace kdm::cli {

CLI::Option* add_threads_option(CLI::App* cmd, int& threads, const std::string& independence) {
  const std::string range = "0 (automatic) or 1 to " + std::to_string(gen::kMaxThreads);
  // A validator sees the text before conversion: text that is no integer is left to CLI11's own message.
  auto in_range = [range](std::string& text) -> std::string {
    char* end = nullptr;
    errno = 0;
    const long long n = std::strtoll(text.c_str(), &end, 10);
    if (end == text.c_str() || *end != '\0') return "";
    if (errno == ERANGE || n < 0 || n > gen::kMaxThreads) return "must be " + range + ", got " + text;
    return "";
  };
  return cmd
      ->add_option("--threads", threads,
                   "Worker threads, at most " + std::to_string(gen::kMaxThreads) +
                       " (0: OMP_NUM_THREADS, else the CPUs this process may use); " + independence)
      ->capture_default_str()
      ->check(CLI::Validator(in_range, ""));
}

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

CLI::Option* add_tileset_option(CLI::App* cmd, std::string& path, const std::string& description) {
  auto named = [](std::string& text) -> std::string {
    return text.empty() ? "is empty: give a tile-set file, or leave the option out for the built-in set" : "";
  };
  return cmd->add_option("--tileset", path, description)->check(CLI::Validator(named, ""));
}

CLI::Option* add_count_option(CLI::App* cmd, const std::string& names, std::int64_t& count,
                              const std::string& description) {
  // A transform sees the text before conversion: a whole number in float notation becomes its digits.
  auto whole = [](std::string& text) -> std::string {
    if (text.find_first_of(".eE") == std::string::npos) {  // an integer, or CLI11's own message
      char* end = nullptr;
      errno = 0;
      std::strtoll(text.c_str(), &end, 10);
      return end != text.c_str() && *end == '\0' && errno == ERANGE ? "must be below 2^63, got " + text : "";
    }
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (end == text.c_str() || *end != '\0') return "";
    if (!(std::fabs(v) < 0x1p63) || v != std::floor(v)) return "must be a whole number, got " + text;
    text = std::to_string(static_cast<std::int64_t>(v));
    return "";
  };
  return cmd->add_option(names, count, description)
      ->capture_default_str()
      ->transform(CLI::Validator(whole, ""));
}

std::string check_output_option(const std::string& path, const std::vector<const char*>& extensions,
                                const std::string& format) {
  std::string error;
  if (!tools::check_output_path(path, extensions, error, format)) throw CommandError(error);
  return tools::output_format(path, format);
}

CLI::Option* add_format_option(CLI::App* cmd, std::string& format,
                               const std::vector<const char*>& extensions) {
  std::string names;
  for (std::size_t i = 0; i < extensions.size(); ++i)
    names += (i ? ", " : "") + std::string(extensions[i] + 1);
  return cmd->add_option(
      "--format", format,
      "The output's format (" + names +
          "; default: -o's extension): -o - writes to standard output, as in `-o - "
          "--format " +
          std::string(extensions[0] + 1) +
          " | …`; it does not override a file name of "
          "another format's extension (-o x.png --format svg is refused: name the file .svg)");
}

std::vector<double> parse_sides(const std::string& text, const std::string& what) {
  std::vector<double> sides;
  for (std::size_t from = 0;;) {
    const std::size_t colon = text.find(':', from);
    const std::string part = text.substr(from, colon == std::string::npos ? std::string::npos : colon - from);
    char* end = nullptr;
    const double v = std::strtod(part.c_str(), &end);
    if (part.empty() || *end != '\0' || !(v > 0 && std::isfinite(v)))
      throw CommandError(what +
                         " must be a number > 0 (the x side over the others), two sides W:H or three sides "
                         "X:Y:Z, each > 0; got '" +
                         text + "'");
    sides.push_back(v);
    if (colon == std::string::npos) break;
    from = colon + 1;
  }
  if (sides.size() == 2) return {sides[0] / sides[1]};  // W:H, as a picture's shape is often written
  if (sides.size() != 1 && sides.size() != 3)
    throw CommandError(what + " takes one number, two sides W:H or three sides X:Y:Z, got " +
                       std::to_string(sides.size()) + " in '" + text + "'");
  return sides;
}

std::vector<std::string> options_given(const CLI::App* cmd, const std::vector<const char*>& picture_only) {
  std::vector<std::string> given;
  for (const char* name : picture_only)
    if (cmd->get_option(name)->count() > 0) given.push_back(name);
  return given;
}

void refuse_picture_options(const std::vector<std::string>& given, const std::string& format) {
  if (format != ".png" && format != ".svg" && !given.empty())
    throw CommandError(given.front() +
                       " sizes pictures: write .png or .svg (points files hold positions only)");
}

}  // namespace kdm::cli
