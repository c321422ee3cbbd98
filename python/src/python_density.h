// A Python function of a point's coordinates as the sampler's and the analysis's density (kdm.sample and
// kdm.analyze with density=f): called with the GIL taken for each call, from whichever thread asks. The
// first exception it raises, or value that is no density (density_value: TypeError for a wrong type,
// ValueError for a value that is not finite and >= 0), is kept and raised once the C++ call has returned
// (the density answers 1 from then on, so that call ends soon).
#pragma once

#include <memory>
#include <string>

#include "bindings.h"
#include "density_value.h"
#include "kdm/generator/sampler.h"

namespace kdm::python {

class PythonDensity {
 public:
  /// `function` takes `dim` (2 or 3) coordinates and returns a number; `name` is the argument it came as
  /// ("density", "class_densities[1]"), for the messages.
  PythonDensity(py::object function, int dim, std::string name = "density")
      : function_(std::move(function)), dim_(dim), name_(std::move(name)) {}

  /// The density, calling the function; it refers to this object, which must outlive its use.
  gen::Density density() {
    gen::Density d;
    d.thread_safe = false;  // the GIL serialises the calls anyway
    d.function = [this](const double* u) -> double {
      py::gil_scoped_acquire gil;  // also guards raised_
      if (raised_) return 1;
      try {
        const py::object value = dim_ == 2 ? function_(u[0], u[1]) : function_(u[0], u[1], u[2]);
        return density_value(value, name_, u, dim_);
      } catch (py::error_already_set& e) {
        raised_ = std::make_unique<py::error_already_set>(std::move(e));
      } catch (const py::builtin_exception& e) {  // density_value's TypeError or ValueError
        e.set_error();
        raised_ = std::make_unique<py::error_already_set>();
      }
      return 1;
    };
    return d;
  }

  /// Whether a call failed (the C++ call's own refusal, if any, is then the consequence, not the cause).
  bool failed() const { return raised_ != nullptr; }

  /// Raises what a call kept: the function's exception, or the TypeError or ValueError for its value. The
  /// GIL is held.
  void rethrow() const {
    if (raised_) throw py::error_already_set(*raised_);
  }

 private:
  py::object function_;
  int dim_;
  std::string name_;
  std::unique_ptr<py::error_already_set> raised_;
};

}  // namespace kdm::python
