// `kdm bake` and `kdm info`: baking tile sets from a recipe, and describing a tile-set file.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "checked_options.h"
#include "commands.h"
#include "kdm/generator/bake.h"
#include "kdm/generator/sampler.h"
#include "kdm/runtime/tileset.h"
#include "point_io.h"
#include "point_output.h"
#include "progress.h"

namespace kdm::cli {
namespace {

/// How messages name an input: "standard input" for "-".
std::string named(const std::string& path) {
  return path == "-" ? std::string("standard input") : "'" + path + "'";
}
std::string recipe_named(const std::string& path) {
  return path == "-" ? std::string("the recipe on standard input") : "recipe '" + path + "'";
}
/// `path` as a command line that reads it again would give it.
std::string as_argument(const std::string& path) {
  return path == "-" ? path : "'" + path + "'";
}

std::string read_text(const std::string& path) {
  std::ifstream file;
  if (path != "-") file.open(path, std::ios::binary);
  std::istream& in = path == "-" ? std::cin : file;
  if (!in) throw CommandError("cannot open recipe '" + path + "': " + std::strerror(errno));
  // A recipe is a few lines: reading stops past the header's cap for it, so an endless input (a device, a
  // pipe) or a directory fails instead of filling memory.
  std::string text(kMaxTilesetHeaderBytes + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (in.bad()) {
    std::error_code ec;
    throw CommandError("cannot read " + recipe_named(path) +
                       (std::filesystem::is_directory(path, ec) ? ": it is a directory" : ""));
  }
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (text.compare(0, 8, "KDMTILES") == 0)  // the arguments swapped: say how to see its recipe
    throw CommandError(named(path) + " is a tile-set file, not a recipe (its recipe: kdm info " +
                       as_argument(path) + ")");
  if (text.size() > kMaxTilesetHeaderBytes)
    throw CommandError(recipe_named(path) + " is longer than " + std::to_string(kMaxTilesetHeaderBytes) +
                       " bytes: not a recipe");
  return text;
}

void run_bake(const std::string& recipe_path, const std::string& output, int threads) {
  gen::BakeRecipe recipe;
  try {
    const std::string text = read_text(recipe_path);
    if (!gen::BakeRecipe::gives_any_key(text))
      throw CommandError(recipe_named(recipe_path) +
                         " gives no key, only blank lines and comments (the "
                         "defaults alone bake for minutes: give at least one key, e.g. 'levels 6')");
    recipe = gen::BakeRecipe::parse(text);
  } catch (const gen::InvalidArgument& e) {
    throw CommandError(named(recipe_path) + ": " + e.what());
  }
  if (output == "-")  // a binary file, written atomically: never to a terminal or a pipe
    throw CommandError("-o -: a tile set is written to a file; name one, e.g. -o tiles.kdmt");
  try {
    tools::refuse_writing_over(recipe_path, output, "recipe");
  } catch (const std::invalid_argument& e) {
    throw CommandError(e.what());
  }
  std::string detail;
  if (const Status s = check_tileset_path(output, &detail); s != Status::kOk)  // before minutes of baking
    throw CommandError(std::string(status_message(s)) + ": " + detail);
  // Said before the minutes of baking: a .txt or .png name expects what the other commands write there.
  if (const std::string ext = tools::output_format(output); !ext.empty() && ext != ".kdmt")
    std::fprintf(stderr,
                 "kdm bake: warning: '%s' receives a tile set (binary, as .kdmt files), not a %s file\n",
                 output.c_str(), ext.c_str());
  const auto t0 = std::chrono::steady_clock::now();
  ProgressBar bar("baking");
  gen::BakeReport report;
  TilesetData set;
  try {
    set = gen::bake_tileset(
        recipe, threads, [&bar](double f) { bar.update(f); }, &report);
  } catch (const gen::InvalidArgument& e) {  // the recipe's values, found while baking
    throw CommandError(named(recipe_path) + ": " + e.what());
  }
  bar.finish();
  const Status s = save_tileset(set, output, &detail);
  if (s != Status::kOk) throw CommandError(std::string(status_message(s)) + ": " + detail);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::fprintf(stderr, "kdm bake: %zu tile(s), %u level%s, %u points per tile -> %s (%.1f s)\n",
               set.tiles.size(), set.levels, set.levels == 1 ? "" : "s", set.level_nominal.back(),
               output.c_str(), seconds);
  if (recipe.separation > 0)
    std::fprintf(stderr, "  close pairs: %zu point(s) moved, %zu split per tile, %zu removed\n", report.moved,
                 report.split, report.removed);
  if (recipe.glide_separation > 0)
    std::fprintf(stderr, "  close glides: %zu point(s) split per tile, %zu removed\n", report.glide_split,
                 report.glide_removed);
}

/// Text from a file for the terminal: bytes outside printable ASCII as \xNN, so that a damaged or hostile
/// file cannot send control sequences.
std::string printable(const std::string& text) {
  std::string out;
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    char hex[8];
    std::snprintf(hex, sizeof hex, "\\x%02X", byte);
    out += byte >= 0x20 && byte < 0x7F ? std::string(1, c) : std::string(hex);
  }
  return out;
}

void run_info(const std::string& path) {
  // The runtime answers what the file is: its header, then the set as queries would hold it.
  const std::vector<char> bytes = read_tileset_input(path);
  TilesetHeader header;
  std::string detail;
  Status s = read_tileset_header(bytes.data(), bytes.size(), header, &detail);
  Tileset loaded;
  if (s == Status::kOk) s = Tileset::load_memory(bytes.data(), bytes.size(), loaded, &detail);
  if (s != Status::kOk) throw tileset_error(path, s, detail, bytes);
  const TilesetData& set = loaded.data();
  std::printf("file           %s (%zu bytes)\n", path == "-" ? "(standard input)" : path.c_str(),
              bytes.size());
  const std::size_t resident = loaded.resident_bytes();
  std::printf("resident       %zu bytes (%.3g MiB) once loaded by the runtime\n", resident,
              double(resident) / (1 << 20));
  std::printf("format         version %u (header %u bytes, payload %llu bytes, %llu decompressed)\n",
              header.format_version, header.header_bytes,
              static_cast<unsigned long long>(header.payload_bytes),
              static_cast<unsigned long long>(header.decompressed_bytes));
  std::printf("generator      kdm %s\n", printable(set.generator_version).c_str());
  std::printf("colours        %u (%zu tile%s)\n", set.colours, set.tiles.size(),
              set.tiles.size() == 1 ? "" : "s");
  std::printf("levels         %u\n", set.levels);
  std::printf("points/level   ");
  for (std::uint32_t k = 0; k < set.levels; ++k) std::printf("%s%u", k ? " " : "", set.level_nominal[k]);
  std::printf("  (nominal per tile, cumulative)\n");
  std::uint32_t fewest = ~0u, most = 0;
  for (const Tile& t : set.tiles)
    fewest = std::min(fewest, t.level_end.back()), most = std::max(most, t.level_end.back());
  std::printf("points/tile    %u to %u (top level, actual)\n", fewest, most);
  std::printf("density range  1 : %.0f (level 0 to level %u)\n",
              double(set.level_nominal.back()) / set.level_nominal.front(), set.levels - 1);
  if (set.keyframe_nominal.empty())
    std::printf("glide track    none (--mode smooth emits stable positions)\n");
  else
    std::printf(
        "glide track    %zu keyframes, %u to %u points per tile (--mode smooth; %.2f tile sides at most)\n",
        set.keyframe_nominal.size(), set.keyframe_nominal.front(), set.keyframe_nominal.back(),
        loaded.glide_reach());
  if (set.handover_zone) {
    char keyframe[80];
    if (set.handover_slack)
      std::snprintf(keyframe, sizeof keyframe, "%u keyframe%s past their first above level %u",
                    set.handover_slack, set.handover_slack == 1 ? "" : "s", set.handover_level);
    else
      std::snprintf(keyframe, sizeof keyframe, "their first keyframe above level %u", set.handover_level);
    std::printf(
        "hand-over      onto %u x %u subtiles past the top level, at %s (%u points per tile; zones of %u "
        "sub-step%s; smooth queries descend)\n",
        set.subtiles_per_side(), set.subtiles_per_side(), keyframe,
        set.keyframe_nominal[set.handover_keyframe()], set.handover_zone, set.handover_zone == 1 ? "" : "s");
  }
  std::printf("recipe\n");
  std::istringstream recipe(set.recipe);
  for (std::string line; std::getline(recipe, line);) std::printf("  %s\n", printable(line).c_str());
}

}  // namespace

std::vector<char> read_tileset_input(const std::string& path) {
  std::vector<char> bytes;
  std::string detail;
  // /dev/stdin: the runtime's reader, with its bounds on what it reads, reads standard input too.
  if (const Status s = read_tileset_file(path == "-" ? "/dev/stdin" : path, bytes, &detail); s != Status::kOk)
    throw CommandError(named(path) + ": " + status_message(s) + ": " + detail);
  return bytes;
}

CommandError tileset_error(const std::string& path, Status s, const std::string& detail,
                           const std::vector<char>& bytes) {
  std::string hint;
  if (s == Status::kBadMagic) {
    // The reader stops at the fixed header of a file without the magic: a recipe's first key line may lie
    // past it, behind comments, so a named file is read again, a little further.
    std::string start(bytes.begin(), bytes.end());
    if (path != "-") {
      std::ifstream in(path, std::ios::binary);
      start.assign(4096, '\0');
      in.read(start.data(), static_cast<std::streamsize>(start.size()));
      start.resize(static_cast<std::size_t>(in.gcount()));
    }
    if (gen::BakeRecipe::looks_like_recipe(start))
      hint = "; it looks like a recipe: bake it with kdm bake " + as_argument(path) + " -o FILE.kdmt";
  }
  return CommandError(named(path) + ": " + status_message(s) + ": " + detail + hint);
}

void add_tile_commands(CLI::App& app) {
  auto recipe = std::make_shared<std::string>();
  auto output = std::make_shared<std::string>();
  auto threads = std::make_shared<int>(0);
  CLI::App* bake =
      app.add_subcommand("bake", "Bake a tile set from a recipe (deterministic for any --threads)");
  bake->add_option(
          "recipe", *recipe,
          "Recipe file ('-': standard input): 'key value' lines (seed, colours, levels, base_points, "
          "temperature, sweeps, band, erosion, edge_gap, min_distance, rank_context, separation, "
          "separation_push, split_shared, separation_fill, separation_per_level, fill_holes, "
          "keyframes, glide_sweeps, glide_separation, glide_consensus, glide_corner_consensus, "
          "glide_late, handover_zone, handover_level, handover_slack)")
      ->required();
  bake->add_option("-o,--output", *output, "Tile-set file to write (atomically)")->required();
  add_threads_option(bake, *threads, "the file does not depend on it");
  bake->callback([=] { run_bake(*recipe, *output, *threads); });

  auto info_path = std::make_shared<std::string>();
  CLI::App* info =
      app.add_subcommand("info", "Describe a tile-set file: header, recipe, tiles, levels, size");
  info->add_option("file", *info_path, "Tile-set file ('-': standard input)")->required();
  info->callback([=] { run_info(*info_path); });
}

}  // namespace kdm::cli
