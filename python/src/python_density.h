// A Python function of a point's coordinates as the sampler's and the analysis's density (kdm.sample and
// kdm.analyze with density=f): called with the GIL taken for each call, from whichever thread asks. The
// first exception it raises, or value that is not finite and >= 0, is kept and raised once the C++ call
// has returned (the density answers 1 from then on, so that call ends soon).
#pragma once

#include <memory>
#include <string>

#include "bindings.h"
#include "kdm/generator/sampler.h"

namespace kdm::python {

class PythonDensity {
 public:
  /// `function` takes `dim` (2 or 3) coordinates and returns a number.
  PythonDensity(py::object function, int dim) : function_(std::move(function)), dim_(dim) {}

  /// The density, calling the function; it refers to this object, which must outlive its use.
  gen::Density density() {
    gen::Density d;
    d.thread_safe = false;  // the GIL serialises the calls anyway
    d.function = [this](const double* u) -> double {
      py::gil_scoped_acquire gil;  // also guards raised_ and refused_
      if (raised_ || !refused_.empty()) return 1;
      try {
        const py::object value = dim_ == 2 ? function_(u[0], u[1]) : function_(u[0], u[1], u[2]);
        const double v = value.cast<double>();
        if (std::isfinite(v) && v >= 0) return v;
        refused_ = "density returned " + std::to_string(v) + " at (" + std::to_string(u[0]) + ", " +
                   std::to_string(u[1]) + (dim_ == 3 ? ", " + std::to_string(u[2]) : "") +
                   "): values must be finite and >= 0";
      } catch (py::error_already_set& e) {
        raised_ = std::make_unique<py::error_already_set>(std::move(e));
      } catch (const py::cast_error&) {
        refused_ = "density must return a number";
      }
      return 1;
    };
    return d;
  }

  /// Whether a call failed (the C++ call's own refusal, if any, is then the consequence, not the cause).
  bool failed() const { return raised_ || !refused_.empty(); }

  /// Raises what a call kept: the function's exception, or ValueError for its value. The GIL is held.
  void rethrow() const {
    if (raised_) throw py::error_already_set(*raised_);
    if (!refused_.empty()) throw std::invalid_argument(refused_);
  }

 private:
  py::object function_;
  int dim_;
  std::unique_ptr<py::error_already_set> raised_;
  std::string refused_;
};

}  // namespace kdm::python
