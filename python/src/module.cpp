// The compiled half of the Python package: kdm._kdm. The public functions, their defaults and their
// docstrings are in python/kdm/*.py, which check argument types and call what is bound here.
#include <cmath>
#include <cstdio>

#include "bindings.h"
#include "kdm/generator/sampler.h"
#include "kdm/runtime/version.h"

namespace kdm::python {

void check_number(const char* name, double value, double min, bool strict) {
  if (std::isfinite(value) && (strict ? value > min : value >= min)) return;
  char text[160];
  std::snprintf(text, sizeof text, "%s must be a finite number %s %g, got %g", name, strict ? ">" : ">=", min,
                value);
  throw std::invalid_argument(text);
}

}  // namespace kdm::python

PYBIND11_MODULE(_kdm, m) {
  namespace py = pybind11;
  using namespace kdm::python;
  m.doc() = "kdm's C++ libraries for the Python package kdm (use kdm, not this module)";
  m.attr("__version__") = kdm::version_string();
  m.attr("MAX_THREADS") = kdm::gen::kMaxThreads;
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const FileError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    }
  });
  bind_density(m);
  bind_sampler(m);
  bind_tileset(m);
  bind_query(m);
  bind_stipple(m);
  bind_analysis(m);
  bind_timing(m);
}
