// The compiled half of the Python package: kdm._kdm. The public functions, their defaults and their
// docstrings are in python/kdm/*.py, which check argument types and call what is bound here.
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
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

FileError read_error(const std::string& path, const std::string& message) {
  struct stat info;
  int error = 0;
  if (::stat(path.c_str(), &info) != 0)
    error = errno;
  else if (S_ISDIR(info.st_mode))
    error = EISDIR;
  else if (::access(path.c_str(), R_OK) != 0)
    error = errno;
  return FileError(message, error);
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
      // OSError(errno, ...) is the subclass that errno names; raised with kdm's message alone.
      PyObject* type = PyExc_OSError;
      const py::object probe = py::reinterpret_steal<py::object>(
          e.error_number ? PyObject_CallFunction(PyExc_OSError, "is", e.error_number, "") : nullptr);
      if (probe) type = reinterpret_cast<PyObject*>(Py_TYPE(probe.ptr()));
      PyErr_Clear();  // a failed probe leaves OSError itself
      PyErr_SetString(type, e.what());
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
