// A Python callable as a query's density (query_density.h).
#include "query_density.h"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

#include "density_value.h"
#include "kdm/runtime/density_check.h"

namespace kdm::python {
namespace {

/// A density value from Python: the C++ query counts a bad one as 0 and one above its bound as the bound
/// (too few points there); from Python either is a bug in the callable or its density_max, said so, by the
/// rule a kdm::DensityCheck applies in C and C++.
double checked_value(double v, const std::string& name, double x, double y, double max_value) {
  const double at[2] = {x, y};
  finite_density(v, name, at, 2);
  if (!density_value_fits(v, max_value))
    throw std::domain_error(name + " callable returned " + number_text(v) + " at " + point_text(at, 2) +
                            ", above density_max " + number_text(max_value) +
                            ": density_max must bound every value (smooth mode also reads up to a glide's "
                            "reach outside the rect)");
  return v;
}

/// The values a vectorized callable returned for n positions into out[0 … n): n of them, or one for all,
/// each checked as checked_value checks one.
void read_values(const py::object& value, const std::string& name, std::size_t n, const double* x,
                 const double* y, double max_value, double* out) {
  const double first[2] = {n ? x[0] : 0, n ? y[0] : 0};
  const auto v = density_values(value, name, n, first, 2);
  const bool one = v.size() == 1 && n != 1;
  const double* values = v.data();
  for (std::size_t i = 0; i < n; ++i)
    out[i] = checked_value(values[one ? 0 : i], name, x[i], y[i], max_value);
}

/// Runs `call` (which talks to Python) with the GIL held, unless an earlier call failed: true if it
/// returned. Its first exception is kept in `d` for rethrow(), as itself, as density_value's TypeError or
/// ValueError, as a ValueError (a bad value, shape or pair) or RuntimeError (a failed conversion inside
/// pybind11), and later calls are skipped.
template <class Call>
bool guarded(CallableDensity& d, Call&& call) {
  if (d.failed.load(std::memory_order_relaxed)) return false;
  py::gil_scoped_acquire gil;
  try {
    call();
    return true;
  } catch (py::error_already_set& e) {
    d.error.emplace(std::move(e));
  } catch (const py::builtin_exception& e) {  // density_value's TypeError or ValueError
    e.set_error();
    d.error.emplace();
  } catch (const std::domain_error& e) {
    PyErr_SetString(PyExc_ValueError, e.what());
    d.error.emplace();
  } catch (const std::invalid_argument& e) {
    PyErr_SetString(PyExc_ValueError, e.what());
    d.error.emplace();
  } catch (const std::exception& e) {
    PyErr_SetString(PyExc_RuntimeError, e.what());
    d.error.emplace();
  }
  d.failed.store(true, std::memory_order_relaxed);
  return false;
}

}  // namespace

CallableDensity::CallableDensity(py::object f, double max_value, py::object bounds, bool vectorized,
                                 std::string argument)
    : function(std::move(f)), bounds_function(std::move(bounds)), name(std::move(argument)) {
  density.kind = QueryDensity::Kind::kCallback;
  density.callback_max = max_value;
  density.user = this;
  if (vectorized) {
    density.batch_callback = [](void* user, std::size_t n, const double* x, const double* y, double* out) {
      CallableDensity& d = *static_cast<CallableDensity*>(user);
      const bool read = guarded(d, [&] {
        const py::array_t<double> xs(py::ssize_t(n), x),
            ys(py::ssize_t(n), y);  // copies the callable may keep
        read_values(d.function(xs, ys), d.name, n, x, y, d.density.callback_max, out);
      });
      if (!read) std::fill(out, out + n, 0.0);
    };
  } else {
    density.callback = [](void* user, double x, double y) -> double {
      CallableDensity& d = *static_cast<CallableDensity*>(user);
      double v = 0;
      guarded(d, [&] {
        const double at[2] = {x, y};
        const double got = density_value(d.function(x, y), d.name, at, 2);
        v = checked_value(got, d.name, x, y, d.density.callback_max);
      });
      return v;
    };
  }
  if (bounds_function.is_none()) return;
  density.bounds = [](void* user, double x0, double y0, double x1, double y1, double* lo, double* hi) {
    CallableDensity& d = *static_cast<CallableDensity*>(user);
    *lo = *hi = std::numeric_limits<double>::quiet_NaN();  // no bounds, unless the call gives them
    guarded(d, [&] {
      const py::object got = d.bounds_function(x0, y0, x1, y1);
      // A wrong type is a TypeError naming what came back, as a density's own value is (density_value.h).
      const auto type_name = [](const py::handle& o) {
        return std::string(py::str(py::type::of(o).attr("__name__")));
      };
      if (!py::isinstance<py::sequence>(got) || py::isinstance<py::str>(got))
        throw py::type_error("density_bounds must return a pair (lo, hi), got " + type_name(got));
      if (py::len(got) != 2)
        throw std::invalid_argument("density_bounds must return a pair (lo, hi), got " +
                                    std::to_string(py::len(got)) + " values");
      const py::sequence pair = got.cast<py::sequence>();
      double l, h;
      try {
        l = pair[0].cast<double>(), h = pair[1].cast<double>();
      } catch (const py::cast_error&) {
        throw py::type_error("density_bounds must return two real numbers (lo, hi), got (" +
                             type_name(pair[0]) + ", " + type_name(pair[1]) + ")");
      }
      if (!(l >= 0 && l <= h))
        throw std::invalid_argument("density_bounds returned (" + number_text(l) + ", " + number_text(h) +
                                    ") for (" + number_text(x0) + ", " + number_text(y0) + ", " +
                                    number_text(x1) + ", " + number_text(y1) +
                                    "): bounds must satisfy 0 <= lo <= hi");
      *lo = l, *hi = h;
    });
  };
}

void CallableDensity::rethrow() {
  if (error) throw std::move(*error);
}

}  // namespace kdm::python
