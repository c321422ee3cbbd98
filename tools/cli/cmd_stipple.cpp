// `kdm stipple`: texture-space stippling of an image, by the runtime and the built-in tile set (fast,
// zoom-coherent) or by the full KDM sampler (highest fidelity).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "commands.h"
#include "density_arg.h"
#include "output.h"
#include "runtime_args.h"
#include "stipple_full.h"

namespace kdm::cli {
namespace {

struct StippleArgs {
  std::string image, output, method = "tiles", region, tileset, mode = "smooth";
  std::int64_t points = 20000;
  double scale = 0, gamma = 1, dot_size = 0;
  bool invert = false;
  int width_px = 1024;
  int frames = 0;
  std::uint64_t seed = 1;
};

/// "x0,y0,x1,y1" in UV units (y up), inside [0, 1]².
void parse_region(const std::string& text, double r[4]) {
  parse_rect(text, "--region", r);
  if (!(r[0] >= 0 && r[1] >= 0 && r[2] <= 1 && r[3] <= 1))
    throw CommandError("--region must be x0,y0,x1,y1 with 0 <= x0 < x1 <= 1 and 0 <= y0 < y1 <= 1, got '" +
                       text + "'");
}

/// The UV rectangle of frame i of k, zooming from the whole image (frame 0) into `region` (frame k-1):
/// the zoom grows geometrically (the same factor every frame) and each rectangle lies inside the one
/// before, so the runtime's zoom coherence keeps every dot that stays in view.
void frame_region(const double region[4], int i, int k, double out[4]) {
  const double last = std::max(region[2] - region[0], region[3] - region[1]);  // 1 / final zoom
  const double extent = std::pow(last, k > 1 ? double(i) / (k - 1) : 1.0);     // 1 / this frame's zoom
  const double s = last < 1 ? (1 - extent) / (1 - last) : 1;                   // 0: whole image, 1: region
  for (int j = 0; j < 2; ++j) {
    out[j] = s * region[j];
    out[j + 2] = 1 + s * (region[j + 2] - 1);
  }
  if (i == k - 1) std::copy(region, region + 4, out);  // exactly the region, whatever the rounding
}

/// OUT.png -> OUT_0007.png (the frame number before the extension).
std::string frame_path(const std::string& output, int i) {
  const std::size_t slash = output.find_last_of('/'), dot = output.find_last_of('.');
  const std::size_t at =
      dot != std::string::npos && (slash == std::string::npos || dot > slash) ? dot : output.size();
  char number[16];
  std::snprintf(number, sizeof number, "_%04d", i);
  return output.substr(0, at) + number + output.substr(at);
}

/// The runtime (tiles) method: the dots of one UV rectangle of the image, normalised to the rectangle.
class TileStippler {
 public:
  TileStippler(const StippleArgs& a, const tools::DensitySpec& spec, double aspect)
      : tiles_(tileset_for(a.tileset, storage_)), aspect_(aspect), mode_(parse_mode(a.mode)) {
    density_ = make_runtime_density(spec, 0, 0, aspect, 1);
    // The scale that gives --points over the whole image (∫ρ dA = mean · aspect).
    scale_ = a.points > 0 ? a.points / (density_->mean_value * aspect) : a.scale;
    // Tiles small enough that 4× the image's peak density (a 2× zoom with --region) fits the top level.
    // The tile size depends on the whole image only, so every region and frame sees the same points.
    tile_size_ = std::sqrt(tiles_.max_points_per_tile() / (4 * scale_ * density_->max_value));
  }

  tools::PointSet render(const double uv[4]) const {
    const double zoom = 1 / std::max(uv[2] - uv[0], uv[3] - uv[1]);
    if (zoom > 2 + 1e-9) throw CommandError("--region zooms more than 2× (the tile set's density range)");
    QueryParams q;
    q.x0 = uv[0] * aspect_, q.y0 = uv[1], q.x1 = uv[2] * aspect_, q.y1 = uv[3];
    q.origin_x = q.x0, q.origin_y = q.y0;
    q.tile_size = tile_size_;
    q.scale = scale_ * zoom * zoom;  // the same dots on screen, so the zoomed view shows more of them
    q.density = density_->density;
    q.mode = mode_;
    std::vector<QueryPoint> points;
    query_all(tiles_, q, points);
    const double rect[4] = {q.x0, q.y0, q.x1, q.y1};
    return normalise_to_rect(points, rect);
  }

 private:
  Tileset storage_;
  const Tileset& tiles_;
  double aspect_, scale_ = 0, tile_size_ = 1;
  QueryMode mode_;
  std::unique_ptr<RuntimeDensity> density_;
};

void run_stipple(const StippleArgs& a) {
  if (a.points <= 0 && a.scale <= 0) throw CommandError("give --points N > 0 or --scale S > 0");
  if (a.frames < 0 || a.frames == 1 || a.frames > 10000)
    throw CommandError("--frames must be 0 (one picture) or a count from 2 to 10000, got " +
                       std::to_string(a.frames));
  if (a.frames > 0 && a.region.empty()) throw CommandError("--frames needs --region (where the zoom ends)");
  if (!(a.width_px >= 1 && a.width_px <= 65536)) throw CommandError("--width must be 1 to 65536 pixels");
  if (!(a.dot_size >= 0 && std::isfinite(a.dot_size))) throw CommandError("--dot-size must be >= 0");
  const tools::DensitySpec spec = parse_density(a.image, a.gamma, a.invert);
  if (spec.kind != tools::DensitySpec::Kind::kImage)
    throw CommandError("kdm stipple needs an image; for a constant density use kdm sample");
  if (!(spec.max_value() > 0))
    throw CommandError("image '" + a.image + "' has no ink: nothing to stipple" +
                       (a.invert ? "" : " (an all-white image has no ink)"));
  const double aspect = double(spec.width) / spec.height;  // world: [0, aspect] × [0, 1]
  double region[4] = {0, 0, 1, 1};
  if (!a.region.empty()) parse_region(a.region, region);
  if (a.method == "full" && !a.region.empty())
    throw CommandError("--region needs --method tiles (the full sampler has no zoom)");
  if (1 / std::max(region[2] - region[0], region[3] - region[1]) > 2 + 1e-9)  // before writing any frame
    throw CommandError("--region zooms more than 2× (the tile set's density range)");
  std::unique_ptr<TileStippler> stippler;
  if (a.method != "full") stippler = std::make_unique<TileStippler>(a, spec, aspect);
  const int frames = std::max(1, a.frames);
  double dot_radius = a.dot_size;  // pixels; fixed by the whole image's dot count, so zoomed dots keep it
  for (int i = 0; i < frames; ++i) {
    double uv[4];
    if (a.frames > 0)
      frame_region(region, i, frames, uv);
    else
      std::copy(region, region + 4, uv);
    const auto t0 = std::chrono::steady_clock::now();
    tools::PointSet set;
    set.dim = 2;
    std::string how;
    if (a.method == "full") {
      set = stipple_full(spec, a.points > 0 ? a.points : std::llround(a.scale * aspect), aspect, a.seed);
      how = "full KDM sampler";
    } else {
      set = stippler->render(uv);
      how = "runtime tiles";
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (dot_radius <= 0) {
      const double full = a.points > 0 ? double(a.points) : double(set.size());
      dot_radius = 0.25 * std::sqrt(double(a.width_px) * (a.width_px / aspect) / std::max(1.0, full));
    }
    DrawStyle style;
    style.width_px = a.width_px;
    style.aspect = aspect * (uv[2] - uv[0]) / (uv[3] - uv[1]);
    style.dot_radius_px = dot_radius;
    char line[200], where[160];
    std::snprintf(line, sizeof line, "kdm stipple: %zu dots (%s)", set.size(), how.c_str());
    std::snprintf(where, sizeof where, "region %.17g,%.17g,%.17g,%.17g", uv[0], uv[1], uv[2], uv[3]);
    const std::string path = a.frames > 0 ? frame_path(a.output, i) : a.output;
    write_points(path, set, {line, "image " + a.image, where}, style);
    std::fprintf(stderr, "%s in %.3f s -> %s\n", line, seconds, path.c_str());
  }
}

}  // namespace

void add_stipple_command(CLI::App& app) {
  auto a = std::make_shared<StippleArgs>();
  CLI::App* cmd = app.add_subcommand("stipple", "Stipple an image: darkness becomes dot density");
  cmd->add_option("image", a->image, "Image (8/16-bit PNG, JPEG, ...); darkness is the dot density")
      ->required();
  cmd->add_option("-o,--output", a->output,
                  "Output: .png (antialiased dots), .svg (circles) or .txt/.csv points (normalised to the "
                  "rendered rectangle); with --frames, OUT_0000.png, OUT_0001.png, ...")
      ->required();
  cmd->add_option("--points", a->points, "Dots over the whole image")->capture_default_str();
  cmd->add_option("--scale", a->scale,
                  "Dots per unit area at full darkness (image height = 1 unit); overrides --points "
                  "(default: unset, --points decides)");
  cmd->add_option("--method", a->method, "tiles: runtime + tile set (fast); full: the full KDM sampler")
      ->check(CLI::IsMember({"tiles", "full"}))
      ->capture_default_str();
  cmd->add_option("--region", a->region,
                  "x0,y0,x1,y1 in the image's UV square [0,1]² (y up): render that part at the same dot "
                  "size with more dots, zoom at most 2× (default: the whole image)");
  cmd->add_option("--frames", a->frames,
                  "Zoom sequence of K numbered pictures from the whole image into --region (geometric "
                  "zoom, zoom-coherent; needs --method tiles; 0: one picture)")
      ->capture_default_str();
  cmd->add_option("--width", a->width_px, "Picture width in pixels (.png/.svg)")->capture_default_str();
  cmd->add_option("--dot-size", a->dot_size,
                  "Dot radius in pixels (default: a quarter of the whole image's mean dot spacing)");
  cmd->add_option("--gamma", a->gamma, "Exponent applied to darkness (> 1 lightens mid-tones)")
      ->capture_default_str();
  cmd->add_flag("--invert", a->invert, "Bright areas get the dots (default: dark areas)");
  cmd->add_option("--seed", a->seed, "Random seed for --method full")->capture_default_str();
  cmd->add_option("--tileset", a->tileset, "Tile-set file for --method tiles (default: the built-in set)");
  cmd->add_option("--mode", a->mode,
                  "--method tiles: smooth (dots glide with the density: good blue noise at every tone) or "
                  "stable (dots never move as the density or zoom changes)")
      ->check(CLI::IsMember({"stable", "smooth"}))
      ->capture_default_str();
  cmd->callback([a] {
    if (a->scale > 0) a->points = 0;
    run_stipple(*a);
  });
}

}  // namespace kdm::cli
