// `kdm analyze`: point-set metrics (DESIGN.md §6) for one or more files of sets — a one-screen summary on
// stdout, DIR/metrics.json, and pictures DIR/points.png, DIR/spectrum.png, DIR/raps.png.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include "commands.h"
#include "image_io.h"
#include "kdm/analysis/common.h"
#include "kdm/analysis/json.h"
#include "kdm/analysis/plots.h"
#include "kdm/analysis/report.h"

namespace kdm::cli {
namespace {

struct AnalyzeArgs {
  std::vector<std::string> files;
  bool torus = false, box = false;
  std::string density;
  double tile_size = 0;
  double fmax = 2.5;
  double min_expected = 20;
  int threads = 0;
  std::string output;
};

// "const:V" or an image whose darkness (1 − luminance) is the density; y up, image row 0 at the top.
analysis::DensityFunction parse_target_density(const std::string& spec) {
  if (spec.rfind("const:", 0) == 0) {
    const std::string text = spec.substr(6);
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || !std::isfinite(v) || v <= 0)
      throw CommandError("--density const:V needs a finite V > 0, got '" + spec + "'");
    return [v](double, double) { return v; };
  }
  auto image = std::make_shared<tools::GreyImage>();
  std::string error;
  if (!tools::load_grey_image(spec, *image, error)) throw CommandError(error);
  return [image](double x, double y) {
    const int px = std::clamp(static_cast<int>(x * image->width), 0, image->width - 1);
    const int py = std::clamp(static_cast<int>((1.0 - y) * image->height), 0, image->height - 1);
    return 1.0 - static_cast<double>(image->at(px, py));
  };
}

void save_png(const std::string& path, const tools::RgbImage& image) {
  std::string error;
  if (!tools::write_png(path, image, error)) throw CommandError(error);
}

void run_analyze(const AnalyzeArgs& args) {
  if (args.torus && args.box) throw CommandError("--torus and --box are mutually exclusive");
  if (!(args.fmax > 0) || !std::isfinite(args.fmax)) throw CommandError("--fmax must be a positive number");
  if (!(args.min_expected > 0)) throw CommandError("--min-expected must be positive");
  analysis::AnalysisOptions o;
  o.torus = !args.box;
  o.fmax = args.fmax;
  o.min_expected = args.min_expected;
  o.tile_size = args.tile_size;
  o.threads = args.threads;
  try {
    if (args.tile_size != 0) analysis::tiles_per_axis(args.tile_size);
    if (!args.density.empty()) o.density = parse_target_density(args.density);
    const std::vector<tools::PointSet> sets = analysis::load_point_sets(args.files);
    if (sets.front().dim != 2 && (!args.density.empty() || args.tile_size != 0))
      std::fprintf(stderr, "kdm: warning: density and tiling diagnostics are 2D only; skipped\n");
    std::error_code ec;
    std::filesystem::create_directories(args.output, ec);
    if (ec || !std::filesystem::is_directory(args.output))
      throw CommandError("cannot create output directory '" + args.output + "'" +
                         (ec ? ": " + ec.message() : ""));
    const analysis::AnalysisReport report = analysis::analyze(sets, o);
    std::fputs(analysis::format_summary(report).c_str(), stdout);
    const std::filesystem::path dir(args.output);
    std::string error;
    if (!tools::write_text_file_atomic((dir / "metrics.json").string(),
                                       analysis::metrics_json(report, args.files), error))
      throw CommandError(error);
    save_png((dir / "points.png").string(), analysis::plot_points(sets.front()));
    if (report.has_spectrum) {
      save_png((dir / "spectrum.png").string(), analysis::plot_spectrum(report.spectrum));
      save_png((dir / "raps.png").string(), analysis::plot_raps(report.spectrum_stats, report.spectrum.fmax));
    }
    std::fprintf(stderr, "kdm analyze: wrote %s/metrics.json and pictures\n", args.output.c_str());
  } catch (const analysis::InvalidInput& e) {
    throw CommandError(e.what());
  }
}

}  // namespace

void add_analyze_command(CLI::App& app) {
  auto args = std::make_shared<AnalyzeArgs>();
  CLI::App* cmd =
      app.add_subcommand("analyze", "Point-set metrics: NN distances, spectrum, g(r), density, tiling");
  cmd->add_option("files", args->files, "Point files (.txt: one point per line, sets separated by '#' lines)")
      ->required();
  cmd->add_flag("--torus", args->torus, "Periodic distances (default)");
  cmd->add_flag("--box", args->box, "Bounded-box distances (g(r) with edge correction)");
  cmd->add_option("--density", args->density,
                  "Target density for the accuracy test: const:V or an image (dark = dense)");
  cmd->add_option("--tile-size", args->tile_size,
                  "Tile side s (1/s an integer) for periodicity and seam statistics");
  cmd->add_option("--fmax", args->fmax, "Periodogram limit in normalised frequency |k|/sqrt(n)")
      ->capture_default_str();
  cmd->add_option("--min-expected", args->min_expected, "Density windows expect at least this many points")
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "Worker threads (0 = all)")->capture_default_str();
  cmd->add_option("-o,--output", args->output, "Output directory (created if missing)")->required();
  cmd->callback([args] { run_analyze(*args); });
}

}  // namespace kdm::cli
