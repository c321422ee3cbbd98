// kdm._kdm.analyze: the point-set analysis as `kdm analyze` runs it (tools/cli/cmd_analyze.cpp), returned as
// the text of the metrics.json it would write, which the Python side parses.
#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bindings.h"
#include "kdm/analysis/classes.h"
#include "kdm/analysis/json.h"
#include "kdm/analysis/report.h"
#include "kdm/generator/multiclass.h"
#include "python_density.h"
#include "sampler_density.h"

namespace kdm::python {
namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

tools::PointSet to_point_set(const Array& a) {
  if (a.ndim() != 2 || (a.shape(1) != 2 && a.shape(1) != 3))
    throw std::invalid_argument("points must be an (n, 2) or (n, 3) array");
  tools::PointSet set;
  set.dim = static_cast<int>(a.shape(1));
  set.coords.assign(a.data(), a.data() + a.size());
  analysis::validate_points(set.coords, set.dim);  // finite, inside [0, 1]
  return set;
}

using Labels = py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>;

/// metrics.json's text, and with `labels` (one array per set, or none) classes.json's (else None). The
/// target density is `density`, or `function` of the coordinates (PythonDensity), or uniform; with
/// `class_densities` (each a DensitySpec or a function; one per class, or none) each class is judged
/// against its own, and the whole set against their sum unless a target density is given.
py::tuple analyze(const std::vector<Array>& arrays, const std::vector<std::string>& names, bool box,
                  const tools::DensitySpec* density, const py::object& function, double tile_size,
                  double fmax, int threads, bool energy, const std::vector<Labels>& labels,
                  double min_expected, int density_bands, double holes_min_density,
                  const std::vector<py::object>& class_densities, const std::vector<double>& extent) {
  check_number("fmax", fmax, 0, true);
  check_number("min_expected", min_expected, 0, true);
  if (density_bands < 1 || density_bands > 1000)
    throw std::invalid_argument("density_bands must be 1 to 1000, got " + std::to_string(density_bands));
  if (!(holes_min_density >= 0 && holes_min_density <= 1))
    throw std::invalid_argument("holes_min_density must be in [0, 1], got " +
                                std::to_string(holes_min_density));
  if (!labels.empty() && labels.size() != arrays.size())
    throw std::invalid_argument("classes must hold one array of labels per set");
  if (!class_densities.empty() && labels.empty())
    throw std::invalid_argument("class_densities needs classes (each point's class)");
  if (threads < 0) throw std::invalid_argument("threads must be >= 0 (0: the default count)");
  if (!std::isfinite(tile_size)) throw std::invalid_argument("tile_size must be a finite number");
  if (extent.size() != 3) throw std::invalid_argument("extent must hold three sides");
  analysis::AnalysisOptions o;
  o.torus = !box;
  o.fmax = fmax;
  o.tile_size = tile_size;
  o.threads = threads;
  o.min_expected = min_expected;
  o.density_bands = density_bands;
  o.holes_min_density = holes_min_density;
  std::copy(extent.begin(), extent.end(), o.extent);
  o.checkpoint = [] { stop_on_signal(0); };                 // Ctrl-C stops it between its measures
  if (tile_size != 0) analysis::tiles_per_axis(tile_size);  // 1 / tile_size an integer
  std::vector<tools::PointSet> sets;
  for (std::size_t i = 0; i < arrays.size(); ++i) {
    sets.push_back(to_point_set(arrays[i]));
    if (labels.empty()) continue;
    const Labels& l = labels[i];
    if (l.ndim() != 1 || std::size_t(l.size()) != sets.back().size())
      throw std::invalid_argument("classes[" + std::to_string(i) + "] must hold one label per point of " +
                                  names[i] + " (" + std::to_string(sets.back().size()) + ")");
    if (sets.back().dim != 2) throw std::invalid_argument("classes are 2-D point sets' labels");
    sets.back().classes.assign(l.data(), l.data() + l.size());
  }
  gen::Density target = gen::Density::constant();
  std::unique_ptr<PythonDensity> function_density;
  if (density && !sets.empty()) {  // as kdm analyze --density refuses them
    const bool volume = density->kind == tools::DensitySpec::Kind::kVolume;
    if (volume && sets[0].dim != 3)
      throw std::invalid_argument("density is a 3-D volume, and the points are " +
                                  std::to_string(sets[0].dim) + "-D");
    if (density->kind == tools::DensitySpec::Kind::kImage && sets[0].dim != 2)
      throw std::invalid_argument("density is a 2-D image, and the points are " +
                                  std::to_string(sets[0].dim) +
                                  "-D: give a 3-D array (depth, rows, columns) or a function");
  }
  if (density) {
    target = tools::to_generator_density(*density);
  } else if (!function.is_none()) {
    function_density = std::make_unique<PythonDensity>(function, sets.empty() ? 2 : sets[0].dim);
    target = function_density->density();
  }
  if (density || function_density) o.density = tools::analysis_density(target);
  std::vector<gen::Density> own;  // the classes' densities; constants keep their values (their shares)
  std::vector<analysis::DensityFunction> own_functions;
  std::vector<std::unique_ptr<PythonDensity>> class_functions;
  for (std::size_t k = 0; k < class_densities.size(); ++k) {
    const py::object& d = class_densities[k];
    if (py::isinstance<tools::DensitySpec>(d)) {
      try {
        own.push_back(tools::to_class_density(d.cast<const tools::DensitySpec&>()));
      } catch (const std::exception& e) {
        throw std::invalid_argument("class_densities[" + std::to_string(k) + "]: " + e.what());
      }
    } else {
      class_functions.push_back(
          std::make_unique<PythonDensity>(d, 2, "class_densities[" + std::to_string(k) + "]"));
      own.push_back(class_functions.back()->density());
    }
    own_functions.push_back(tools::analysis_density(own.back()));
  }
  // The whole set against the classes' summed density, unless the caller named its own target.
  if (!own.empty() && !o.density)
    target = gen::sum_of_densities(own), o.density = tools::analysis_density(target);
  const auto failed = [&] {
    if (function_density && function_density->failed()) return true;
    for (const auto& f : class_functions)
      if (f->failed()) return true;
    return false;
  };
  std::string metrics, classes;
  analysis::Periodogram spectrum;  // the set-averaged periodogram, for the caller's own measures
  try {
    py::gil_scoped_release release;
    auto energy_of = [&](const std::vector<tools::PointSet>& of, const gen::Density& under) {
      try {
        return tools::mean_energy_per_point(of, o.torus, under, threads, o.extent);
      } catch (const gen::InvalidArgument& e) {
        throw std::invalid_argument(std::string("energy: ") + e.what());
      }
    };
    analysis::AnalysisReport report = analysis::analyze(sets, o);
    if (energy) report.energy_per_point = energy_of(sets, target), report.has_energy = true;
    metrics = analysis::metrics_json(report, names);
    if (report.has_spectrum) spectrum = std::move(report.spectrum);
    if (!labels.empty()) {
      analysis::ClassEnergy class_energy;
      if (energy)
        class_energy = [&](std::uint8_t k, const std::vector<tools::PointSet>& of) {
          return energy_of(of, own.empty() ? target : own[k]);
        };
      classes =
          analysis::classes_json(analysis::analyze_classes(sets, o, class_energy, own_functions), names);
    }
  } catch (...) {
    if (!failed()) throw;  // else a density function's failure is the cause
  }
  if (function_density) function_density->rethrow();
  for (const auto& f : class_functions) f->rethrow();
  py::object power = py::none();
  if (!spectrum.power.empty()) {
    py::array_t<double> grid({py::ssize_t(spectrum.height()), py::ssize_t(spectrum.width())});
    std::copy(spectrum.power.begin(), spectrum.power.end(), grid.mutable_data());
    power = grid;
  }
  return py::make_tuple(metrics, labels.empty() ? py::object(py::none()) : py::object(py::str(classes)),
                        power);
}

}  // namespace

void bind_analysis(py::module_& m) {
  m.def("analyze", &analyze, py::arg("sets"), py::arg("names"), py::arg("box"), py::arg("density").none(true),
        py::arg("function").none(true), py::arg("tile_size"), py::arg("fmax"), py::arg("threads"),
        py::arg("energy"), py::arg("labels"), py::arg("min_expected"), py::arg("density_bands"),
        py::arg("holes_min_density"), py::arg("class_densities"), py::arg("extent"),
        "kdm analyze's metrics.json (and classes.json) for point sets in memory");
}

}  // namespace kdm::python
