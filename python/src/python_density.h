// A Python function of a point's coordinates as the sampler's and the analysis's density (kdm.sample and
// kdm.analyze with density=f): called with the GIL taken for each call, from whichever thread asks, or,
// vectorized, on arrays of coordinates (the sampler's Density::batch: a run of grid nodes a call). The
// first exception it raises, or value that is no density (density_value, density_values: TypeError for a
// wrong type, ValueError for a value that is not finite and >= 0 or a wrong shape), is kept and raised once
// the C++ call has returned (the density answers 1 from then on, so that call ends soon).
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "bindings.h"
#include "density_value.h"
#include "kdm/generator/sampler.h"

namespace kdm::python {

class PythonDensity {
 public:
  /// `function` takes `dim` (2 or 3) coordinates and returns a number, or with `vectorized` takes `dim`
  /// float64 arrays of one length and returns an array of that length; `name` is the argument it came as
  /// ("density", "class_densities[1]"), for the messages.
  PythonDensity(py::object function, int dim, std::string name = "density", bool vectorized = false)
      : function_(std::move(function)), dim_(dim), name_(std::move(name)), vectorized_(vectorized) {}

  /// The density, calling the function; it refers to this object, which must outlive its use.
  gen::Density density() {
    gen::Density d;
    d.thread_safe = false;  // the GIL serialises the calls anyway
    if (vectorized_) {
      d.batch = [this](const double* u, std::size_t count, double* out) { call(u, count, out); };
      d.function = [this](const double* u) {  // the same callable on arrays of one
        double v = 1;
        call(u, 1, &v);
        return v;
      };
      return d;
    }
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
  /// The vectorized function at `count` positions (`dim_` coordinates each, one after another) into out:
  /// one call, with the GIL taken for it alone and the coordinates copied into one array per axis.
  void call(const double* u, std::size_t count, double* out) {
    py::gil_scoped_acquire gil;  // also guards raised_
    if (!raised_) {
      try {
        std::vector<py::array_t<double>> axes;
        for (int k = 0; k < dim_; ++k) {
          py::array_t<double> axis(static_cast<py::ssize_t>(count));
          double* to = axis.mutable_data();
          for (std::size_t i = 0; i < count; ++i) to[i] = u[i * std::size_t(dim_) + std::size_t(k)];
          axes.push_back(std::move(axis));
        }
        const py::object value =
            dim_ == 2 ? function_(axes[0], axes[1]) : function_(axes[0], axes[1], axes[2]);
        const auto values = density_values(value, name_, count, u, dim_);
        const bool one = values.size() == 1;  // one value for all positions, as queries take it
        for (std::size_t i = 0; i < count; ++i)
          out[i] = finite_density(values.data()[one ? 0 : i], name_, u + i * std::size_t(dim_), dim_);
        return;
      } catch (py::error_already_set& e) {
        raised_ = std::make_unique<py::error_already_set>(std::move(e));
      } catch (const py::builtin_exception& e) {  // density_values' TypeError or ValueError
        e.set_error();
        raised_ = std::make_unique<py::error_already_set>();
      }
    }
    std::fill(out, out + count, 1.0);
  }

  py::object function_;
  int dim_;
  std::string name_;
  bool vectorized_;
  std::unique_ptr<py::error_already_set> raised_;
};

}  // namespace kdm::python
