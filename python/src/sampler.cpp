// kdm._kdm.sample: the full KDM sampler (gen::sample) with `kdm sample`'s defaults and density conversion,
// so the same arguments give the same bits as the command line, returned as a numpy array it owns.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "density_spec.h"
#include "kdm/generator/multiclass.h"
#include "kdm/generator/sampler.h"
#include "python_density.h"
#include "sampler_density.h"

namespace kdm::python {
namespace {

using tools::DensitySpec;

/// MH sweeps on the finest level and on the levels between (kdm sample --sweeps, --coarse-sweeps); unset:
/// the sampler's defaults.
struct Sweeps {
  std::optional<int> finest, coarse;
};

/// A 3D domain's three sides (kdm sample --aspect X:Y:Z); unset: `aspect` or the density's shape.
using Sides = std::optional<std::array<double, 3>>;

/// The options every sampling call shares, checked: `edged` densities (a picture, a ramp, a function) get
/// a box unless `domain` says otherwise, as in kdm sample; `image_aspect` is the domain's width / height
/// unless `aspect` or `sides` is given (sides: 3D only, each finite and > 0, checked by the caller too).
gen::SamplerOptions sampler_options(std::int64_t n, int dim, const std::optional<std::string>& domain,
                                    bool edged, double temperature, std::uint64_t seed, int threads,
                                    std::optional<double> aspect, double image_aspect, const Sweeps& sweeps,
                                    const Sides& sides = std::nullopt) {
  const std::string where = domain ? *domain : (edged ? "box" : "torus");
  if (where != "box" && where != "torus")
    throw std::invalid_argument("domain must be 'torus' or 'box', got '" + where + "'");
  gen::SamplerOptions o;
  o.n = n;
  o.dim = dim;
  o.domain = where == "box" ? gen::Domain::kBox : gen::Domain::kTorus;
  o.extent[0] = aspect ? *aspect : image_aspect;
  o.extent[1] = 1;
  if (sides) {
    if (dim != 3) throw std::invalid_argument("aspect=(x, y, z) sets a 3-D domain's sides: use dim=3");
    for (double side : *sides)
      if (!(std::isfinite(side) && side > 0))
        throw std::invalid_argument("aspect sides must be finite and > 0, got " + std::to_string(side));
    std::copy(sides->begin(), sides->end(), o.extent);
  }
  o.temperature = temperature;
  o.seed = seed;
  o.threads = threads;
  o.progress = stop_on_signal;  // Ctrl-C stops the sampler at its next sweep
  if (sweeps.finest) o.sweeps = *sweeps.finest;
  if (sweeps.coarse) o.coarse_sweeps = *sweeps.coarse;
  return o;
}

/// gen::sample_sets with seeds o.seed, o.seed + 1, ..., o.seed + sets - 1, into a new (sets, n, dim) array:
/// the sizes checked before the array is made, the GIL released while the sets run.
py::array_t<double> sample_sets(const gen::SamplerOptions& o, const gen::Density& density,
                                std::int64_t sets) {
  if (sets < 1 || sets > gen::kMaxSampleSets)
    throw std::invalid_argument("sets must be 1 to " + std::to_string(gen::kMaxSampleSets) + ", got " +
                                std::to_string(sets));
  if (o.n > gen::kMaxSampleSetPoints / sets)
    throw std::invalid_argument(std::to_string(sets) + " sets of " + std::to_string(o.n) + " points are " +
                                std::to_string(sets * o.n) + " points in all, more than the " +
                                std::to_string(gen::kMaxSampleSetPoints) +
                                " one call returns: ask for fewer");
  if (o.seed > std::numeric_limits<std::uint64_t>::max() - std::uint64_t(sets - 1))
    throw std::invalid_argument("seed " + std::to_string(o.seed) + " with sets=" + std::to_string(sets) +
                                " runs past the largest seed, 2**64 - 1");
  std::vector<std::uint64_t> seeds(static_cast<std::size_t>(sets));
  for (std::size_t k = 0; k < seeds.size(); ++k) seeds[k] = o.seed + k;
  py::array_t<double> points({py::ssize_t(sets), py::ssize_t(o.n), py::ssize_t(o.dim)});
  double* data = points.mutable_data();
  {
    py::gil_scoped_release release;
    gen::sample_sets(o, density, seeds, data);
  }
  return points;
}

py::object sample(std::int64_t n, const DensitySpec* density, int dim,
                  const std::optional<std::string>& domain, double temperature, std::uint64_t seed,
                  int threads, std::optional<double> aspect, std::optional<int> sweeps,
                  std::optional<int> coarse_sweeps, const Sides& sides, std::optional<std::int64_t> sets) {
  DensitySpec uniform;  // kdm sample's default, const:1
  const DensitySpec& spec = density ? *density : uniform;
  const bool image = spec.kind == DensitySpec::Kind::kImage, volume = spec.kind == DensitySpec::Kind::kVolume;
  if (volume && dim != 3)
    throw std::invalid_argument("a 3-D density array (depth, height, width) is a volume: use dim=3");
  // As kdm sample: a ramp, a picture or a volume has edges that do not meet, so a box unless asked otherwise;
  // a volume's domain has its voxel counts as sides unless `aspect` says otherwise.
  Sides shape = sides;
  if (volume && !sides && !aspect) shape = {{double(spec.width), double(spec.height), double(spec.depth)}};
  const gen::SamplerOptions o = sampler_options(
      n, dim, domain, image || volume || spec.kind == DensitySpec::Kind::kRamp, temperature, seed, threads,
      aspect, image ? double(spec.width) / spec.height : 1.0, {sweeps, coarse_sweeps}, shape);
  if (image && dim != 2) throw std::invalid_argument("image and array densities are 2-D; use dim=2");
  const gen::Density target = tools::to_generator_density(spec);
  if (sets) return sample_sets(o, target, *sets);
  gen::SampleResult result;
  {
    py::gil_scoped_release release;
    result = gen::sample(o, target);
  }
  const auto count = static_cast<py::ssize_t>(result.size());
  return owning_array(std::move(result.points), {count, result.dim});
}

/// gen::sample of a Python function of the point's coordinates: called once per node of the sampler's
/// grid, on one thread, with the GIL taken for each call, or `vectorized` once per run of nodes (up to
/// gen::kDensityBatch positions) on coordinate arrays. The first exception it raises, or value that is
/// not finite and >= 0, ends the call with that error once the sampler returns.
py::object sample_function(std::int64_t n, const py::object& function, int dim,
                           const std::optional<std::string>& domain, double temperature, std::uint64_t seed,
                           int threads, std::optional<double> aspect, std::optional<int> sweeps,
                           std::optional<int> coarse_sweeps, const Sides& sides,
                           std::optional<std::int64_t> sets, bool vectorized) {
  // A function's edges do not meet in general: a box unless asked otherwise, as for a ramp or a picture.
  const gen::SamplerOptions o = sampler_options(n, dim, domain, true, temperature, seed, threads, aspect, 1.0,
                                                {sweeps, coarse_sweeps}, sides);
  PythonDensity function_density(function, dim, "density", vectorized);
  if (sets) {
    py::object points;
    try {
      points = sample_sets(o, function_density.density(), *sets);
    } catch (...) {
      if (!function_density.failed()) throw;
    }
    function_density.rethrow();
    return points;
  }
  gen::SampleResult result;
  try {
    py::gil_scoped_release release;
    result = gen::sample(o, function_density.density());
  } catch (...) {
    if (!function_density.failed()) throw;  // the sampler's own refusal (a density zero everywhere)
  }
  function_density.rethrow();
  const auto count = static_cast<py::ssize_t>(result.size());
  return owning_array(std::move(result.points), {count, result.dim});
}

/// gen::sample_classes as `kdm sample --class` runs it: the points (n × 2, class 0's first) and each
/// one's class.
py::tuple sample_classes(std::int64_t n, const std::vector<const DensitySpec*>& specs,
                         const std::optional<std::string>& domain, double temperature, std::uint64_t seed,
                         int threads, std::optional<double> aspect, std::optional<int> sweeps,
                         std::optional<int> coarse_sweeps) {
  if (specs.empty() || specs.size() > 8)
    throw std::invalid_argument("classes must hold 1 to 8 densities, got " + std::to_string(specs.size()));
  if (const auto [i, j] = tools::images_of_different_shapes(specs); j >= 0)
    throw std::invalid_argument("class images must have one shape (width to height): classes[" +
                                std::to_string(i) + "] is " + std::to_string(specs[i]->width) + "x" +
                                std::to_string(specs[i]->height) + ", classes[" + std::to_string(j) + "] " +
                                std::to_string(specs[j]->width) + "x" + std::to_string(specs[j]->height));
  // As kdm sample --class: a box if any class has edges (an image, a ramp), the first image's aspect.
  bool edged = false;
  const DensitySpec* first_image = nullptr;
  std::vector<gen::Density> densities;
  for (const DensitySpec* spec : specs) {
    const bool image = spec->kind == DensitySpec::Kind::kImage;
    edged = edged || image || spec->kind == DensitySpec::Kind::kRamp;
    if (image && !first_image) first_image = spec;
    try {
      densities.push_back(tools::to_class_density(*spec));
    } catch (const std::invalid_argument& e) {  // named as the caller gave it
      throw std::invalid_argument("classes[" + std::to_string(densities.size()) + "]: " + e.what());
    }
  }
  const gen::SamplerOptions o = sampler_options(
      n, 2, domain, edged, temperature, seed, threads, aspect,
      first_image ? double(first_image->width) / first_image->height : 1.0, {sweeps, coarse_sweeps});
  gen::ClassSample result;
  {
    py::gil_scoped_release release;
    result = gen::sample_classes(o, densities);
  }
  const auto count = static_cast<py::ssize_t>(result.size());
  py::array_t<std::uint8_t> labels(count);
  std::copy(result.classes.begin(), result.classes.end(), labels.mutable_data());
  return py::make_tuple(owning_array(std::move(result.points), {count, py::ssize_t(2)}), labels);
}

}  // namespace

void bind_sampler(py::module_& m) {
  m.def("sample", &sample, py::arg("n"), py::arg("density").none(true), py::arg("dim"),
        py::arg("domain").none(true), py::arg("temperature"), py::arg("seed"), py::arg("threads"),
        py::arg("aspect").none(true), py::arg("sweeps").none(true) = py::none(),
        py::arg("coarse_sweeps").none(true) = py::none(), py::arg("sides").none(true) = py::none(),
        py::arg("sets").none(true) = py::none(),
        "gen::sample as kdm sample runs it; with sets, gen::sample_sets for seeds seed, seed + 1, ...");
  m.def("sample_function", &sample_function, py::arg("n"), py::arg("function"), py::arg("dim"),
        py::arg("domain").none(true), py::arg("temperature"), py::arg("seed"), py::arg("threads"),
        py::arg("aspect").none(true), py::arg("sweeps").none(true) = py::none(),
        py::arg("coarse_sweeps").none(true) = py::none(), py::arg("sides").none(true) = py::none(),
        py::arg("sets").none(true) = py::none(), py::arg("vectorized") = false,
        "gen::sample of a Python function of the coordinates (with sets, gen::sample_sets), vectorized: "
        "of coordinate arrays");
  m.def("sample_classes", &sample_classes, py::arg("n"), py::arg("specs"), py::arg("domain").none(true),
        py::arg("temperature"), py::arg("seed"), py::arg("threads"), py::arg("aspect").none(true),
        py::arg("sweeps").none(true) = py::none(), py::arg("coarse_sweeps").none(true) = py::none(),
        "gen::sample_classes as kdm sample --class runs it");
  m.def("default_thread_count", &gen::default_thread_count);
}

}  // namespace kdm::python
