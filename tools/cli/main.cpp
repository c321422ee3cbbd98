// kdm: the command line. See `kdm --help` and README.md.
#include <CLI/CLI.hpp>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <iostream>
#include <iterator>
#include <new>
#include <sstream>
#include <string>
#include <vector>

#include "atomic_file.h"
#include "commands.h"
#include "kdm/runtime/version.h"

namespace {

// CLI11 takes the word after an option that needs a value as that value even when the word is another of
// the command's options ("--density -o x" read "-o" as the density, then reported -o missing). Returns
// the error for the first such pair on the command line, or "" if there is none.
std::string option_given_as_value(const CLI::App& app, int argc, char** argv) {
  if (argc < 3) return "";
  const CLI::App* cmd = nullptr;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
    if (sub->get_name() == argv[1]) cmd = sub;
  if (cmd == nullptr) return "";
  const auto option_named = [cmd](const std::string& word) -> const CLI::Option* {
    if (word.size() < 2 || word[0] != '-') return nullptr;
    for (const CLI::Option* opt : cmd->get_options())
      if (!opt->get_positional() && opt->check_name(word)) return opt;
    return nullptr;
  };
  for (int i = 2; i + 1 < argc; ++i) {
    const std::string word = argv[i];
    if (word == "--") break;
    const CLI::Option* opt = option_named(word);
    if (opt == nullptr || opt->get_expected_min() == 0) continue;  // not an option, or a flag
    const std::string next = argv[i + 1];
    if (option_named(next) != nullptr || next == "-h" || next == "--help")
      return word + " needs a value, but is followed by the option " + next;
    ++i;  // the value
  }
  return "";
}

// CLI11 reads an integer with a leading 0 as octal: "--width 0100" drew 64 pixels, "--seed 010" seed 8,
// and "--points 0800" was no number. A script's zero-padded numbers are decimal: strip the zeros.
void read_integers_as_decimal(CLI::App& app) {
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
    for (CLI::Option* opt : sub->get_options()) {
      const std::string type = opt->get_type_name();
      if (type != "INT" && type != "UINT") continue;
      opt->transform(
          [](std::string word) {
            const std::size_t sign = word.size() > 1 && (word[0] == '-' || word[0] == '+') ? 1 : 0;
            std::size_t first = sign;
            while (first + 1 < word.size() && word[first] == '0' &&
                   std::isdigit(static_cast<unsigned char>(word[first + 1])))
              ++first;
            return word.substr(0, sign) + word.substr(first);
          },
          "", "decimal");
    }
}

// CLI11 reads an empty word as 0 or as no value: "-T $T" with T unset sampled at temperature 0, "--sweeps
// ''" ran no sweeps. Every option's value, and every positional, must be a word.
void refuse_empty_values(CLI::App& app) {
  const CLI::Validator non_empty(
      [](std::string& word) { return word.empty() ? std::string("is empty (an unset variable?)") : ""; }, "");
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
    for (CLI::Option* opt : sub->get_options())
      if (opt->get_expected_min() > 0) opt->check(non_empty);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"kdm — blue-noise point sets from Fattal's kernel density model (KDM, SIGGRAPH 2011)"};
  app.set_version_flag("--version", std::string("kdm ") + kdm::version_string() + " (tile-set format " +
                                        std::to_string(kdm::kTilesetFormatVersion) + ")");
  app.require_subcommand(1);
  kdm::tools::remove_temporary_files_on_signals();  // an interrupted write leaves no OUT.tmp~ behind
  kdm::cli::add_sample_command(app);
  kdm::cli::add_stipple_command(app);
  kdm::cli::add_query_command(app);
  kdm::cli::add_tile_commands(app);
  kdm::cli::add_analyze_command(app);
  kdm::cli::add_verify_command(app);
  read_integers_as_decimal(app);
  refuse_empty_values(app);
  try {
    if (const std::string error = option_given_as_value(app, argc, argv); !error.empty()) {
      std::fprintf(stderr, "kdm: error: %s (see kdm %s --help)\n", error.c_str(), argv[1]);
      return 1;
    }
    app.parse(argc, argv);
    // What a command printed (info, verify's tables, analyze's summary) must have reached its reader: a
    // full disk or a closed file behind > is a failure, as for -o -.
    std::cout.flush();
    if (std::fflush(stdout) != 0 || std::ferror(stdout) || !std::cout) {
      std::fprintf(stderr, "kdm: error: cannot write to standard output: %s\n", std::strerror(errno));
      return 1;
    }
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // Bad command lines get the same one-line error as every other failure (CLI11 would add a hint line).
    std::string message = e.what(), help = "kdm --help";
    // CLI11 lists unexpected words last first ("300 --width"): put them back in the command line's order.
    if (const std::size_t colon = message.find(": ");
        dynamic_cast<const CLI::ExtrasError*>(&e) && colon != std::string::npos) {
      std::istringstream words(message.substr(colon + 2));
      std::vector<std::string> given{std::istream_iterator<std::string>(words), {}};
      std::string in_order;
      for (auto word = given.rbegin(); word != given.rend(); ++word)
        in_order += (in_order.empty() ? "" : " ") + *word;
      message = message.substr(0, colon + 2) + in_order;
    }
    if (argc > 1 && argv[1][0] != '-') {  // CLI11 calls an unknown subcommand "a subcommand is required"
      bool known = false;
      for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
        known = known || sub->get_name() == argv[1];
      if (!known) message = std::string("unknown subcommand '") + argv[1] + "'";
      if (known) help = std::string("kdm ") + argv[1] + " --help";  // the command's own options
    }
    for (char& c : message)
      if (c == '\n') c = ' ';
    std::fprintf(stderr, "kdm: error: %s (see %s)\n", message.c_str(), help.c_str());
    return 1;
  } catch (const kdm::cli::CommandError& e) {
    std::fprintf(stderr, "kdm: error: %s\n", e.what());
    return e.exit_status;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr,
                 "kdm: error: out of memory (fewer --threads, fewer points or a smaller image may fit)\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "kdm: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
