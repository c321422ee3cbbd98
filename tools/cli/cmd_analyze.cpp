// `kdm analyze`: point-set metrics (docs/design.md §6) for one or more files of sets — a one-screen summary
// on stdout, DIR/metrics.json, and pictures DIR/points.png, DIR/spectrum.png, DIR/raps.png.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <memory>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "atomic_file.h"
#include "checked_options.h"
#include "commands.h"
#include "density_arg.h"
#include "generator_density.h"
#include "kdm/analysis/classes.h"
#include "kdm/analysis/common.h"
#include "kdm/analysis/json.h"
#include "kdm/analysis/plots.h"
#include "kdm/analysis/report.h"
#include "kdm/generator/multiclass.h"
#include "kdm/generator/sampler.h"
#include "picture.h"
#include "sampler_density.h"

namespace kdm::cli {
namespace {

struct AnalyzeArgs {
  std::vector<std::string> files;
  bool torus = false, box = false;
  std::string density;
  std::vector<std::string> class_densities;  ///< --class-density, repeated: one per class, class 0 first
  double gamma = 1;
  bool invert = false;
  bool no_energy = false;
  double tile_size = 0;
  double fmax = 2.5;
  double min_expected = 20;
  int density_bands = 10;
  double holes_min_density = 0;
  int threads = 0;
  std::string aspect;  ///< --aspect: empty, the files' headers say the shape
  std::string output;
  bool tile_size_given = false;  // 0 given is a mistake, not the default
};

void save_png(const std::string& path, const tools::RgbImage& image) {
  std::string error;
  if (!tools::write_png(path, image, error)) throw CommandError(error);
}

/// The classes' own densities (--class-density), as the analysis and the energy take them.
struct ClassTargets {
  std::vector<gen::Density> densities;  ///< as kdm sample --class has them: constants keep their values
  std::vector<analysis::DensityFunction> functions;
};

/// Labelled points (several classes): each class alone, as the whole set was analysed (printed to `text`),
/// and classes.json's text, with the closest pair of points of different classes; with class densities,
/// each class against its own, and the classes' counts against their shares.
std::string analyze_classes(const std::vector<tools::PointSet>& sets, const analysis::AnalysisOptions& o,
                            const gen::Density& target, const ClassTargets& own, const AnalyzeArgs& args,
                            std::FILE* text) {
  analysis::ClassEnergy energy;
  if (!args.no_energy)
    energy = [&](std::uint8_t k, const std::vector<tools::PointSet>& subsets) {
      return tools::mean_energy_per_point(subsets, o.torus,
                                          own.densities.empty() ? target : own.densities[k]);
    };
  const analysis::ClassesReport report = analysis::analyze_classes(sets, o, energy, own.functions);
  std::fprintf(text, "\nclasses: %zu; closest pair of different classes: %.4f %s\n",
               report.classes.size() + report.too_small.size(), report.cross_class_closest,
               !own.functions.empty() ? "local d_hex of all points (of the --class-density sum)"
               : o.density            ? "local d_hex of all points (of --density)"
                                      : "d_hex of all points");
  std::fputs(analysis::format_class_shares(report).c_str(), text);
  for (std::uint8_t k : report.too_small)
    std::fprintf(text, "\nclass %u alone: fewer than 2 points in every set, not analysed\n", unsigned(k));
  for (std::size_t c = 0; c < report.classes.size(); ++c) {
    const unsigned k = report.classes[c];
    if (own.functions.empty())
      std::fprintf(text, "\nclass %u alone:\n", k);
    else
      std::fprintf(text, "\nclass %u alone, against --class-density %s:\n", k,
                   args.class_densities[k].c_str());
    std::fputs(analysis::format_summary(report.reports[c]).c_str(), text);
  }
  return analysis::classes_json(report, args.files);
}

/// metrics.json's text with classes.json's as its key "classes" (as kdm.analyze returns them): one JSON
/// document for standard output.
std::string with_classes(std::string metrics, const std::string& classes) {
  const std::size_t end = metrics.rfind('}');
  if (end == std::string::npos) return metrics;
  std::string inner = classes;
  while (!inner.empty() && (inner.back() == '\n' || inner.back() == ' ')) inner.pop_back();
  return metrics.substr(0, end) + ",\n  \"classes\": " + inner + "\n}\n";
}

/// A domain's relative sides x y z (gen::SamplerOptions::extent) and how the summary names them.
struct Shape {
  double extent[3] = {1, 1, 1};
  std::string text;    ///< "aspect 2" or "sides 2:1:0.5"; "" for a square or cube
  int numbers = 1;     ///< as given: one (an aspect) or three (sides)
  bool named = false;  ///< a file's header named it (else the file says nothing: taken as a square)
  bool square() const { return extent[0] == extent[1] && extent[1] == extent[2]; }
  bool same(const Shape& o) const {  // only the sides' ratios count: 4:2:1 is 2:1:0.5
    for (int i = 1; i < 3; ++i)
      if (std::fabs(extent[i] / extent[0] - o.extent[i] / o.extent[0]) > 1e-12 * (extent[i] / extent[0]))
        return false;
    return true;
  }
};

/// The shape --aspect or a file's header gives (parse_sides); `what` names the source in the error.
Shape parse_shape(const std::string& text, const std::string& what) {
  const std::vector<double> sides = parse_sides(text, what);
  Shape shape;
  shape.numbers = int(sides.size());
  shape.extent[0] = sides[0];
  if (sides.size() == 3) std::copy(sides.begin(), sides.end(), shape.extent);
  char buffer[96];
  if (sides.size() == 3)
    std::snprintf(buffer, sizeof buffer, "sides %g:%g:%g", sides[0], sides[1], sides[2]);
  else
    std::snprintf(buffer, sizeof buffer, "aspect %g", sides[0]);
  if (!shape.square()) shape.text = buffer;
  return shape;
}

/// Standard input's first bytes read ahead, so that its header lines tell its domain as a file's do, and
/// then served again before the rest: the points stream as a file's are (reading it whole first held
/// gigabytes before a bad line was found).
class BufferedStandardInput : private std::streambuf {
 public:
  static constexpr std::size_t kAhead = 4096;  // the header lines lie in the first few
  BufferedStandardInput() : rest_(std::cin.rdbuf()) {
    ahead_.resize(kAhead);
    ahead_.resize(static_cast<std::size_t>(rest_->sgetn(ahead_.data(), std::streamsize(kAhead))));
    setg(ahead_.data(), ahead_.data(), ahead_.data() + ahead_.size());
    std::cin.rdbuf(this);
  }
  ~BufferedStandardInput() override { std::cin.rdbuf(rest_); }
  BufferedStandardInput(const BufferedStandardInput&) = delete;
  BufferedStandardInput& operator=(const BufferedStandardInput&) = delete;
  const std::string& bytes() const { return ahead_; }  ///< the first kAhead bytes (fewer if that is all)

 private:
  int_type underflow() override {
    if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
    const std::streamsize got = rest_->sgetn(chunk_, sizeof chunk_);
    if (got <= 0) return traits_type::eof();
    setg(chunk_, chunk_, chunk_ + got);
    return traits_type::to_int_type(*gptr());
  }
  std::string ahead_;
  std::streambuf* rest_;
  char chunk_[1 << 16];
};

/// A file's domain as its header lines name it (domain_header.h): its shape, a square or cube when they say
/// none (a file of other tools, a .npy), and whether it wraps around ("" when unsaid). "-" is standard
/// input, whose bytes are `standard_input`.
struct SampledDomain {
  Shape shape;
  std::string domain;  ///< "box", "torus" or ""
};

SampledDomain sampled_domain(const std::string& path, const std::string& standard_input) {
  std::ifstream file;
  std::istringstream piped;
  if (path == "-")
    piped.str(standard_input);  // BufferedStandardInput's first bytes
  else
    file.open(path);
  const tools::DomainHeader header =
      tools::read_domain_header(path == "-" ? static_cast<std::istream&>(piped) : file);
  SampledDomain read;
  read.domain = header.domain;
  if (!header.shape_key.empty()) {
    read.shape = parse_shape(header.shape_text, path + ": the header's " + header.shape_key);
    read.shape.named = true;
  }
  return read;
}

/// Whether the files are measured as wrapping around: --torus or --box, else what their headers say (all
/// alike: pooled sets share one domain), else a torus. Says on `text` when a header chose a box (a torus,
/// the default, goes unsaid). Throws CommandError.
bool measured_torus(const AnalyzeArgs& args, const std::vector<SampledDomain>& read, std::FILE* text) {
  if (args.torus || args.box) return args.torus;
  std::string said;
  for (std::size_t f = 0; f < read.size(); ++f) {
    if (read[f].domain.empty()) continue;
    if (!said.empty() && read[f].domain != said)
      throw CommandError(
          "the files were sampled in different domains (a box and a torus): their sets pool "
          "into one report, so analyse them apart, or give --box or --torus");
    said = read[f].domain;
  }
  if (said != "box") return true;
  std::fprintf(text, "domain from the file header%s: a bounded box (--torus overrides)\n",
               read.size() > 1 ? "s" : "");
  return false;
}

/// Says on standard error (a note, the summary's first line says it too) when the files' domain is the
/// default one because no header named it: CSV and .npy files, a bounded stipple's or query's among them,
/// carry none, and a torus measures a bounded set wrongly. Names the unknown shape too where it is unknown.
void note_unsaid_domain(const AnalyzeArgs& args, const std::vector<SampledDomain>& read, int dim) {
  if (args.torus || args.box) return;
  bool shape_known = !args.aspect.empty();
  for (const SampledDomain& d : read) {
    if (!d.domain.empty()) return;
    shape_known = shape_known || d.shape.named;
  }
  const std::string which = read.size() > 1        ? "the files have"
                            : args.files[0] == "-" ? "standard input has"
                                                   : args.files[0] + " has";
  std::fprintf(stderr,
               "kdm: note: %s no domain header (kdm's .txt files carry one; CSV and .npy files none): "
               "measured as a torus%s; give --box for a bounded set (a stipple, a query, a box sample)%s, or "
               "--torus to keep the torus\n",
               which.c_str(),
               shape_known ? ""
               : dim == 3  ? " in the unit cube"
                           : " in the unit square",
               shape_known ? "" : " and --aspect for its shape");
}

/// The shape the files are measured in: --aspect's, else their headers' (all alike: pooled sets share one
/// domain). Says on `text` which it took when that is not the square. Throws CommandError.
Shape measured_shape(const AnalyzeArgs& args, int dim, std::FILE* text,
                     const std::vector<SampledDomain>& domains) {
  std::vector<Shape> read;
  for (const SampledDomain& d : domains) read.push_back(d.shape);
  if (!args.aspect.empty()) {
    const Shape given = parse_shape(args.aspect, "--aspect");
    if (dim == 2 && given.numbers == 3)
      throw CommandError(
          "--aspect X:Y:Z gives a 3D domain's sides, and the points are 2D: give one number "
          "(width / height)");
    if (dim == 3 && std::count(args.aspect.begin(), args.aspect.end(), ':') == 1)  // as kdm sample says
      throw CommandError(
          "--aspect W:H is a 2D domain's shape, and the points are 3D: give three sides X:Y:Z, or one "
          "number (the x side over the others)");
    if (!given.square()) std::fprintf(text, "domain from --aspect: %s\n", given.text.c_str());
    for (std::size_t f = 0; f < read.size(); ++f)
      if (read[f].named && !read[f].same(given) && !(read[f].square() && given.square()))
        std::fprintf(text, "%s was sampled with %s; measured with --aspect %s\n", args.files[f].c_str(),
                     read[f].square() ? "equal sides" : read[f].text.c_str(), args.aspect.c_str());
    return given;
  }
  for (std::size_t f = 1; f < read.size(); ++f)
    if (!read[f].same(read[0]))
      throw CommandError("the files were sampled in different domains (" + args.files[0] + ": " +
                         (read[0].square() ? "square" : read[0].text) + ", " + args.files[f] + ": " +
                         (read[f].square() ? "square" : read[f].text) +
                         "): their sets pool into one report, so analyse them apart, or give --aspect to "
                         "measure them all in one");
  if (!read[0].square())
    std::fprintf(text,
                 "domain from the file header%s: %s (--aspect overrides; --aspect 1 measures in the "
                 "unit %s)\n",
                 read.size() > 1 ? "s" : "", read[0].text.c_str(), dim == 3 ? "cube" : "square");
  return read[0];
}

/// Creates `output` as analyze's directory (it receives metrics.json and pictures), or says why it cannot.
void prepare_output_directory(const std::string& output) {
  // A name like metrics.json is a mistake that would make a directory of it.
  const std::string ext = std::filesystem::path(output).extension().string();
  for (const char* file_ext : {".json", ".png", ".txt", ".csv", ".svg"})
    if (ext == file_ext && !std::filesystem::is_directory(output))
      throw CommandError(
          "-o is the output directory (it receives metrics.json and pictures), got the file name '" + output +
          "'");
  std::error_code ec;
  if (std::filesystem::exists(output) && !std::filesystem::is_directory(output))
    throw CommandError("-o must be a directory, but '" + output + "' is a file");
  std::filesystem::create_directories(output, ec);
  if (ec || !std::filesystem::is_directory(output))
    throw CommandError("cannot create output directory '" + output + "'" + (ec ? ": " + ec.message() : ""));
}

void run_analyze(const AnalyzeArgs& args) {
  if (args.torus && args.box) throw CommandError("--torus and --box are mutually exclusive");
  if (!(args.fmax > 0) || !std::isfinite(args.fmax)) throw CommandError("--fmax must be a positive number");
  if (!(args.min_expected > 0)) throw CommandError("--min-expected must be positive");
  if (args.tile_size_given && args.tile_size == 0)
    throw CommandError("--tile-size must be > 0 (leave it out for no tiling diagnostics)");
  analysis::AnalysisOptions o;
  o.fmax = args.fmax;
  o.min_expected = args.min_expected;
  if (args.density_bands < 1 || args.density_bands > 1000)
    throw CommandError("--density-bands must be 1 to 1000, got " + std::to_string(args.density_bands));
  o.density_bands = args.density_bands;
  if (!(args.holes_min_density >= 0 && args.holes_min_density <= 1))
    throw CommandError("--holes-min-density must be in [0, 1]");
  o.holes_min_density = args.holes_min_density;
  // Without a density these would do nothing: refused, as --gamma is.
  const analysis::AnalysisOptions defaults;
  const char* idle = args.holes_min_density != defaults.holes_min_density ? "--holes-min-density"
                     : args.density_bands != defaults.density_bands       ? "--density-bands"
                                                                          : nullptr;
  if (idle && args.density.empty() && args.class_densities.empty())
    throw CommandError(std::string(idle) +
                       " applies with a density (--density or --class-density), and none is given");
  o.tile_size = args.tile_size;
  o.threads = args.threads;
  try {
    if (args.tile_size != 0) analysis::tiles_per_axis(args.tile_size);
    gen::Density target = gen::Density::constant();
    std::vector<tools::DensitySpec> specs;  // --density's, then each --class-density's
    std::vector<std::pair<std::string, std::string>> inputs = {{"--density", args.density}};
    for (const std::string& text : args.class_densities) inputs.emplace_back("--class-density", text);
    if (std::find(args.files.begin(), args.files.end(), "-") != args.files.end())
      inputs.emplace_back("the points", "-");
    check_one_standard_input(inputs);
    if (!args.density.empty()) specs.push_back(parse_density(args.density, args.gamma, args.invert));
    for (std::size_t k = 0; k < args.class_densities.size(); ++k) try {
        specs.push_back(parse_density(args.class_densities[k], args.gamma, args.invert));
      } catch (const CommandError& e) {
        throw CommandError("--class-density for class " + std::to_string(k) + ": " + e.what());
      }
    std::vector<const tools::DensitySpec*> given;
    for (const tools::DensitySpec& s : specs) given.push_back(&s);
    check_image_options(given, args.gamma, args.invert);  // refused as sample does
    const bool volume = !args.density.empty() && specs.front().kind == tools::DensitySpec::Kind::kVolume;
    if (!args.density.empty()) {
      target = cli::to_generator_density(specs.front());
      o.density = tools::analysis_density(target);
    }
    ClassTargets own;
    const std::size_t first_class = args.density.empty() ? 0 : 1;
    bool any = false;
    for (std::size_t k = first_class; k < specs.size(); ++k) {
      own.densities.push_back(cli::to_class_density(specs[k]));  // its scale sets the class's share
      own.functions.push_back(tools::analysis_density(own.densities.back()));
      any = any || specs[k].max_value() > 0;
    }
    if (!own.densities.empty() && !any) throw CommandError("every --class-density is zero everywhere");
    std::vector<std::string> warnings;
    std::unique_ptr<BufferedStandardInput> piped;
    if (std::find(args.files.begin(), args.files.end(), "-") != args.files.end())
      piped = std::make_unique<BufferedStandardInput>();
    const std::vector<tools::PointSet> sets = analysis::load_point_sets(args.files, &warnings);
    for (const std::string& w : warnings) std::fprintf(stderr, "kdm: warning: %s\n", w.c_str());
    if (volume && sets.front().dim != 3)
      throw CommandError("--density '" + args.density + "' is a 3-D volume, and the points are 2D");
    if (!own.densities.empty()) {
      if (sets.front().classes.empty())
        throw CommandError(
            "--class-density needs labelled points (a class column, with the header line "
            "x,y,class), and the points have no classes");
      try {  // refused before anything is printed
        analysis::class_shares(sets, own.functions);
      } catch (const analysis::InvalidInput& e) {
        std::string why = e.what();  // said in the option's name
        if (const std::size_t at = why.find(" class densities given"); at != std::string::npos)
          why.replace(at, 16, " --class-density");
        throw CommandError(why);
      }
      if (args.density.empty()) {  // the whole set against the classes' summed density
        target = gen::sum_of_densities(own.densities);
        o.density = tools::analysis_density(target);
      }
    }
    if (sets.front().dim != 2 && (!args.density.empty() || args.tile_size != 0)) {
      std::fprintf(stderr,
                   "kdm: warning: density windows and tiling diagnostics are 2D only; skipped (a --density "
                   "still sets the energy)\n");
      o.tile_size = 0;  // skipped indeed: measured on a 3D set they were numbers of nothing
    }
    // -o -: metrics.json on standard output, the summary on standard error beside the warnings.
    const bool to_stdout = args.output == tools::kStandardOutput;
    std::FILE* text = to_stdout ? stderr : stdout;
    std::vector<SampledDomain> domains;
    for (const std::string& file : args.files)
      domains.push_back(sampled_domain(file, piped ? piped->bytes() : std::string()));
    o.torus = measured_torus(args, domains, text);
    const Shape shape = measured_shape(args, sets.front().dim, text, domains);
    std::copy(shape.extent, shape.extent + 3, o.extent);
    if (!shape.square() && args.tile_size != 0)
      throw CommandError(
          "--tile-size: tiling diagnostics take square tiles of the unit square, and the points "
          "were drawn in a domain of " +
          shape.text +
          " (--aspect 1 measures them in the unit "
          "square)");
    if (!shape.square() && !sets.front().classes.empty())
      throw CommandError(
          "labelled points are analysed in the unit square only, and these were drawn in a "
          "domain of " +
          shape.text + ": give --aspect 1 (the measures are stretched then)");
    if (!args.output.empty() && !to_stdout) prepare_output_directory(args.output);
    analysis::AnalysisReport report = analysis::analyze(sets, o);
    if (!args.no_energy) {
      report.energy_per_point = tools::mean_energy_per_point(sets, o.torus, target, 0, o.extent);
      report.has_energy = true;
    }
    note_unsaid_domain(args, domains, sets.front().dim);  // after the analysis: an error stays one line
    if (args.files.size() > 1)  // not one report a file: the measures pool the sets of them all
      std::fprintf(text, "%zu files pooled into one report (analyse them one at a time for one each)\n",
                   args.files.size());
    if (!own.densities.empty())
      std::fprintf(text, "all classes together, against %s\n",
                   args.density.empty() ? "the sum of the --class-density densities" : "--density");
    std::fputs(analysis::format_summary(report).c_str(), text);
    const std::string classes =
        sets.front().classes.empty() ? "" : analyze_classes(sets, o, target, own, args, text);
    if (args.output.empty()) return;  // the summary alone
    if (to_stdout) {
      const std::string metrics = analysis::metrics_json(report, args.files);
      const std::string json = classes.empty() ? metrics : with_classes(metrics, classes);
      if (std::fwrite(json.data(), 1, json.size(), stdout) != json.size() || std::fflush(stdout) != 0)
        throw CommandError("cannot write to standard output");
      return;
    }
    const std::filesystem::path dir(args.output);
    std::string error;
    if (!classes.empty() && !tools::write_text_file_atomic((dir / "classes.json").string(), classes, error))
      throw CommandError(error);
    save_png((dir / "points.png").string(), analysis::plot_points(sets.front(), 1024, report.sides));
    if (report.has_spectrum) {
      save_png((dir / "spectrum.png").string(), analysis::plot_spectrum(report.spectrum));
      save_png((dir / "raps.png").string(), analysis::plot_raps(report.spectrum_stats, report.spectrum.fmax));
    }
    // Last: a metrics.json is there only when the pictures before it were written too.
    if (!tools::write_text_file_atomic((dir / "metrics.json").string(),
                                       analysis::metrics_json(report, args.files), error))
      throw CommandError(error);
    std::fprintf(stderr, "kdm analyze: wrote %s/metrics.json and pictures\n", args.output.c_str());
  } catch (const analysis::InvalidInput& e) {
    throw CommandError(e.what());
  } catch (const gen::InvalidArgument& e) {
    throw CommandError(std::string("energy: ") + e.what());
  }
}

}  // namespace

void add_analyze_command(CLI::App& app) {
  auto args = std::make_shared<AnalyzeArgs>();
  CLI::App* cmd = app.add_subcommand("analyze",
                                     "Point-set metrics: NN distances, spectrum, g(r), holes, density, "
                                     "tiling (3D sets: NN distances, g(r) and the energy)");
  cmd->add_option(
         "files", args->files,
         "Point files: text (one point per line, blanks or commas between coordinates, sets "
         "separated by '#' lines), CSV with a header naming columns x and y (and z, or class/label "
         "for labelled points: each class is analysed alone too; other columns are skipped), or "
         "NumPy .npy ((n, 2) or (n, 3) float64/float32, or (sets, n, 2) or (sets, n, 3) as kdm sample "
         "--sets writes); - reads standard input. Several files, "
         "and the sets in one, are pooled into one report")
      ->required();
  cmd->add_flag("--torus", args->torus,
                "Periodic distances, for a set that wraps around (default, unless the files' headers say "
                "\"domain box\", as the .txt files of kdm query and stipple and a bounded kdm sample do; CSV "
                "and .npy files carry no header; the summary's first line says which were used)");
  cmd->add_flag("--box", args->box,
                "Bounded-box distances, for a set in a square with walls (most other tools' sets, and kdm "
                "stipple's, query's or a bounded sample's as CSV or .npy; g(r) with edge correction)");
  cmd->add_option(
      "--density", args->density,
      "Target density for the accuracy test and the per-band bias table: const:V, an image "
      "(dark = dense), ramp:R / radial:R or a NumPy .npy array, as given to kdm sample (default: none, no "
      "density test; const:1 tests against a uniform density). With --class-density it judges the whole "
      "set only "
      "(default there: the sum of the class densities); each class keeps its own");
  cmd->add_option(
      "--class-density", args->class_densities,
      "Labelled points: repeat it, one target density per class, class 0 first, at least up to the "
      "largest class in the file (any form --density takes: the densities given to kdm sample --class). Each "
      "class alone "
      "is judged against its own (density test, bands, holes in its local spacings), the whole set "
      "against their sum, and the closest pair of different classes in local spacings of the sum. Only "
      "each density's shape matters to its class's test; their integrals together predict each class's "
      "share of the points, which the summary and classes.json (\"shares\") compare with its count "
      "(z against a binomial sd); by default none, every class against --density as the whole set");
  cmd->add_option("--gamma", args->gamma, "Exponent applied to image darkness (as in kdm sample)")
      ->capture_default_str();
  cmd->add_flag("--invert", args->invert, "Bright image areas are dense (as in kdm sample)");
  cmd->add_flag("--no-energy", args->no_energy, "Skip the KDM energy per point (default: computed)");
  cmd->add_option_function<double>(
      "--tile-size", [a = args.get()](double s) { a->tile_size = s, a->tile_size_given = true; },
      "Tile side s in unit-square units (1/s an integer) for periodicity and seam statistics "
      "(default: none, no tiling diagnostics)");
  cmd->add_option("--fmax", args->fmax, "Periodogram limit in normalised frequency |k|/sqrt(n)")
      ->capture_default_str();
  cmd->add_option("--min-expected", args->min_expected, "Density windows expect at least this many points")
      ->capture_default_str();
  cmd->add_option("--holes-min-density", args->holes_min_density,
                  "With --density: count empty circles only where the density is at least this fraction of "
                  "its largest value (0.5: the dark half of a picture)")
      ->capture_default_str();
  cmd->add_option("--density-bands", args->density_bands,
                  "With --density: bands of the per-band bias table, the points where the target density "
                  "lies in each band (equal steps in log density) against the count it should get")
      ->capture_default_str();
  cmd->add_option(
      "--aspect", args->aspect,
      "The domain the points were drawn in: width/height as a number or W:H (in 3D the x side over "
      "the others), or three sides X:Y:Z; they are measured in it, scaled to unit area (volume); 1 forces "
      "the "
      "square (default: what the files' .txt headers say, as kdm sample --aspect, query and stipple "
      "write it; else, as for CSV and .npy files, the unit square or cube)");
  add_threads_option(cmd, args->threads, "results do not depend on it");
  cmd->add_option(
      "-o,--output", args->output,
      "Output directory (created if missing) for metrics.json (classes.json for labelled points) and "
      "pictures; - writes metrics.json (with classes.json's as \"classes\") to standard output and "
      "the summary to standard error, no pictures (default: the summary is only printed)");
  cmd->callback([args] { run_analyze(*args); });
}

}  // namespace kdm::cli
