// kdm._kdm.analyze: the point-set analysis as `kdm analyze` runs it (tools/cli/cmd_analyze.cpp), returned as
// the text of the metrics.json it would write, which the Python side parses.
#include <cmath>
#include <string>
#include <vector>

#include "bindings.h"
#include "kdm/analysis/json.h"
#include "kdm/analysis/report.h"
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

std::string analyze(const std::vector<Array>& arrays, const std::vector<std::string>& names, bool box,
                    const tools::DensitySpec* density, double tile_size, double fmax, int threads,
                    bool energy) {
  check_number("fmax", fmax, 0, true);
  if (threads < 0) throw std::invalid_argument("threads must be >= 0 (0: the default count)");
  if (!std::isfinite(tile_size)) throw std::invalid_argument("tile_size must be a finite number");
  analysis::AnalysisOptions o;
  o.torus = !box;
  o.fmax = fmax;
  o.tile_size = tile_size;
  o.threads = threads;
  o.checkpoint = [] { stop_on_signal(0); };                 // Ctrl-C stops it between its measures
  if (tile_size != 0) analysis::tiles_per_axis(tile_size);  // 1 / tile_size an integer
  gen::Density target = gen::Density::constant();
  if (density) {
    target = tools::to_generator_density(*density);
    o.density = tools::analysis_density(target);
  }
  std::vector<tools::PointSet> sets;
  for (const Array& a : arrays) sets.push_back(to_point_set(a));
  py::gil_scoped_release release;
  analysis::AnalysisReport report = analysis::analyze(sets, o);
  if (energy) {
    try {
      report.energy_per_point = tools::mean_energy_per_point(sets, o.torus, target, threads);
    } catch (const gen::InvalidArgument& e) {
      throw std::invalid_argument(std::string("energy: ") + e.what());
    }
    report.has_energy = true;
  }
  return analysis::metrics_json(report, names);
}

}  // namespace

void bind_analysis(py::module_& m) {
  m.def("analyze", &analyze, py::arg("sets"), py::arg("names"), py::arg("box"), py::arg("density").none(true),
        py::arg("tile_size"), py::arg("fmax"), py::arg("threads"), py::arg("energy"),
        "kdm analyze's metrics.json for point sets in memory");
}

}  // namespace kdm::python
