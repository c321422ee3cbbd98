// `kdm sample`: the full KDM sampler from the command line.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "checked_options.h"
#include "commands.h"
#include "density_arg.h"
#include "generator_density.h"
#include "kdm/generator/multiclass.h"
#include "kdm/generator/sampler.h"
#include "point_output.h"
#include "progress.h"

namespace kdm::cli {
namespace {

const std::vector<const char*> kSampleFormats = {".txt", ".csv", ".npy", ".svg", ".png"};

struct SampleArgs {
  gen::SamplerOptions options;
  std::string density = "const:1";
  std::vector<std::string> classes;  ///< --class, repeated: one density per class, class 0 first
  std::string domain;                // empty: box for images, arrays and ramps, torus otherwise
  std::string output, format;
  std::string aspect;  // empty: from the image or volume, or 1
  double gamma = 1;
  bool invert = false;
  bool unadjusted = false;
  bool timing = false;
  int width_px = 1024;
  double dot_radius = 0;
  std::int64_t sets = 1;                     ///< --sets: point sets, seeds --seed, --seed + 1, ...
  std::vector<std::string> picture_options;  ///< --width, --dot-size as given: pictures only
};

/// --aspect: one number, the x side over the others, or in 3D three sides X:Y:Z (their ratios count).
/// Returns the sides (one for a single number); throws CommandError for anything else.
std::vector<double> parse_aspect(const std::string& text, int dim) {
  std::vector<double> sides;
  try {
    sides = parse_sides(text, "--aspect");
  } catch (const CommandError&) {
    if (dim != 3) throw;
    throw CommandError(
        "--aspect must be one number > 0 (the x side over the others) or, in 3D, three sides "
        "X:Y:Z, each > 0; got '" +
        text + "'");
  }
  if (dim == 3 && std::count(text.begin(), text.end(), ':') == 1)
    throw CommandError(
        "--aspect W:H is a 2D domain's shape: in 3D give three sides X:Y:Z, or one number (the "
        "x side over the others)");
  if (sides.size() == 3 && dim != 3)
    throw CommandError(
        "--aspect X:Y:Z sets a 3D domain's sides: add --dim 3, or give one number (width/height)");
  return sides;
}

/// --sets: refuses, before any sampling, what several sets cannot be (a count from --resolution, classes,
/// a picture or CSV file, seeds past 2^64 - 1). Sizes past sample_sets()'s bounds it refuses itself.
void check_sets(const SampleArgs& args, const std::string& format, bool classed) {
  if (args.sets < 1 || args.sets > gen::kMaxSampleSets)
    throw CommandError("--sets must be 1 to " + std::to_string(gen::kMaxSampleSets) + ", got " +
                       std::to_string(args.sets));
  if (args.sets == 1) return;
  if (args.options.n <= 0) throw CommandError("--sets needs --n > 0: every set has that many points");
  if (classed) throw CommandError("--sets draws one class: drop --class, or --sets");
  if (format != ".txt" && format != ".npy")
    throw CommandError(
        "--sets writes .txt (sets separated by '#' lines, as kdm analyze reads them) or .npy " +
        std::string("(a (sets, n, dim) array), not ") + format);
  if (args.options.seed > std::numeric_limits<std::uint64_t>::max() - std::uint64_t(args.sets - 1))
    throw CommandError("--seed " + std::to_string(args.options.seed) + " with --sets " +
                       std::to_string(args.sets) + " runs past the largest seed, 2^64 - 1");
}

/// kdm sample --sets K: K sets with seeds --seed, --seed + 1, ... (gen::sample_sets), each the points
/// `kdm sample --seed S` writes for its seed S, in one file.
void run_sets(const SampleArgs& args, const gen::SamplerOptions& o, const gen::Density& density,
              const std::string& format, const std::string& domain, const double extent[3], double aspect,
              ProgressBar& bar) {
  std::vector<std::uint64_t> seeds(static_cast<std::size_t>(args.sets));
  for (std::size_t k = 0; k < seeds.size(); ++k) seeds[k] = o.seed + k;
  std::vector<gen::SampleResult> results;
  const auto start = std::chrono::steady_clock::now();
  try {
    results = gen::sample_sets(o, density, seeds);
  } catch (const gen::InvalidArgument& e) {
    throw CommandError(e.what());
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  bar.finish();
  std::vector<tools::PointSet> sets(results.size());
  std::vector<std::string> set_headers;
  std::uint64_t proposals = 0, accepted = 0;
  for (std::size_t k = 0; k < results.size(); ++k) {
    sets[k].dim = results[k].dim;
    sets[k].coords = std::move(results[k].points);
    proposals += results[k].report.proposals, accepted += results[k].report.accepted;
    char set_line[96];
    std::snprintf(set_line, sizeof set_line, "set %zu, seed %llu, acceptance %.3f", k,
                  static_cast<unsigned long long>(seeds[k]), results[k].report.acceptance_rate());
    set_headers.push_back(set_line);
  }
  const double acceptance = proposals ? double(accepted) / double(proposals) : 0.0;
  char line[256];
  std::snprintf(
      line, sizeof line,
      "kdm sample: %lld sets of %lld points, T=%g (model %.4g), seeds %llu to %llu, acceptance %.3f",
      static_cast<long long>(args.sets), static_cast<long long>(o.n), o.temperature,
      results.front().report.model_temperature, static_cast<unsigned long long>(seeds.front()),
      static_cast<unsigned long long>(seeds.back()), acceptance);
  std::string error;
  if (!tools::write_point_sets(args.output, sets,
                               {line, "density " + args.density + ", " +
                                          tools::domain_header(domain == "torus", o.dim, extent, aspect)},
                               set_headers, error, format))
    throw std::runtime_error(error);
  std::fprintf(stderr, "%s, %.3f s -> %s\n", line, seconds,
               args.output == tools::kStandardOutput ? "standard output" : args.output.c_str());
  if (args.timing)
    std::printf("sets %lld points_per_set %lld seconds %.4f sets_per_second %.1f threads %d\n",
                static_cast<long long>(args.sets), static_cast<long long>(o.n), seconds,
                double(args.sets) / std::max(1e-9, seconds),
                o.threads > 0 ? o.threads : gen::default_thread_count());
}

void run_sample(const SampleArgs& args, bool density_given, bool aspect_given) {
  const std::string format =
      check_output_option(args.output, kSampleFormats, args.format);  // before sampling
  refuse_picture_options(args.picture_options, format);
  if (args.timing && args.output == tools::kStandardOutput)
    throw CommandError("--timing prints on standard output, which -o - writes the points to: drop one");
  // Range checks here rather than CLI11's validators, whose messages print the whole double range.
  if (args.options.n < 0) throw CommandError("--n must be >= 0 (0: use --resolution)");
  if (args.options.resolution < 0) throw CommandError("--resolution must be >= 0");
  const std::vector<double> sides =
      aspect_given ? parse_aspect(args.aspect, args.options.dim) : std::vector<double>{};
  if (!(args.width_px >= 1 && args.width_px <= 65536))
    throw CommandError("--width must be 1 to 65536 pixels");
  if (!(args.dot_radius >= 0 && std::isfinite(args.dot_radius)))
    throw CommandError("--dot-size must be a finite number >= 0");
  if (density_given && !args.classes.empty())
    throw CommandError("give either --density or --class (one per class), not both");
  if (args.classes.size() > 8)
    throw CommandError("--class given " + std::to_string(args.classes.size()) + " times; at most 8 classes");
  const bool classed = !args.classes.empty();
  if (classed && format == ".npy")
    throw CommandError("--class writes its classes to .csv (x,y,class) or pictures, not .npy");
  if (classed && args.options.n <= 0) throw CommandError("--class needs --n > 0 (the points of all classes)");
  if (classed && args.options.dim != 2) throw CommandError("--class samples 2D points: drop --dim 3");
  check_sets(args, format, classed);
  std::vector<tools::DensitySpec> specs;
  std::vector<std::pair<std::string, std::string>> inputs;
  for (const std::string& text : classed ? args.classes : std::vector<std::string>{args.density})
    inputs.emplace_back(classed ? "--class" : "--density", text);
  check_one_standard_input(inputs);
  for (const std::string& text : classed ? args.classes : std::vector<std::string>{args.density}) {
    tools::refuse_writing_over(text, args.output, "density image");  // a picture written over its input
    specs.push_back(parse_density(text, args.gamma, args.invert));
  }
  std::vector<const tools::DensitySpec*> class_specs;
  for (const tools::DensitySpec& s : specs) class_specs.push_back(&s);
  check_class_images(class_specs);
  check_image_options(class_specs, args.gamma, args.invert);
  bool edged = false;
  const tools::DensitySpec *image = nullptr, *volume = nullptr;
  for (const tools::DensitySpec& s : specs) {
    if (s.kind == tools::DensitySpec::Kind::kImage && !image) image = &s;
    if (s.kind == tools::DensitySpec::Kind::kVolume) volume = &s;
    // A ramp, a picture or a volume has edges that do not meet: a box, unless asked otherwise.
    edged = edged || s.kind == tools::DensitySpec::Kind::kImage ||
            s.kind == tools::DensitySpec::Kind::kRamp || s.kind == tools::DensitySpec::Kind::kVolume;
  }
  if (volume && classed)
    throw CommandError("--class samples 2D points, and '" + volume->text + "' is a 3-D volume");
  if (volume && args.options.dim == 2)
    throw CommandError("density '" + volume->text + "' is a 3-D array (" + std::to_string(volume->depth) +
                       ", " + std::to_string(volume->height) + ", " + std::to_string(volume->width) +
                       "): sample it with --dim 3");
  gen::SamplerOptions o = args.options;
  const std::string domain = args.domain.empty() ? (edged ? "box" : "torus") : args.domain;
  o.domain = domain == "box" ? gen::Domain::kBox : gen::Domain::kTorus;
  // The domain's sides: --aspect's, else an image's width / height, a volume's voxel counts, or a cube.
  double aspect = sides.empty() ? 1 : sides[0];
  double extent[3] = {aspect, 1, 1};
  if (sides.size() == 3) std::copy(sides.begin(), sides.end(), extent);
  if (!aspect_given) {
    for (const tools::DensitySpec& s : specs)
      if (s.kind == tools::DensitySpec::Kind::kImage) {
        aspect = extent[0] = double(s.width) / s.height;
        break;
      }
    if (volume) extent[0] = volume->width, extent[1] = volume->height, extent[2] = volume->depth;
  }
  if (image && o.dim != 2)
    throw CommandError(image->array
                           ? "density '" + image->text + "' is a 2-D array (" +
                                 std::to_string(image->height) + ", " + std::to_string(image->width) +
                                 "): drop --dim 3, or give a 3-D array (depth, height, width)"
                           : std::string("image densities are 2D; drop --dim 3"));
  std::vector<gen::Density> densities;
  for (const tools::DensitySpec& s : specs)
    densities.push_back(classed ? to_class_density(s) : to_generator_density(s));
  std::copy(extent, extent + 3, o.extent);
  if (o.dim == 2 && (format == ".png" || format == ".svg")) try {  // said before the points are placed
      tools::check_picture_size(args.width_px, extent[0] / extent[1], args.output, format, 0, "--width");
    } catch (const std::invalid_argument& e) {
      throw CommandError(e.what());
    }
  o.metropolis = !args.unadjusted;
  if (args.unadjusted)
    std::fprintf(stderr, "kdm: warning: --unadjusted skips the Metropolis-Hastings test; output is biased\n");
  ProgressBar bar("sampling");
  o.progress = [&bar](double f) { bar.update(f); };
  if (args.sets > 1) return run_sets(args, o, densities.front(), format, domain, extent, aspect, bar);
  gen::SampleResult result;
  tools::PointSet set;
  try {
    if (classed) {
      gen::ClassSample labelled = gen::sample_classes(o, densities);
      set.classes = std::move(labelled.classes);
      result.dim = labelled.dim, result.points = std::move(labelled.points);
      // One report for the file's header: the classes' runs summed (their acceptance and time).
      for (const gen::SampleReport& r : labelled.reports) {
        result.report.proposals += r.proposals, result.report.accepted += r.accepted;
        result.report.seconds += r.seconds;
        result.report.model_temperature = r.model_temperature, result.report.threads = r.threads;
      }
    } else {
      result = gen::sample(o, densities.front());
    }
  } catch (const gen::InvalidArgument& e) {
    throw CommandError(e.what());
  }
  bar.finish();
  // --resolution sets the grid and the model the count: too coarse a grid holds no point at all.
  if (result.points.empty())
    throw CommandError("--resolution " + std::to_string(o.resolution) +
                       " is too coarse: the model puts no points on that grid (raise it, or give --n)");
  set.dim = result.dim;
  set.coords = std::move(result.points);
  const gen::SampleReport& r = result.report;
  // The file's header holds only what the inputs determine, so the same options give the same bytes;
  // the time goes to stderr.
  char line[256];
  std::snprintf(line, sizeof line, "kdm sample: %zu points, T=%g (model %.4g), seed %llu, acceptance %.3f",
                set.size(), o.temperature, r.model_temperature, static_cast<unsigned long long>(o.seed),
                r.acceptance_rate());
  std::string what = "density " + args.density;
  if (classed) {
    what = "classes";
    for (const std::string& c : args.classes) what += " " + c;
  }
  // kdm analyze measures in the domain the header names.
  std::vector<std::string> header = {
      line, what + ", " + tools::domain_header(domain == "torus", o.dim, extent, aspect)};
  tools::DrawStyle style;
  style.width_px = args.width_px;
  style.dot_radius_px = args.dot_radius;
  style.aspect = extent[0] / extent[1];  // pictures show x and y
  if (classed) style.classes = &set.classes, style.inks = tools::class_inks(specs.size());
  tools::write_points(args.output, set, header, style, format);
  std::fprintf(stderr, "%s, %.3f s -> %s\n", line, r.seconds,
               args.output == tools::kStandardOutput ? "standard output" : args.output.c_str());
  // A step far too large is rejected almost always: the points stay where the coarser levels put them.
  if (o.step > 0 && r.acceptance_rate() < 0.01)
    std::fprintf(stderr,
                 "kdm sample: warning: %.2f%% of moves were accepted, so the points barely moved; --step %g "
                 "is too large (0, the default, picks the step)\n",
                 100 * r.acceptance_rate(), o.step);
  if (args.timing) {
    std::printf("points %zu seconds %.4f points_per_second %.0f threads %d acceptance %.4f\n", set.size(),
                r.seconds, set.size() / std::max(1e-9, r.seconds), r.threads, r.acceptance_rate());
    std::printf("model seconds %.4f\n", r.model_seconds);
    if (r.count_mismatch_before > 0)
      std::printf("count balance mismatch before %.4f after %.4f\n", r.count_mismatch_before,
                  r.count_mismatch_after);
    for (const gen::LevelReport& l : r.levels) {
      std::string grid = std::to_string(l.grid[0]);
      for (int k = 1; k < set.dim; ++k) grid += "x" + std::to_string(l.grid[k]);
      std::printf("level grid %s points %lld sweeps %d setup %.4f burn_in %.4f sweeps_seconds %.4f\n",
                  grid.c_str(), static_cast<long long>(l.points), l.sweeps, l.setup_seconds,
                  l.burn_in_seconds, l.sweep_seconds);
    }
  }
}

}  // namespace

void add_sample_command(CLI::App& app) {
  auto args = std::make_shared<SampleArgs>();
  CLI::App* cmd = app.add_subcommand("sample", "Draw a point set from the KDM model (the full sampler)");
  gen::SamplerOptions& o = args->options;
  add_count_option(cmd, "-n,--n", o.n, "Exact number of points (0: use --resolution)");
  cmd->add_option("--resolution", o.resolution,
                  "Finest grid nodes along the short axis, used when --n 0 (default: unset)");
  cmd->add_option("--dim", o.dim, "Dimension of the points (2 or 3)")
      ->capture_default_str()
      ->check(CLI::IsMember({2, 3}));
  cmd->add_option(
         "--domain", args->domain,
         "torus (periodic) or box (bounded); default: box for images, .npy arrays and volumes and ramp:R, "
         "torus otherwise")
      ->check(CLI::IsMember({"torus", "box"}));
  cmd->add_option(
      "--aspect", args->aspect,
      "Width/height of the domain, as a number or W:H (in 3D one number is its x side over its y and "
      "z sides), or in 3D its three "
      "sides X:Y:Z (relative lengths, e.g. 2:1:0.5); default: the image's, a volume's voxel counts "
      "W:H:D, or 1");
  cmd->add_option(
         "--temperature,-T", o.temperature,
         "Temperature in the reference implementation's units, 0 to 1000 (0.5 = the paper's look with "
         "the default --sweeps; lower = more ordered down to about 0.1; 0 = deterministic descent; "
         "100 and up near white noise, reached with --sweeps 300)")
      ->capture_default_str();
  add_seed_option(cmd, o.seed, "Random seed; the output depends on nothing else");
  cmd->add_option(
         "--density", args->density,
         "const:V, an image whose darkness is the density (a Radiance .hdr keeps its range, scaled by "
         "its brightest pixel: with --invert, bright is dense), or a test map: ramp:R (R^-x, dynamic "
         "range R) or radial:R (R^-(2r) around the centre, 1/R past r = 0.5; both by x and y alone, so in 3D "
         "a ramp along x and a cylinder along z), or a NumPy .npy array of densities (floats, integers "
         "as their values, or bools): 2-D (rows, columns) as a picture's, row 0 at the top (y near 1), the "
         "last axis x; with "
         "--dim 3 a 3-D volume (depth, height, width), trilinear between voxels, stretched over the domain: "
         "[k] is the slice at z = (k + 0.5) / depth, each slice as a 2-D array; '-' reads the image or array "
         "from standard input")
      ->capture_default_str();
  cmd->add_option("--class", args->classes,
                  "Several classes (instead of --density): repeat it, one density each, highest priority "
                  "first, up to 8; --n counts all of them, split by each density's integral; class k is "
                  "sampled around classes 0 … k-1 at their summed density (a class column in .csv, a colour "
                  "in pictures); by default one class, --density. Colours: " +
                      std::string(tools::kClassInkNames));
  cmd->add_option("--gamma", args->gamma, "Exponent applied to image darkness")->capture_default_str();
  cmd->add_flag("--invert", args->invert, "Bright image areas are dense instead of dark ones");
  add_threads_option(cmd, o.threads, "output does not depend on it");
  add_count_option(
      cmd, "--sets", args->sets,
      "Point sets to draw, 1 to 1048576, with seeds --seed, --seed + 1, ... (each set the points "
      "--sets 1 writes for its seed), run a set per thread: many small sets for Monte Carlo "
      "work; written to .txt with a '#' line before each set (as kdm analyze reads several "
      "sets) or to .npy as a (sets, n, dim) array; needs --n, at most 2^27 points in all")
      ->capture_default_str();
  cmd->add_option("--sweeps", o.sweeps,
                  "Metropolis-Hastings sweeps over all points on the finest level (where that is "
                  "the only level, as for a few hundred points, at least 30: points start there at random); "
                  "more keep ordering a set: δavg .872 at 30, .884 at 100, .897 at 1000 (T = 0.5)")
      ->capture_default_str();
  cmd->add_option("--coarse-sweeps", o.coarse_sweeps,
                  "Metropolis-Hastings sweeps on each level between the coarsest and the finest")
      ->capture_default_str();
  cmd->add_option("--step", o.step, "Langevin step factor (Δt of eq. 5, model units; 0 = automatic)")
      ->capture_default_str();
  cmd->add_flag("--unadjusted", args->unadjusted,
                "Skip the Metropolis-Hastings test (biased; experiments only)");
  cmd->add_option("--width", args->width_px,
                  "Picture width in pixels (.png/.svg), 1 to 65536; a PNG holds at most 2^28 pixels in all")
      ->capture_default_str();
  cmd->add_option("--dot-size", args->dot_radius, "Dot radius in pixels (default: from the point count)");
  cmd->add_flag("--timing", args->timing,
                "Print points per second and each level's time on stdout (default: off)");
  cmd->add_option("--vector-lanes", o.vector_lanes,
                  "Widest vectors the updates use: 16 (AVX-512 where the CPU has it), 8 (AVX2), 4 (SSE2); "
                  "the output is the same")
      ->check(CLI::IsMember({4, 8, 16}))
      ->capture_default_str();
  cmd->add_option(
         "-o,--output", args->output,
         "Output file: .txt (UTK/psa points in [0,1)), .csv (x,y[,z][,class]), .npy (NumPy: an (n, 2) or "
         "(n, 3) float64 array; not with classes), .svg or .png; - for "
         "standard output (with --format)")
      ->required();
  add_format_option(cmd, args->format, kSampleFormats);
  cmd->callback([args, cmd] {
    args->picture_options = options_given(cmd, {"--width", "--dot-size"});
    run_sample(*args, cmd->get_option("--density")->count() > 0, cmd->get_option("--aspect")->count() > 0);
  });
}

}  // namespace kdm::cli
