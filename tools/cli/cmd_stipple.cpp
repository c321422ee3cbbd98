// `kdm stipple`: texture-space stippling of an image, by the runtime and the built-in tile set (fast,
// zoom-coherent) or by the full KDM sampler (highest fidelity).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>

#include "checked_options.h"
#include "colour_separation.h"
#include "commands.h"
#include "density_arg.h"
#include "full_stippler.h"
#include "point_output.h"
#include "runtime_args.h"
#include "tile_stippler.h"

namespace kdm::cli {
namespace {

using tools::kStippleFormats;  // kdm.stipple writes the same

struct StippleArgs {
  std::string image, output, format, method = "tiles", region, tileset, mode = "smooth", colours, paper_width;
  std::int64_t points = 20000;
  double scale = 0, gamma = 1, dot_size = 0, fade = 0;
  double white = 0;  // a Radiance picture's luminance that is white; 0: its brightest pixel's
  bool invert = false;
  int width_px = 1024, height_px = 0;
  std::int64_t frames = 0;  // wide, so that any count is refused by name, not by the option's parser
  int threads = 0;
  std::uint64_t seed = 1;
  std::vector<std::string> picture_options;  // --width, --height, --dot-size as given: pictures only
};

/// "x0,y0,x1,y1" in UV units (y up): meeting [0, 1]² for one picture (past the image is blank paper, as a
/// zoom's first frames show, so a frame's printed region draws that frame again), inside it for a zoom's
/// last frame.
void parse_region(const std::string& text, bool zoom, double r[4]) {
  parse_rect(text, "--region", r);
  if (zoom && !(r[0] >= 0 && r[1] >= 0 && r[2] <= 1 && r[3] <= 1))
    throw CommandError(
        "--region must be x0,y0,x1,y1 with 0 <= x0 < x1 <= 1 and 0 <= y0 < y1 <= 1 for "
        "--frames (where the zoom ends), got '" +
        text + "'");
  if (!(r[0] < 1 && r[1] < 1 && r[2] > 0 && r[3] > 0))
    throw CommandError("--region must meet the image's square [0,1]², got '" + text + "'");
}

/// The first `n` bytes of the file `path` (fewer for a shorter file, none for one that does not open).
std::string first_bytes(const std::string& path, std::size_t n) {
  std::string bytes(n, '\0');
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"), std::fclose);
  bytes.resize(file ? std::fread(bytes.data(), 1, n, file.get()) : 0);
  return bytes;
}

/// OUT.png -> OUT_0007.png (the frame number before the extension); a name holding a printf-style
/// number, as ffmpeg takes it ("frame_%04d.png", "f%d.png"), gets the number there instead.
std::string frame_path(const std::string& output, int i) {
  const std::size_t slash = output.find_last_of('/');
  const std::size_t percent = output.find('%', slash == std::string::npos ? 0 : slash + 1);
  if (percent != std::string::npos) {
    std::size_t end = percent + 1;
    if (end < output.size() && output[end] == '0') ++end;
    while (end < output.size() && end - percent < 4 && std::isdigit(static_cast<unsigned char>(output[end])))
      ++end;
    if (end < output.size() && output[end] == 'd') {
      const int width =
          end > percent + 1 ? std::atoi(output.c_str() + percent + (output[percent + 1] == '0' ? 2 : 1)) : 0;
      char number[24];
      std::snprintf(number, sizeof number, output[percent + 1] == '0' ? "%0*d" : "%*d", width, i);
      return output.substr(0, percent) + number + output.substr(end + 1);
    }
  }
  const std::size_t dot = output.find_last_of('.');
  const std::size_t at =
      dot != std::string::npos && (slash == std::string::npos || dot > slash) ? dot : output.size();
  char number[16];
  std::snprintf(number, sizeof number, "_%04d", i);
  return output.substr(0, at) + number + output.substr(at);
}

void run_stipple(const StippleArgs& a, bool scale_given) {
  const std::string format = check_output_option(a.output, kStippleFormats, a.format);  // before the dots
  refuse_picture_options(a.picture_options, format);
  if (a.frames < 0 || a.frames == 1 || a.frames > 10000)  // before anything loops over them
    throw CommandError("--frames must be 0 (one picture) or a count from 2 to 10000, got " +
                       std::to_string(a.frames));
  if (a.frames > 0 && a.output == tools::kStandardOutput)
    throw CommandError("--frames writes a file per frame: give -o a file name, not - (standard output)");
  for (int i = 0; i < std::max(1, int(a.frames)); ++i)
    tools::refuse_writing_over(a.image, a.frames > 0 ? frame_path(a.output, i) : a.output, "input image");
  if (scale_given && !(a.scale > 0 && std::isfinite(a.scale)))
    throw CommandError("--scale must be a finite number > 0 (dots per unit area at full darkness)");
  if (!scale_given && a.points <= 0) throw CommandError("give --points N > 0 or --scale S > 0");
  if (a.frames > 0 && a.region.empty()) throw CommandError("--frames needs --region (where the zoom ends)");
  if (!(a.fade >= 0 && a.fade <= 10)) {
    char message[120];
    std::snprintf(message, sizeof message, "--fade must be a fraction of density from 0 (off) to 10, got %g",
                  a.fade);
    throw CommandError(message);
  }
  if (!a.colours.empty() && format == ".txt")  // said before the dots are placed
    throw CommandError(
        "--colours writes each dot's ink as a class: write .csv (x,y,class[,id]), .svg or .png");
  if (a.fade > 0 && a.method == "full") throw CommandError("--fade needs --method tiles (dots that appear)");
  if (a.fade > 0 && format != ".png" && format != ".svg")
    throw CommandError("--fade grows dots in pictures: write .png or .svg (points files have no dot sizes)");
  if (!(a.width_px >= 1 && a.width_px <= 65536)) throw CommandError("--width must be 1 to 65536 pixels");
  if (!(a.height_px >= 0 && a.height_px <= 65536)) throw CommandError("--height must be 1 to 65536 pixels");
  if (!a.paper_width.empty()) {
    if (format != ".svg") throw CommandError("--paper-width sizes an SVG for print: write .svg");
    try {
      tools::check_paper_width(a.paper_width);
    } catch (const std::invalid_argument& e) {
      throw CommandError(std::string("--paper-width ") + e.what());
    }
  }
  check_one_standard_input({{"the image", a.image}, {"--tileset", a.tileset}});
  // "-": the image piped in, read once (the loaders below read these bytes).
  const bool piped = a.image == "-";
  const std::vector<std::uint8_t> piped_bytes = piped ? standard_input_bytes() : std::vector<std::uint8_t>{};
  const std::string named = piped ? kStandardInputName : a.image;  // in messages
  if (a.white > 0) {                                               // given (checked as it was read)
    const std::string start =
        piped ? std::string(piped_bytes.begin(),
                            piped_bytes.begin() + std::min<std::size_t>(16, piped_bytes.size()))
              : first_bytes(a.image, 16);
    // (An empty or missing file is left to the loader to name.)
    if (!start.empty() && !tools::is_radiance(start.data(), start.size()))
      throw CommandError("--white sets the luminance that is white in a Radiance .hdr picture, and '" +
                         named + "' is none (its white is already its format's)");
  }
  if (!(a.dot_size >= 0 && std::isfinite(a.dot_size)))
    throw CommandError("--dot-size must be a finite number >= 0");
  double region[4] = {0, 0, 1, 1};
  if (!a.region.empty()) parse_region(a.region, a.frames > 0, region);
  // A large picture is averaged down to what its dots can show, at the deepest zoom drawn.
  const tools::KeptPixels kept = tools::stipple_kept_pixels(
      scale_given ? 0.0 : double(a.points), scale_given ? a.scale : 0.0, tools::stipple_zoom(region));
  const auto load_colours = [&](tools::ColourImage& image, std::string& error) {
    return piped ? tools::load_colour_image_memory(piped_bytes.data(), piped_bytes.size(), image, error,
                                                   named, tools::kMaxStipplePixels, kept, a.white)
                 : tools::load_colour_image(a.image, image, error, tools::kMaxStipplePixels, kept, a.white);
  };
  // One ink (the image's darkness), or with --colours the image separated into several.
  tools::ColourSeparation inks;
  double aspect = 1;  // world: [0, aspect] × [0, 1]
  if (a.colours.empty()) {
    const bool named_map = a.image.rfind("const:", 0) == 0 || a.image.rfind("ramp:", 0) == 0 ||
                           a.image.rfind("radial:", 0) == 0;  // refused below: stipple needs an image
    std::error_code missing;  // said as --colours' loader says it, not "a density is a picture, const:V, …"
    if (!named_map && !piped && !std::filesystem::exists(a.image, missing))
      throw CommandError("cannot read image '" + a.image +
                         "': " + (missing ? missing.message() : std::string(std::strerror(ENOENT))));
    if (piped) {
      check_gamma(a.gamma);
      try {
        inks.channels.push_back(tools::parse_density_bytes(piped_bytes.data(), piped_bytes.size(), named,
                                                           a.gamma, a.invert, tools::kMaxStipplePixels, kept,
                                                           a.white));
      } catch (const std::exception& e) {  // a bad value, or an image that cannot be read
        throw CommandError(e.what());
      }
    } else {
      inks.channels.push_back(
          parse_density(a.image, a.gamma, a.invert, tools::kMaxStipplePixels, kept, a.white));
    }
    inks.inks = tools::class_inks(1);
    const tools::DensitySpec& spec = inks.channels.front();
    if (spec.kind == tools::DensitySpec::Kind::kVolume)
      throw CommandError("kdm stipple needs an image, and '" + named +
                         "' is a 3-D volume (kdm sample --dim 3)");
    if (spec.kind != tools::DensitySpec::Kind::kImage)
      throw CommandError("kdm stipple needs an image; for a constant density use kdm sample");
    aspect = double(spec.width) / spec.height;
    if (!(spec.max_value() > 0)) inks.channels.clear();  // no ink: an empty picture, below
  } else {
    if (a.invert) throw CommandError("--invert does not apply to --colours (each ink has its own channel)");
    // An array of densities has no colours to separate: said so, not as an image of no known type.
    const std::string start =
        piped ? std::string(piped_bytes.begin(),
                            piped_bytes.begin() + std::min<std::size_t>(6, piped_bytes.size()))
              : first_bytes(a.image, 6);
    if (start == "\x93NUMPY")
      throw CommandError("--colours separates a picture's colours, and '" + named +
                         "' is a NumPy array of densities: stipple it without --colours");
    tools::ColourImage image;
    std::string error;
    if (!load_colours(image, error)) throw CommandError(error);
    check_gamma(a.gamma);
    try {
      inks = tools::separate_colours(image, a.colours, a.gamma);
    } catch (const std::invalid_argument& e) {
      throw CommandError(e.what());
    }
    aspect = double(image.width) / image.height;
  }
  const bool coloured = !a.colours.empty();
  std::vector<const tools::DensitySpec*> specs;
  for (const tools::DensitySpec& channel : inks.channels) specs.push_back(&channel);
  const bool blank = specs.empty();  // a white image (a black one with --invert): no dots, not an error
  const double whole_dots = blank ? 0.0 : tools::stipple_dot_count(specs, double(a.points), a.scale);
  if (a.method == "full" && !a.region.empty())
    throw CommandError("--region needs --method tiles (the full sampler has no zoom)");
  Tileset storage;
  const Tileset& tiles = tileset_for(a.tileset, storage);
  if (a.method != "full" &&  // before any frame
      tools::stipple_zoom(region) > tools::max_stipple_zoom(tiles, parse_mode(a.mode)) * (1 + 1e-9))
    throw CommandError(tools::stipple_zoom_error("--region", tiles, parse_mode(a.mode)));
  if (a.method != "full") warn_without_glide_track("kdm stipple", tiles, parse_mode(a.mode));
  std::unique_ptr<tools::TileStippler> stippler;
  if (blank) {
    // Said as the image is: every pixel transparent (paper), or white.
    tools::ColourImage probe;
    std::string unread;
    const bool transparent =
        load_colours(probe, unread) && !probe.alpha.empty() &&
        std::all_of(probe.alpha.begin(), probe.alpha.end(), [](float alpha) { return alpha == 0; });
    std::fprintf(stderr, "kdm stipple: image '%s' has no ink%s%s: no dots\n", named.c_str(),
                 coloured ? " in any colour" : "",
                 transparent            ? " (it is all transparent)"
                 : coloured || a.invert ? ""
                                        : " (it is all white)");
  }
  if (!blank && a.method != "full") {
    stippler = std::make_unique<tools::TileStippler>(specs, tiles, double(a.points), a.scale,
                                                     parse_mode(a.mode), a.seed);
    // As kdm query says a tile size too small: tones under the set's coarsest level come out clumpy.
    // Said for the least zoomed picture (deeper ones ask more points per tile).
    double first[4];
    if (a.frames > 0)
      tools::stipple_frame_region(region, 0, int(a.frames), first);
    else
      std::copy(region, region + 4, first);
    const std::string thin = tools::TileStippler::thin_tones_warning(
        stippler->thin_tones(tools::stipple_zoom(first)), "--gamma", !a.tileset.empty());
    if (!thin.empty()) std::fprintf(stderr, "kdm stipple: warning: %s\n", thin.c_str());
  }
  if (coloured && !blank) {  // which ink each class number of a .csv is, and its colour (a plotter's pen)
    std::string names;
    for (std::size_t k = 0; k < inks.inks.size(); ++k)
      names += (k ? ", " : "") + std::to_string(k) + " " + inks.inks[k].name + " " + inks.inks[k].hex();
    for (std::size_t k = 0; k < inks.unused.size(); ++k)  // still a layer in .svg, for the plotter's pens
      names += (k ? ", " : "; no pixel uses ") + inks.unused[k].name;
    std::fprintf(stderr, "kdm stipple: classes %s\n", names.c_str());
  }
  const int frames = std::max(1, int(a.frames));
  // --height sizes a tall picture (a strip 3 pixels wide and 4,000 high has no --width that fits).
  const double picture_aspect = aspect * (region[2] - region[0]) / (region[3] - region[1]);
  const int width_px =
      a.height_px > 0 ? int(std::clamp(std::lround(a.height_px * picture_aspect), 1L, 1L << 30)) : a.width_px;
  double largest_dot = HUGE_VAL;  // pixels: a quarter of the pictures' shorter side
  std::string picture;            // "WxH", for the message
  if (format == ".png" || format == ".svg")
    for (int i = 0; i < frames; ++i) {  // each frame's picture, before any dot is placed
      double uv[4];
      if (a.frames > 0)
        tools::stipple_frame_region(region, i, frames, uv);
      else
        std::copy(region, region + 4, uv);
      try {
        const int height = tools::check_picture_size(width_px, aspect * (uv[2] - uv[0]) / (uv[3] - uv[1]),
                                                     a.output, format, a.height_px, "--width", "--height");
        if (tools::max_dot_radius(width_px, height) < largest_dot) {
          largest_dot = tools::max_dot_radius(width_px, height);
          picture = std::to_string(width_px) + "x" + std::to_string(height);
        }
      } catch (const std::invalid_argument& e) {
        throw CommandError(e.what());
      }
    }
  // Larger dots would be moved in from the edge by more than the picture can spare (an SVG of a few dots
  // drew them all at its centre), and only blacken it.
  if (a.dot_size > largest_dot)
    throw CommandError("--dot-size " + tools::shortest(a.dot_size) + " is more than a quarter of the " +
                       picture + " picture's shorter side: at most " + tools::shortest(largest_dot) +
                       " pixels");
  double dot_radius = a.dot_size;  // pixels; fixed by the whole image's dot count, so zoomed dots keep it
  for (int i = 0; i < frames; ++i) {
    double uv[4];
    if (a.frames > 0)
      tools::stipple_frame_region(region, i, frames, uv);
    else
      std::copy(region, region + 4, uv);
    const auto t0 = std::chrono::steady_clock::now();
    tools::PointSet set;
    set.dim = 2;
    std::string how;
    if (blank) {
      how = "no ink";
    } else if (a.method == "full") {
      const std::int64_t count = tools::full_stipple_count(whole_dots, a.scale);
      if (coloured) {
        set = tools::stipple_full(specs, count, aspect, a.seed, a.threads);
      } else {
        set = tools::stipple_full(*specs.front(), count, aspect, a.seed, a.threads);
      }
      how = "full KDM sampler";
    } else {
      try {
        set = stippler->render(uv, a.fade);
      } catch (const std::length_error& e) {  // the collecting query's limit, said in stipple's terms
        char message[200];
        std::snprintf(message, sizeof message,
                      "the picture of region %g,%g,%g,%g would hold more than 2^25 dots; lower --points or "
                      "--scale",
                      uv[0], uv[1], uv[2], uv[3]);
        throw CommandError(message);
      }
      how = "runtime tiles";
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (dot_radius <= 0) {
      dot_radius =
          blank ? 1.0 : std::min(tools::stipple_dot_radius(whole_dots, width_px, aspect, specs), largest_dot);
      if (dot_radius < 0.25 && (format == ".png" || format == ".svg"))  // a flat strip's default width
        std::fprintf(stderr,
                     "kdm stipple: warning: dots of radius %.2g pixels are too small to show on %s; raise "
                     "--width or --height, or lower --points\n",
                     dot_radius, picture.empty() ? "the picture" : ("the " + picture + " picture").c_str());
    }
    tools::DrawStyle style;
    style.width_px = width_px;
    style.height_px = a.height_px;
    style.aspect = aspect * (uv[2] - uv[0]) / (uv[3] - uv[1]);
    style.dot_radius_px = dot_radius;
    style.paper_width = a.paper_width;
    style.dots_inside = true;  // for pen plotters
    if (coloured) {
      if (set.classes.empty()) set.classes.assign(set.size(), 0);  // one ink left: a one-class query
      style.classes = &set.classes, style.inks = inks.layers();
      std::copy(inks.background, inks.background + 3, style.background);
      style.blend = inks.blend;
    }
    const std::string line = tools::stipple_summary(set.size(), how, a.colours, inks);
    const std::string where = tools::stipple_region_text(uv);
    const std::string path = a.frames > 0 ? frame_path(a.output, i) : a.output;
    const auto t1 = std::chrono::steady_clock::now();
    std::vector<std::string> header = {line, "image " + (piped ? "- (" + named + ")" : a.image)};
    for (std::string& more : tools::stipple_region_header(uv, style.aspect))
      header.push_back(std::move(more));
    tools::write_points(path, set, header, style, format);
    const double writing = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
    // A frame's region is said too: a .csv frame has no header to hold it.
    std::fprintf(stderr, "%s%s%s placed in %.3f s, written in %.3f s -> %s\n", line.c_str(),
                 a.frames > 0 ? ", " : "", a.frames > 0 ? where.c_str() : "", seconds, writing,
                 path == tools::kStandardOutput ? "standard output" : path.c_str());
  }
}

}  // namespace

void add_stipple_command(CLI::App& app) {
  auto a = std::make_shared<StippleArgs>();
  CLI::App* cmd = app.add_subcommand("stipple", "Stipple an image: darkness becomes dot density");
  cmd->add_option(
         "image", a->image,
         "Image (8/16-bit PNG, JPEG turned as its EXIF orientation says, ...); darkness is the dot "
         "density; transparent pixels are paper. A NumPy .npy 2-D array of densities (rows, columns; row 0 "
         "at the top, as kdm sample takes it) is the density itself (not with --colours). Up to 2^28 pixels "
         "in all (16384x16384): a picture larger than its dots need (about 4096x4096, or 64 pixels per dot, "
         "times the zoom squared; at most 2^26) is averaged down as it is read. '-': standard input")
      ->required();
  cmd->add_option(
         "-o,--output", a->output,
         "Output: .png (antialiased dots), .svg (circles) or .txt/.csv points (normalised to the "
         "rendered rectangle; with tiles a .csv's id column names each dot in every region, frame and "
         "tone, to follow dots across frames); with --frames, OUT_0000.png, OUT_0001.png, ... (or the number "
         "where a printf-style %04d in the name says, as ffmpeg reads a sequence); - for "
         "standard "
         "output (with --format). For pen plotters, .svg has an Inkscape layer per ink, its dots in "
         "drawing order (each the nearest not yet drawn: short pen travel), every dot whole within a "
         "margin as wide as a dot around the picture (coordinates are the PNG's pixels); white paper is no "
         "element (nothing to trace as a frame), other paper (rgb's black) "
         "a layer '% paper (not plotted)' that AxiDraw skips: hide it in other plotter software")
      ->required();
  add_format_option(cmd, a->format, kStippleFormats);
  add_count_option(
      cmd, "--points", a->points,
      "Dots over the whole image: exactly this many with --method full; about this many with tiles "
      "(within 1% from a few thousand where the image has areas of tone; lines and details under a "
      "dot's spacing get fewer, docs/limits.md; a few dozen may be 10% off, and 1 may give none). A pale "
      "image gets as many as a dark one: --scale keeps the tone's absolute darkness");
  cmd->add_option("--scale", a->scale,
                  "Dots per unit area at full darkness (image height = 1 unit); overrides --points. With "
                  "tiles the dots then depend on the scale and seed, not on the picture (where its inks sum "
                  "to at most full darkness): for an animated picture, frames keep their dots where their "
                  "tone stays (--points rescales each frame by its mean tone) (default: unset, --points "
                  "decides)");
  cmd->add_option("--method", a->method, "tiles: runtime + tile set (fast); full: the full KDM sampler")
      ->check(CLI::IsMember({"tiles", "full"}))
      ->capture_default_str();
  cmd->add_option(
      "--region", a->region,
      "x0,y0,x1,y1 in the image's UV square [0,1]² (y up): render that part at the same dot "
      "size with more dots, a zoom of 1 / its width (it may reach past the image, drawn as blank "
      "paper, as a zoom's first frames do; not with --frames); needs --method tiles; zoom at most 2× in "
      "stable mode, in smooth mode as deep as the tile set's "
      "subtiles go (2·m^4×: about 2·10^6 for 32×32 subtiles) (default: the whole image)");
  cmd->add_option("--frames", a->frames,
                  "Zoom sequence of K numbered pictures from the whole image into --region (geometric "
                  "zoom, zoom-coherent; every picture has the region's shape, the first blank beside the "
                  "image where the shapes differ; needs --method tiles; 0: one picture, else 2 to 10000; "
                  "dots glide rather than boil where a frame zooms at most about 1.05x the one before "
                  "(K = 1 + ln(zoom) / 0.05, 140 frames for 1,000x), but the hand-over between depths, "
                  "passed every 32x of zoom within 1.03x, then moves a quarter of the dots by over half "
                  "a spacing in one frame: 1.0125x per frame (K = 1 + ln(zoom) / 0.0125) glides through "
                  "it too, docs/limits.md)")
      ->capture_default_str();
  cmd->add_option(
         "--fade", a->fade,
         "Dots grow in as they appear instead of popping up: a dot's area grows from 0 where it "
         "appears to full once the density there is this fraction higher (e.g. 0.2 for a zoom "
         "sequence; pictures only, which it lightens by about 1 - ln(1 + F) / F: 31% at 1, 64% at 5; a pen "
         "plotter draws a shrunken dot at its pen's width, so leave it off for plots; 0: off)")
      ->capture_default_str();
  CLI::Option* width =
      cmd->add_option(
             "--width", a->width_px,
             "Picture width in pixels (.png/.svg), 1 to 65536; the height, from the picture's shape, is 1 "
             "to 65536 too (size a tall picture by --height), and a PNG holds at most 2^28 pixels in all")
          ->capture_default_str();
  cmd->add_option(
         "--height", a->height_px,
         "Picture height in pixels instead of --width, 1 to 65536 (the width follows the picture's shape: "
         "for tall images; default: unset, --width decides)")
      ->excludes(width);
  cmd->add_option(
      "--paper-width", a->paper_width,
      "SVG only: its printed width, a number and a unit (mm, cm, in, pt, pc, px: 180mm, 7.5in), the "
      "height in proportion; the drawing stays --width pixels wide inside, so dot sizes keep their "
      "share of it (default: --width pixels)");
  cmd->add_option(
      "--dot-size", a->dot_size,
      "Dot radius in pixels, at most a quarter of the picture's shorter side (default, or 0: the size at "
      "which the whole image's dots cover as much of the picture as the image's mean darkness, with "
      "--colours the inks' summed coverage: the picture keeps the image's tone)");
  cmd->add_option(
      "--white", a->white,
      "Radiance .hdr pictures: the luminance (0.2126 R + 0.7152 G + 0.0722 B of the file's linear "
      "values) that is white paper; brighter is white too (default: an HDR picture's brightest "
      "pixel is white, so one small highlight darkens the rest)");
  cmd->add_option("--gamma", a->gamma, "Exponent applied to darkness (> 1 lightens mid-tones)")
      ->capture_default_str();
  cmd->add_flag("--invert", a->invert, "Bright areas get the dots (default: dark areas); not with --colours");
  cmd->add_option(
      "--colours", a->colours,
      "Colour stipple: cmyk (cyan, magenta, yellow, black on white, black by under-colour removal), rgb "
      "(red, green, blue on black), N (up to N = 2-8 inks chosen for the image: its own colours at full "
      "strength, black where it has black, fewer if another would draw it under 5% better or an ink would "
      "hold under 1% of "
      "the ink; one black for a grey image) or your pens as '#rrggbb,#rrggbb,...' (1 to 8). With N inks or "
      "pens each pixel's colour is split over them (the mix of inks side by side nearest its colour: a "
      "gradient is drawn by mixing dots of several inks). One class of dots per ink, all inks together one "
      "blue-noise set; the run prints each class number with its ink's name and colour; .svg has a layer "
      "per ink named as printed (with N inks or pens ink-K-colour, K the class number; an empty layer for "
      "an ink no pixel uses), in class order, but for cmyk and rgb in their fixed printing order (cyan, "
      "magenta, yellow, black; red, green, blue) and for pens in the order given, so a plotter's pens "
      "stay put whatever the image; .csv a "
      "class column; classes: least-used ink first (but inks under a tenth of all ink last), pens may be "
      "separated by ', ' (default: black dots of the image's darkness)");
  add_seed_option(cmd, a->seed,
                  "Random seed: --method full's sampler; --method tiles, where the image lies in the tile "
                  "set's endless tiling (another seed, other dots; one seed, the same dots in every region "
                  "and frame)");
  add_tileset_option(cmd, a->tileset,
                     "Tile-set file for --method tiles ('-': standard input; default: the built-in set)");
  cmd->add_option("--mode", a->mode,
                  "--method tiles: smooth (dots glide with the density: good blue noise at every tone) or "
                  "stable (dots never move as the density or zoom changes)")
      ->check(CLI::IsMember({"stable", "smooth"}))
      ->capture_default_str();
  add_threads_option(cmd, a->threads,
                     "--method full's sampler (the dots do not depend on it; tiles use one)");
  cmd->callback([a, cmd] {
    const bool scale_given = cmd->get_option("--scale")->count() > 0;
    // Given as 0, --height reads as unset: say so rather than draw at the default size.
    if (cmd->get_option("--height")->count() > 0 && a->height_px < 1)
      throw CommandError("--height must be 1 to 65536 pixels");
    if (cmd->get_option("--white")->count() > 0 && !(a->white > 0 && std::isfinite(a->white)))
      throw CommandError("--white must be a finite number > 0 (the luminance that is white), got " +
                         tools::shortest(a->white));
    a->picture_options = options_given(cmd, {"--width", "--height", "--dot-size"});
    if (scale_given) a->points = 0;
    if (a->method == "full")  // options the full sampler would ignore
      for (const char* tiles_only : {"--mode", "--tileset"})
        if (cmd->get_option(tiles_only)->count() > 0)
          throw CommandError(std::string(tiles_only) +
                             " applies to --method tiles (the full sampler has no tiles)");
    run_stipple(*a, scale_given);
  });
}

}  // namespace kdm::cli
