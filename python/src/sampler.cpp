// kdm._kdm.sample: the full KDM sampler (gen::sample) with `kdm sample`'s defaults and density conversion,
// so the same arguments give the same bits as the command line, returned as a numpy array it owns.
#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "density_spec.h"
#include "kdm/generator/multiclass.h"
#include "kdm/generator/sampler.h"
#include "sampler_density.h"

namespace kdm::python {
namespace {

using tools::DensitySpec;

py::array_t<double> sample(std::int64_t n, const DensitySpec* density, int dim,
                           const std::optional<std::string>& domain, double temperature, std::uint64_t seed,
                           int threads, std::optional<double> aspect) {
  if (n < 1) throw std::invalid_argument("n must be >= 1, got " + std::to_string(n));
  if (dim != 2 && dim != 3) throw std::invalid_argument("dim must be 2 or 3, got " + std::to_string(dim));
  check_number("temperature", temperature, 0, false);
  if (threads < 0) throw std::invalid_argument("threads must be >= 0 (0: the default count)");
  if (aspect) check_number("aspect", *aspect, 0, true);
  DensitySpec uniform;  // kdm sample's default, const:1
  const DensitySpec& spec = density ? *density : uniform;
  const bool image = spec.kind == DensitySpec::Kind::kImage;
  // As kdm sample: a ramp or a picture has edges that do not meet, so a box unless asked otherwise.
  const bool edged = image || spec.kind == DensitySpec::Kind::kRamp;
  const std::string where = domain ? *domain : (edged ? "box" : "torus");
  if (where != "box" && where != "torus")
    throw std::invalid_argument("domain must be 'torus' or 'box', got '" + where + "'");
  if (image && dim != 2) throw std::invalid_argument("image densities are 2D; use dim=2");
  gen::SamplerOptions o;
  o.n = n;
  o.dim = dim;
  o.domain = where == "box" ? gen::Domain::kBox : gen::Domain::kTorus;
  o.extent[0] = aspect ? *aspect : (image ? double(spec.width) / spec.height : 1.0);
  o.extent[1] = 1;
  o.temperature = temperature;
  o.seed = seed;
  o.threads = threads;
  o.progress = stop_on_signal;  // Ctrl-C stops the sampler at its next sweep
  const gen::Density target = tools::to_generator_density(spec);
  gen::SampleResult result;
  {
    py::gil_scoped_release release;
    result = gen::sample(o, target);
  }
  const auto count = static_cast<py::ssize_t>(result.size());
  return owning_array(std::move(result.points), {count, result.dim});
}

/// gen::sample_classes as `kdm sample --class` runs it: the points (n × 2, class 0's first) and each
/// one's class.
py::tuple sample_classes(std::int64_t n, const std::vector<const DensitySpec*>& specs,
                         const std::optional<std::string>& domain, double temperature, std::uint64_t seed,
                         int threads, std::optional<double> aspect) {
  if (n < 1) throw std::invalid_argument("n must be >= 1, got " + std::to_string(n));
  if (specs.empty() || specs.size() > 8)
    throw std::invalid_argument("classes must hold 1 to 8 densities, got " + std::to_string(specs.size()));
  check_number("temperature", temperature, 0, false);
  if (threads < 0) throw std::invalid_argument("threads must be >= 0 (0: the default count)");
  if (aspect) check_number("aspect", *aspect, 0, true);
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
  const std::string where = domain ? *domain : (edged ? "box" : "torus");
  if (where != "box" && where != "torus")
    throw std::invalid_argument("domain must be 'torus' or 'box', got '" + where + "'");
  gen::SamplerOptions o;
  o.n = n;
  o.domain = where == "box" ? gen::Domain::kBox : gen::Domain::kTorus;
  o.extent[0] = aspect ? *aspect : (first_image ? double(first_image->width) / first_image->height : 1.0);
  o.extent[1] = 1;
  o.temperature = temperature;
  o.seed = seed;
  o.threads = threads;
  o.progress = stop_on_signal;
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
        py::arg("aspect").none(true), "gen::sample as kdm sample runs it");
  m.def("sample_classes", &sample_classes, py::arg("n"), py::arg("specs"), py::arg("domain").none(true),
        py::arg("temperature"), py::arg("seed"), py::arg("threads"), py::arg("aspect").none(true),
        "gen::sample_classes as kdm sample --class runs it");
  m.def("default_thread_count", &gen::default_thread_count);
}

}  // namespace kdm::python
