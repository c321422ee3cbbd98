// `kdm query`: the runtime from the command line — points of a world rectangle for a density.
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <memory>

#include "commands.h"
#include "density_arg.h"
#include "output.h"
#include "runtime_args.h"

namespace kdm::cli {
namespace {

struct QueryArgs {
  std::string tileset, rect, density = "const:1", output;
  double scale = 1000, tile_size = 1, gamma = 1;
  bool invert = false;
};

void run_query_command(const QueryArgs& a) {
  double r[4];
  parse_rect(a.rect, "--rect", r);
  const DensityArg arg = parse_density(a.density, a.gamma, a.invert);
  Tileset storage;
  const Tileset& tiles = tileset_for(a.tileset, storage);
  const auto density = make_runtime_density(arg, r[0], r[1], r[2], r[3]);  // an image covers the rect
  QueryParams q;
  q.x0 = r[0], q.y0 = r[1], q.x1 = r[2], q.y1 = r[3];
  q.origin_x = r[0], q.origin_y = r[1];
  q.tile_size = a.tile_size;
  q.scale = a.scale;
  q.density = density->density;
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<QueryPoint> points;
  query_all(tiles, q, points);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const tools::PointSet set = normalise_to_rect(points, r);
  const double w = r[2] - r[0], h = r[3] - r[1];
  char line[200];
  std::snprintf(line, sizeof line, "kdm query: %zu points (rect %s, scale %g, tile size %g)", set.size(),
                a.rect.c_str(), a.scale, a.tile_size);
  DrawStyle style;
  style.aspect = w / h;
  write_points(a.output, set, {line, "coordinates normalised to the rect"}, style);
  std::fprintf(stderr, "%s in %.4f s -> %s\n", line, seconds, a.output.c_str());
}

}  // namespace

void add_query_command(CLI::App& app) {
  auto a = std::make_shared<QueryArgs>();
  CLI::App* cmd = app.add_subcommand("query", "Points of a world rectangle from a tile set (the runtime)");
  cmd->add_option("--tileset", a->tileset, "Tile-set file (default: the built-in set)");
  cmd->add_option("--rect", a->rect, "World rectangle x0,y0,x1,y1 in world units (half-open)")->required();
  cmd->add_option("--density", a->density, "const:V, or an image stretched over the rect (dark = dense)")
      ->capture_default_str();
  cmd->add_option("--gamma", a->gamma, "Exponent applied to image darkness")->capture_default_str();
  cmd->add_flag("--invert", a->invert, "Bright image areas are dense");
  cmd->add_option("--scale", a->scale, "Points per world unit area at density 1")->capture_default_str();
  cmd->add_option("--tile-size", a->tile_size, "World units per tile side")->capture_default_str();
  cmd->add_option("-o,--output", a->output, "Output: .txt, .csv (normalised to the rect), .svg or .png")
      ->required();
  cmd->callback([a] { run_query_command(*a); });
}

}  // namespace kdm::cli
