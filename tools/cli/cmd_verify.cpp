// `kdm verify`: the generator test on any tile set — every tile and level against the full sampler.
#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "checked_options.h"
#include "commands.h"
#include "kdm/runtime/tileset_format.h"
#include "kdm/verify/verify.h"
#include "progress.h"

namespace kdm::cli {
namespace {

struct VerifyArgs {
  std::string path;
  verify::VerifyOptions options;
  bool no_seams = false, no_direct = false, no_glide_track = false, quiet = false;
  std::vector<std::int64_t> levels;  ///< --level, signed: -1 is refused by name, not by CLI11's conversion
  std::int64_t spectrum_budget = std::int64_t(1) << 30;  ///< signed for the same reason
};

void run_verify(VerifyArgs args) {
  // 0 turns a bar off; a negative or NaN bar would too, silently.
  if (!(args.options.bars.hole_largest >= 0 && std::isfinite(args.options.bars.hole_largest)))
    throw CommandError("--hole-largest must be a number >= 0 (0: report only)");
  if (!(args.options.bars.holes_per_1e5 >= 0 && std::isfinite(args.options.bars.holes_per_1e5)))
    throw CommandError("--holes-per-1e5 must be a number >= 0 (0: report only)");
  if (args.options.handover_rows < 1 || args.options.handover_rows > 1000)
    throw CommandError("--handover-rows must be in [1, 1000]");
  if (args.options.reference_runs < 2 || args.options.reference_runs > 1000)
    throw CommandError("--runs must be in [2, 1000]");
  if (args.spectrum_budget < 0)
    throw CommandError("--spectrum-budget must be a point count >= 0 (0: no spectra), got " +
                       std::to_string(args.spectrum_budget));
  args.options.spectrum_budget = static_cast<std::size_t>(args.spectrum_budget);
  for (const std::int64_t level : args.levels) {
    if (level < 0)
      throw CommandError("--level must be a level number >= 0 (the first is 0), got " +
                         std::to_string(level));
    if (level > std::numeric_limits<std::uint32_t>::max())
      throw CommandError("--level " + std::to_string(level) + " is not in the tile set");
    args.options.levels.push_back(static_cast<std::uint32_t>(level));
  }
  TilesetData set;
  std::string detail;
  const std::vector<char> bytes = read_tileset_input(args.path);
  const Status s = decode_tileset(bytes.data(), bytes.size(), set, &detail);
  if (s != Status::kOk) throw tileset_error(args.path, s, detail, bytes);
  args.options.seams = !args.no_seams;
  args.options.direct_check = !args.no_direct;
  args.options.glide_track = !args.no_glide_track;
  const auto t0 = std::chrono::steady_clock::now();
  ProgressBar bar("verifying");
  args.options.progress = [&bar](double f) { bar.update(f); };
  const verify::Report report = verify::verify_tileset(set, args.options);
  bar.finish();
  std::printf("%s: %zu tile(s), %u levels, %u reference runs per level\n", args.path.c_str(),
              set.tiles.size(), set.levels, unsigned(args.options.reference_runs));
  verify::print_report(report, stdout, !args.quiet);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("(%.1f s)\n", seconds);
  std::fflush(stdout);
  if (!report.passed())
    throw CommandError("'" + args.path + "' failed " + std::to_string(report.failed_checks()) +
                           " check(s) of the generator test",
                       2);  // a set that was read and judged, told apart from one that could not be
}

}  // namespace

void add_verify_command(CLI::App& app) {
  auto args = std::make_shared<VerifyArgs>();
  CLI::App* cmd = app.add_subcommand(
      "verify",
      "Judge every tile and level of a tile set against the full KDM sampler (the generator test); "
      "prints a table per level; exits 2 if any check fails, 1 if the file cannot be read or an option is "
      "wrong");
  cmd->add_option("file", args->path, "Tile-set file ('-': standard input)")->required();
  cmd->add_option("--runs", args->options.reference_runs, "Full-sampler reference runs per level (2 to 1000)")
      ->capture_default_str();
  cmd->add_option("--level", args->levels,
                  "Judge only these levels and the keyframes within them (repeatable; default: all)");
  add_count_option(
      cmd, "--spectrum-budget", args->spectrum_budget,
      "Largest tile torus (points) whose spectra (lowP, RAPS) are computed (default: every one)");
  cmd->add_flag("--no-seams", args->no_seams, "Skip the seam and in-between-density checks");
  cmd->add_flag("--no-direct", args->no_direct, "Skip the direct check (tiles freed for 15 sweeps)");
  cmd->add_flag("--no-glide-track", args->no_glide_track, "Skip the glide track's keyframes (smooth mode)");
  cmd->add_option("--hole-largest", args->options.bars.hole_largest,
                  "Fail a complete level or keyframe whose largest empty circle exceeds this many d_hex "
                  "(0: report only; the design's bar is 1.0)")
      ->capture_default_str();
  cmd->add_option("--holes-per-1e5", args->options.bars.holes_per_1e5,
                  "Fail a complete level or keyframe with more empty circles above 0.85 d_hex per 10^5 "
                  "points (0: report only; the design's bar is 10)")
      ->capture_default_str();
  cmd->add_option("--handover-rows", args->options.handover_rows,
                  "Densities at which the hand-over past the top level is judged, in even steps (1 to 1000)")
      ->capture_default_str();
  cmd->add_flag("--quiet", args->quiet,
                "Print only the failed checks and the count, not the tables (build logs)");
  add_threads_option(cmd, args->options.threads, "results do not depend on it");
  cmd->callback([args] { run_verify(*args); });
}

}  // namespace kdm::cli
