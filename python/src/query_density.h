// A query's density from what Python passes: a DensitySpec (a constant, an image or array stretched over a
// world rectangle, or a test map: tools::SpecDensity, as `kdm query --density` builds it), or a Python
// callable.
#pragma once

#include <atomic>
#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "density_spec.h"
#include "kdm/runtime/query.h"
#include "spec_density.h"

namespace kdm::python {

using tools::SpecDensity;  // as `kdm query` builds it (tools/stipple/spec_density.h)

/// A Python callable f(x, y) -> float as a query callback or, `vectorized`, f(x, y) -> array of float64
/// arrays x and y of the same length (QueryDensity::batch_callback: up to kDensityBatch positions a call).
/// The query runs with the GIL released; each call takes it back. The first exception f raises is kept (later
/// calls return 0 at once) for rethrow() to raise once the query is over, so it reaches the caller as itself.
/// `bounds`, if not None, is a callable (x0, y0, x1, y1) -> (lo, hi) bounding the density over a rectangle
/// (QueryDensity::bounds). `name` is the argument it came as ("density", "classes[1]"), for the messages.
struct CallableDensity {
  CallableDensity(py::object function, double max_value, py::object bounds, bool vectorized,
                  std::string name = "density");
  /// Raises the kept exception, if any. Call with the GIL held.
  void rethrow();

  QueryDensity density;
  py::object function, bounds_function;
  std::string name;
  std::atomic<bool> failed{false};
  std::optional<py::error_already_set> error;
};

}  // namespace kdm::python
