// A Python callable as a query's density (query_density.h).
#include "query_density.h"

#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

namespace kdm::python {
namespace {

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", v);
  return text;
}

}  // namespace

CallableDensity::CallableDensity(py::object f, double max_value, py::object bounds)
    : function(std::move(f)), bounds_function(std::move(bounds)) {
  density.kind = QueryDensity::Kind::kCallback;
  density.callback_max = max_value;
  density.user = this;
  density.callback = [](void* user, double x, double y) -> double {
    CallableDensity& d = *static_cast<CallableDensity*>(user);
    if (d.failed.load(std::memory_order_relaxed)) return 0;
    py::gil_scoped_acquire gil;
    try {
      const py::object value = d.function(x, y);
      const double v = PyFloat_AsDouble(value.ptr());  // any number, numpy's too
      if (v == -1 && PyErr_Occurred()) throw py::error_already_set();
      // The C++ query counts such a value as 0; from Python it is a bug in the callable, said so.
      if (!(v >= 0 && v < std::numeric_limits<double>::infinity()))
        throw std::domain_error("density callable returned " + number(v) + " at (" + number(x) + ", " +
                                number(y) + "): a density must be finite and >= 0");
      return v;
    } catch (const std::domain_error& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
      d.error.emplace();
    } catch (py::error_already_set& e) {
      d.error.emplace(std::move(e));
    } catch (const std::exception& e) {  // a failed conversion inside pybind11
      PyErr_SetString(PyExc_RuntimeError, e.what());
      d.error.emplace();
    }
    d.failed.store(true, std::memory_order_relaxed);
    return 0;
  };
  if (bounds_function.is_none()) return;
  density.bounds = [](void* user, double x0, double y0, double x1, double y1, double* lo, double* hi) {
    CallableDensity& d = *static_cast<CallableDensity*>(user);
    *lo = *hi = std::numeric_limits<double>::quiet_NaN();  // no bounds, unless the call gives them
    if (d.failed.load(std::memory_order_relaxed)) return;
    py::gil_scoped_acquire gil;
    try {
      const py::sequence pair = d.bounds_function(x0, y0, x1, y1).cast<py::sequence>();
      if (pair.size() != 2) throw std::invalid_argument("density_bounds must return (lo, hi)");
      const double l = pair[0].cast<double>(), h = pair[1].cast<double>();
      if (!(l >= 0 && l <= h))
        throw std::invalid_argument("density_bounds returned (" + number(l) + ", " + number(h) + ") for (" +
                                    number(x0) + ", " + number(y0) + ", " + number(x1) + ", " + number(y1) +
                                    "): bounds must satisfy 0 <= lo <= hi");
      *lo = l, *hi = h;
      return;
    } catch (py::error_already_set& e) {
      d.error.emplace(std::move(e));
    } catch (const std::exception& e) {  // a failed cast, or not a pair
      PyErr_SetString(PyExc_ValueError, e.what());
      d.error.emplace();
    }
    d.failed.store(true, std::memory_order_relaxed);
  };
}

void CallableDensity::rethrow() {
  if (error) throw std::move(*error);
}

}  // namespace kdm::python
