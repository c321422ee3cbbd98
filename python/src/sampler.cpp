// kdm._kdm.sample: the full KDM sampler (gen::sample) with `kdm sample`'s defaults and density conversion,
// so the same arguments give the same bits as the command line, returned as a numpy array it owns.
#include <optional>
#include <string>

#include "bindings.h"
#include "density_spec.h"
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

}  // namespace

void bind_sampler(py::module_& m) {
  m.def("sample", &sample, py::arg("n"), py::arg("density").none(true), py::arg("dim"),
        py::arg("domain").none(true), py::arg("temperature"), py::arg("seed"), py::arg("threads"),
        py::arg("aspect").none(true), "gen::sample as kdm sample runs it");
  m.def("default_thread_count", &gen::default_thread_count);
}

}  // namespace kdm::python
