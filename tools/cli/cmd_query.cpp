// `kdm query`: the runtime from the command line — points of a world rectangle for a density, in world
// units with their stable ids (.csv, .json), or normalised to the rectangle (.txt, pictures).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include "atomic_file.h"
#include "checked_options.h"
#include "commands.h"
#include "density_arg.h"
#include "point_output.h"
#include "runtime_args.h"

namespace kdm::cli {
namespace {

const std::vector<const char*> kQueryFormats = {".csv", ".json", ".txt", ".svg", ".png"};

struct QueryArgs {
  std::string tileset, rect, density_rect, density = "const:1", output, format, mode = "stable";
  std::vector<std::string> classes;  ///< --class, repeated: one density per class, class 0 first
  double scale = 1000, tile_size = 1, gamma = 1;
  bool invert = false, normalised = false, glide_together = false;
};

/// .csv (with a header line) or .json: every point's position and its id (tile, rank, depth) and level, and
/// its class when `classes` is given. Positions are world coordinates printed exactly (%.17g), so the points
/// of any partition of a region are the same lines as the region's own; or, with `normalised`, coordinates in
/// [0, 1) of the rectangle.
std::string points_with_ids(const std::vector<QueryPoint>& points, const std::vector<std::uint8_t>* classes,
                            const Tileset& tiles, const double r[4], bool normalised, bool json) {
  std::vector<QueryPoint> from_corner;  // normalise_to_rect takes positions relative to the corner
  if (normalised) {
    from_corner = points;
    for (QueryPoint& p : from_corner) p.x -= r[0], p.y -= r[1];
  }
  const tools::PointSet unit = tools::normalise_to_rect(from_corner, r);
  // A point's id is (tile_x, tile_y, rank, depth): past the top level ranks repeat in subtiles. The depth
  // comes last, so that the columns files had before it keep their places.
  std::string out = json      ? "{\"rect\": ["
                    : classes ? "x,y,tile_x,tile_y,rank,level,class,depth\n"
                              : "x,y,tile_x,tile_y,rank,level,depth\n";
  char line[192];
  if (json) {
    std::snprintf(line, sizeof line, "%.17g, %.17g, %.17g, %.17g], \"normalised\": %s, \"points\": [", r[0],
                  r[1], r[2], r[3], normalised ? "true" : "false");
    out += line;
  }
  out.reserve(out.size() + points.size() * 64);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const QueryPoint& p = points[i];
    const double x = normalised ? unit.coords[2 * i] : p.x, y = normalised ? unit.coords[2 * i + 1] : p.y;
    const unsigned level = tile_of(tiles, p.id)->level_of(p.id.rank);
    const long long tx = p.id.tile_x, ty = p.id.tile_y;
    if (json)
      std::snprintf(line, sizeof line,
                    "%s\n  {\"x\": %.17g, \"y\": %.17g, \"tile_x\": %lld, \"tile_y\": %lld, \"rank\": %u, "
                    "\"level\": %u",
                    i ? "," : "", x, y, tx, ty, p.id.rank, level);
    else
      std::snprintf(line, sizeof line, "%.17g,%.17g,%lld,%lld,%u,%u", x, y, tx, ty, p.id.rank, level);
    out += line;
    if (classes) out += (json ? ", \"class\": " : ",") + std::to_string((*classes)[i]);
    out += (json ? ", \"depth\": " : ",") + std::to_string(p.id.depth) + (json ? "}" : "\n");
  }
  if (json) out += "\n]}\n";
  return out;
}

void run_query_command(const QueryArgs& a, bool density_given) {
  const std::string format = check_output_option(a.output, kQueryFormats, a.format);  // before a query
  double r[4], dr[4];
  parse_rect(a.rect, "--rect", r);
  if (density_given && !a.classes.empty())
    throw CommandError("give either --density or --class (one per class), not both");
  const bool csv = format == ".csv", json = format == ".json", ids = csv || json;
  if (a.normalised && !ids)
    throw CommandError(
        "--normalised is for .csv and .json output (.txt and pictures are always normalised to "
        "the rect)");
  if (!a.classes.empty() && format == ".txt")
    throw CommandError("--class: .txt has no class column; write .csv, .json, .svg or .png");
  // A picture's longer side is 1,024 pixels: a rect far longer than wide would be a line of pixels.
  const double aspect = (r[2] - r[0]) / (r[3] - r[1]);
  if ((format == ".png" || format == ".svg") && !(aspect >= 1.0 / 1024 && aspect <= 1024))
    throw CommandError(
        "--rect is more than 1,024 times " +
        std::string(aspect < 1 ? "taller than wide" : "wider than tall") +
        ": its picture, 1,024 pixels long, would be less than a pixel across; write .csv or .json");
  if (a.classes.size() > kMaxQueryClasses)
    throw CommandError("--class given " + std::to_string(a.classes.size()) + " times; at most " +
                       std::to_string(kMaxQueryClasses) + " classes");
  // One density per class (--density alone is one class); specs and densities stay put (queries point in).
  std::vector<std::unique_ptr<tools::DensitySpec>> specs;
  std::vector<std::pair<std::string, std::string>> inputs = {{"--tileset", a.tileset}};
  for (const std::string& text : a.classes.empty() ? std::vector<std::string>{a.density} : a.classes)
    inputs.emplace_back(a.classes.empty() ? "--density" : "--class", text);
  check_one_standard_input(inputs);
  for (const std::string& text : a.classes.empty() ? std::vector<std::string>{a.density} : a.classes) {
    tools::refuse_writing_over(text, a.output, "density image");  // a picture written over its input
    specs.push_back(std::make_unique<tools::DensitySpec>(parse_density(text, a.gamma, a.invert)));
  }
  std::vector<const tools::DensitySpec*> class_specs;
  for (const auto& spec : specs) class_specs.push_back(spec.get());
  check_class_images(class_specs);
  check_image_options(class_specs, a.gamma, a.invert);
  const bool any_map = std::any_of(specs.begin(), specs.end(), [](const auto& s) {
    return s->kind != tools::DensitySpec::Kind::kConstant;
  });
  if (!a.density_rect.empty() && !any_map)
    throw CommandError("--density-rect needs an image or a test map (--density or --class)");
  if (a.density_rect.empty()) {
    std::copy(r, r + 4, dr);  // the image stretched over the rectangle queried
    // A chunk of a map queried without the map's rectangle gets the whole map squeezed into it: where the
    // shapes differ, that is seldom what was meant.
    for (const auto& spec : specs)
      if (spec->kind == tools::DensitySpec::Kind::kImage && spec->height > 0) {
        const double map = double(spec->width) / spec->height, rect = (r[2] - r[0]) / (r[3] - r[1]);
        if (std::abs(std::log(map / rect)) > 0.01) {
          std::fprintf(stderr,
                       "kdm query: warning: the %dx%d map is stretched over --rect, whose shape (%.4g wide "
                       "per tall) is not the map's (%.4g): to query a part of a map, give the map's whole "
                       "world rectangle as --density-rect\n",
                       spec->width, spec->height, rect, map);
          break;
        }
      }
  } else {
    parse_rect(a.density_rect, "--density-rect", dr);
  }
  Tileset storage;
  const Tileset& tiles = tileset_for(a.tileset, storage);
  std::vector<std::unique_ptr<tools::SpecDensity>> densities;
  for (const auto& spec : specs) densities.push_back(std::make_unique<tools::SpecDensity>(*spec, dr));
  QueryParams q;
  q.x0 = r[0], q.y0 = r[1], q.x1 = r[2], q.y1 = r[3];
  q.tile_size = a.tile_size;
  q.scale = a.scale;
  q.density = densities[0]->density;
  q.mode = parse_mode(a.mode);
  q.glide_together = a.glide_together;
  if (a.glide_together && q.mode != QueryMode::kSmooth)  // stable points never glide: said, not refused
    std::fprintf(stderr, "kdm query: warning: --glide-together applies to --mode smooth only; ignored\n");
  warn_without_glide_track("kdm query", tiles, q.mode);
  // Below a point per tile a tile's count rounds (docs/runtime.md, "Parameters"): said, not refused, since a
  // sparse corner of a map is no mistake.
  double densest = 0;
  for (const auto& spec : specs) densest += spec->max_value() * spec->divided_by;  // an array's own size
  const std::string sparse =
      tools::tile_size_warning(tile_size_advice(tiles, densest, a.scale, a.tile_size), "--tile-size");
  if (!sparse.empty()) std::fprintf(stderr, "kdm query: warning: %s\n", sparse.c_str());
  std::vector<double> peaks;
  for (const auto& spec : specs) peaks.push_back(spec->max_value() * spec->divided_by);
  for (const std::string& uneven :
       tools::class_count_warnings(tiles, peaks, a.scale, a.tile_size, "--tile-size"))
    std::fprintf(stderr, "kdm query: warning: %s\n", uneven.c_str());
  const auto t0 = std::chrono::steady_clock::now();
  // Origin 0: positions are world coordinates, the same bits in any query.
  std::vector<QueryPoint> points;
  std::vector<std::uint8_t> classes;
  const bool classed = !a.classes.empty();
  if (classed) {
    ClassQueryParams cq;
    cq.query = q;
    cq.class_count = static_cast<std::uint32_t>(densities.size());
    for (std::size_t k = 0; k < densities.size(); ++k) cq.classes[k] = densities[k]->density;
    ClassImageSums sums;
    tools::read_images_by_sums(cq, sums);
    tools::query_all(tiles, cq, points, classes, kCommandLineNames);
  } else {
    tools::query_all(tiles, q, points, kCommandLineNames);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  char line[200];
  std::snprintf(line, sizeof line, "kdm query: %zu points (rect %s, scale %g, tile size %g)", points.size(),
                a.rect.c_str(), a.scale, a.tile_size);
  const auto t1 = std::chrono::steady_clock::now();
  if (ids) {
    std::string error;
    if (!tools::write_text_file_atomic(
            a.output, points_with_ids(points, classed ? &classes : nullptr, tiles, r, a.normalised, json),
            error))
      throw CommandError(error);
  } else {
    // .txt is the UTK/psa format, [0, 1) by definition; pictures show the rectangle.
    for (QueryPoint& p : points) p.x -= r[0], p.y -= r[1];
    tools::DrawStyle style;
    style.aspect = aspect;
    // The longer side 1,024 pixels: a tall, narrow rect is a tall picture, not one 1,024 pixels wide.
    style.width_px =
        style.aspect >= 1 ? 1024 : static_cast<int>(std::max(1.0, std::round(1024 * style.aspect)));
    if (classed) style.classes = &classes, style.inks = tools::class_inks(densities.size());
    tools::write_points(
        a.output, tools::normalise_to_rect(points, r),
        {line, "coordinates normalised to the rect, " + tools::domain_header(false, 2, nullptr, aspect)},
        style, format);
  }
  const double writing = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  std::fprintf(stderr, "%s queried in %.4f s, written in %.3f s -> %s\n", line, seconds, writing,
               a.output == tools::kStandardOutput ? "standard output" : a.output.c_str());
}

}  // namespace

void add_query_command(CLI::App& app) {
  auto a = std::make_shared<QueryArgs>();
  CLI::App* cmd = app.add_subcommand("query", "Points of a world rectangle from a tile set (the runtime)");
  add_tileset_option(cmd, a->tileset, "Tile-set file ('-': standard input; default: the built-in set)");
  cmd->add_option("--rect", a->rect, "World rectangle x0,y0,x1,y1 in world units (half-open)")->required();
  CLI::Option* density =
      cmd->add_option(
             "--density", a->density,
             "const:V (V >= 0), an image (density = 1 - luminance, 0.2126 R + 0.7152 G + 0.0722 B of the "
             "file's values, alpha on white; dark = dense; a Radiance .hdr keeps its range, scaled by its "
             "brightest pixel), a test map ramp:R or radial:R (dynamic range R), or a NumPy .npy 2-D array "
             "of densities (rows, columns; row 0 at the top, as kdm sample takes it), stretched over "
             "--density-rect (past it the edge texels go on); '-' reads the image or array from standard "
             "input")
          ->capture_default_str();
  cmd->add_option(
         "--class", a->classes,
         "Several classes in one query (instead of --density): repeat it, one density each, the "
         "first given first place (largest objects first), up to 8; every point gets a class "
         "(a class column in .csv/.json, a colour in pictures, a group per class in .svg); by default "
         "one class, --density. Colours: " +
             std::string(tools::kClassInkNames))
      ->take_all();
  cmd->add_option(
      "--density-rect", a->density_rect,
      "World rectangle x0,y0,x1,y1 the image or test map covers (default: --rect, so that a chunk queried "
      "without it stretches the whole map over itself); fix it to query chunks of one region and get "
      "exactly the region's points. Past it the map's edge goes on");
  cmd->add_option("--gamma", a->gamma, "Exponent applied to image darkness")->capture_default_str();
  cmd->add_flag("--invert", a->invert, "Bright image areas are dense");
  cmd->add_option("--scale", a->scale, "Points per world unit area at density 1")->capture_default_str();
  cmd->add_option("--tile-size", a->tile_size, "World units per tile side")->capture_default_str();
  cmd->add_option("--mode", a->mode,
                  "stable: points never move once they appear (placing objects); smooth: points glide with "
                  "the density, so every density is good blue noise (stippling, sample patterns)")
      ->check(CLI::IsMember({"stable", "smooth"}))
      ->capture_default_str();
  cmd->add_flag("--glide-together", a->glide_together,
                "Smooth mode with a varying density: each point glides by the most density around it, so "
                "neighbours do not close up where the density changes from dot to dot (pictures, textures); "
                "about twice as slow");
  cmd->add_flag("--normalised", a->normalised,
                ".csv/.json coordinates in [0, 1) of --rect instead of world units");
  cmd->add_option("-o,--output", a->output,
                  "Output: .csv or .json (world x, y, tile_x, tile_y, rank, level[, class], depth: with "
                  "tile_x, tile_y and rank the point's id), .txt (UTK format, "
                  "normalised to the rect), .svg or .png; - for standard output (with --format)")
      ->required();
  add_format_option(cmd, a->format, kQueryFormats);
  cmd->callback([a, density] { run_query_command(*a, density->count() > 0); });
}

}  // namespace kdm::cli
