// `kdm stipple`: texture-space stippling of an image, by the runtime and the built-in tile set (fast,
// zoom-coherent) or by the full KDM sampler (highest fidelity).
#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>

#include "commands.h"
#include "density_arg.h"
#include "kdm/generator/sampler.h"
#include "output.h"
#include "runtime_args.h"

namespace kdm::cli {
namespace {

struct StippleArgs {
  std::string image, output, method = "tiles", region, tileset;
  std::int64_t points = 20000;
  double scale = 0, gamma = 1, dot_size = 0;
  bool invert = false;
  int width_px = 1024;
  std::uint64_t seed = 1;
};

/// "x0,y0,x1,y1" in UV units (y up), inside [0, 1]².
void parse_region(const std::string& text, double r[4]) {
  std::istringstream in(text);
  char comma;
  if (!(in >> r[0] >> comma >> r[1] >> comma >> r[2] >> comma >> r[3]) || !(r[0] >= 0 && r[1] >= 0) ||
      !(r[2] <= 1 && r[3] <= 1) || !(r[2] > r[0] && r[3] > r[1]))
    throw CommandError("--region must be x0,y0,x1,y1 with 0 <= x0 < x1 <= 1 and 0 <= y0 < y1 <= 1, got '" +
                       text + "'");
}

void run_stipple(const StippleArgs& a) {
  if (a.points <= 0 && a.scale <= 0) throw CommandError("give --points N > 0 or --scale S > 0");
  const DensityArg arg = parse_density(a.image, a.gamma, a.invert);
  if (!arg.from_image)
    throw CommandError("kdm stipple needs an image; for a constant density use kdm sample");
  const double aspect = double(arg.image_width) / arg.image_height;  // world: [0, aspect] × [0, 1]
  double uv[4] = {0, 0, 1, 1};
  if (!a.region.empty()) parse_region(a.region, uv);
  const auto t0 = std::chrono::steady_clock::now();
  tools::PointSet set;
  set.dim = 2;
  std::string how;
  if (a.method == "full") {
    if (!a.region.empty()) throw CommandError("--region needs --method tiles (the full sampler has no zoom)");
    gen::SamplerOptions o;
    o.n = a.points > 0 ? a.points : std::llround(a.scale * aspect);
    o.domain = gen::Domain::kBox;
    o.extent[0] = aspect;
    o.seed = a.seed;
    try {
      set.coords = gen::sample(o, arg.density).points;
    } catch (const gen::InvalidArgument& e) {
      throw CommandError(e.what());
    }
    how = "full KDM sampler";
  } else {
    Tileset storage;
    const Tileset& tiles = tileset_for(a.tileset, storage);
    const auto density = make_runtime_density(arg, 0, 0, aspect, 1);
    // The scale that gives --points over the whole image (∫ρ dA = mean · aspect).
    const double scale = a.points > 0 ? a.points / (density->mean_value * aspect) : a.scale;
    // Tiles small enough that 4× the image's peak density (a 2× zoom with --region) fits the top level.
    const double tile_size = std::sqrt(tiles.max_points_per_tile() / (4 * scale * density->max_value));
    const double zoom = 1 / std::max(uv[2] - uv[0], uv[3] - uv[1]);
    QueryParams q;
    q.x0 = uv[0] * aspect, q.y0 = uv[1], q.x1 = uv[2] * aspect, q.y1 = uv[3];
    q.origin_x = q.x0, q.origin_y = q.y0;
    q.tile_size = tile_size;
    q.scale = scale * zoom * zoom;  // the same dots on screen, so the zoomed view shows more of them
    q.density = density->density;
    if (zoom > 2 + 1e-9) throw CommandError("--region zooms more than 2× (the tile set's density range)");
    std::vector<QueryPoint> points;
    query_all(tiles, q, points);
    const double w = q.x1 - q.x0, h = q.y1 - q.y0;
    set.coords.reserve(points.size() * 2);
    for (const QueryPoint& p : points)
      set.coords.insert(set.coords.end(), {std::min(p.x / w, std::nextafter(1.0, 0.0)),
                                           std::min(p.y / h, std::nextafter(1.0, 0.0))});
    how = "runtime tiles";
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  DrawStyle style;
  style.width_px = a.width_px;
  style.aspect = aspect * (uv[2] - uv[0]) / (uv[3] - uv[1]);
  style.dot_radius_px = a.dot_size;
  if (style.dot_radius_px <= 0) {  // from the whole image's dot count, so a zoomed region keeps the dot size
    const double full = a.points > 0 ? double(a.points) : double(set.size());
    style.dot_radius_px = 0.25 * std::sqrt(double(a.width_px) * (a.width_px / aspect) / full);
  }
  char line[200];
  std::snprintf(line, sizeof line, "kdm stipple: %zu dots (%s) in %.3f s", set.size(), how.c_str(), seconds);
  write_points(a.output, set, {line, "image " + a.image}, style);
  std::fprintf(stderr, "%s -> %s\n", line, a.output.c_str());
}

}  // namespace

void add_stipple_command(CLI::App& app) {
  auto a = std::make_shared<StippleArgs>();
  CLI::App* cmd = app.add_subcommand("stipple", "Stipple an image: darkness becomes dot density");
  cmd->add_option("image", a->image, "Image (8/16-bit PNG, JPEG, ...)")->required();
  cmd->add_option("-o,--output", a->output,
                  "Output: .png (antialiased dots), .svg (circles) or .txt/.csv points")
      ->required();
  cmd->add_option("--points", a->points, "Dots over the whole image")->capture_default_str();
  cmd->add_option("--scale", a->scale,
                  "Dots per unit area at full darkness (image height = 1); overrides --points");
  cmd->add_option("--method", a->method, "tiles: runtime + tile set (fast); full: the full KDM sampler")
      ->check(CLI::IsMember({"tiles", "full"}))
      ->capture_default_str();
  cmd->add_option("--region", a->region,
                  "x0,y0,x1,y1 in the image's UV square (y up): render that part, same dot size, more dots");
  cmd->add_option("--width", a->width_px, "Picture width in pixels")->capture_default_str();
  cmd->add_option("--dot-size", a->dot_size, "Dot radius in pixels (default: from the dot count)");
  cmd->add_option("--gamma", a->gamma, "Exponent applied to darkness")->capture_default_str();
  cmd->add_flag("--invert", a->invert, "Bright areas get the dots");
  cmd->add_option("--seed", a->seed, "Seed for --method full")->capture_default_str();
  cmd->add_option("--tileset", a->tileset, "Tile-set file (default: the built-in set)");
  cmd->callback([a] {
    if (a->scale > 0) a->points = 0;
    run_stipple(*a);
  });
}

}  // namespace kdm::cli
