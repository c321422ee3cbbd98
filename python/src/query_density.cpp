// A Python callable as a query's density (query_density.h).
#include "query_density.h"

#include <stdexcept>

namespace kdm::python {

CallableDensity::CallableDensity(py::object f, double max_value) : function(std::move(f)) {
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
      return v;  // NaN, negative or infinite: the query counts it as 0
    } catch (py::error_already_set& e) {
      d.error.emplace(std::move(e));
    } catch (const std::exception& e) {  // a failed conversion inside pybind11
      PyErr_SetString(PyExc_RuntimeError, e.what());
      d.error.emplace();
    }
    d.failed.store(true, std::memory_order_relaxed);
    return 0;
  };
}

void CallableDensity::rethrow() {
  if (error) throw std::move(*error);
}

}  // namespace kdm::python
