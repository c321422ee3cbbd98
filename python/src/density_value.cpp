// A Python density callable's value (density_value.h).
#include "density_value.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <new>

namespace kdm::python {
namespace {

[[noreturn]] void wrong_type(const std::string& what, const std::string& name, const double* point, int dim) {
  throw py::type_error(name + " callable returned " + what + " at " + point_text(point, dim) +
                       ": a density must be a real number");
}

std::string type_name(const py::handle& value) {
  return py::str(py::type::handle_of(value).attr("__name__"));
}

}  // namespace

std::string number_text(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", v);
  return text;
}

std::string point_text(const double* point, int dim) {
  std::string text = "(";
  for (int k = 0; k < dim; ++k) text += (k ? ", " : "") + number_text(point[k]);
  return text + ")";
}

double finite_density(double v, const std::string& name, const double* point, int dim) {
  if (v >= 0 && v < std::numeric_limits<double>::infinity()) return v;
  throw py::value_error(name + " callable returned " + number_text(v) + " at " + point_text(point, dim) +
                        ": a density must be finite and >= 0");
}

py::array_t<double, py::array::c_style | py::array::forcecast> density_values(const py::handle& value,
                                                                              const std::string& name,
                                                                              std::size_t n,
                                                                              const double* first, int dim) {
  using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;
  const auto wrong_type = [&](const std::string& what) {
    const double none[3] = {0, 0, 0};
    throw py::type_error(name + " callable returned " + what + " for " + std::to_string(n) +
                         " positions from " + point_text(n ? first : none, dim) +
                         ": a vectorized density must return an array of real numbers");
  };
  const std::string type = type_name(value);
  // Cast to double, None would become NaN and a complex number lose its imaginary part.
  if (value.is_none() || PyComplex_Check(value.ptr())) wrong_type(type);
  const py::array raw = py::array::ensure(value);
  if (!raw) wrong_type(type);
  const char kind = raw.dtype().kind();
  if (kind != 'b' && kind != 'i' && kind != 'u' && kind != 'f')
    wrong_type(py::isinstance<py::array>(value) ? type + " of dtype " + std::string(py::str(raw.dtype()))
                                                : type);
  const Array v = Array::ensure(raw);  // real numbers as float64: fails only where memory runs out
  if (!v) throw std::bad_alloc();
  const bool one = v.ndim() == 0 || (v.ndim() == 1 && v.shape(0) == 1);
  if (!one && !(v.ndim() == 1 && std::size_t(v.shape(0)) == n)) {
    std::string shape;
    for (py::ssize_t k = 0; k < v.ndim(); ++k) shape += (k ? ", " : "") + std::to_string(v.shape(k));
    throw py::value_error(name + " callable returned shape (" + shape + ") for " + std::to_string(n) +
                          " positions: a vectorized density must return one value per position");
  }
  return v;
}

double density_value(const py::handle& value, const std::string& name, const double* point, int dim) {
  PyObject* v = value.ptr();
  if (PyFloat_Check(v)) return finite_density(PyFloat_AS_DOUBLE(v), name, point, dim);  // numpy's float64 too
  // A complex number's __float__ (numpy's) would drop its imaginary part, and an array's would take its one
  // element: neither is a density.
  if (PyComplex_Check(v)) wrong_type(type_name(value), name, point, dim);
  if (py::isinstance<py::array>(value)) {
    const py::array a = py::reinterpret_borrow<py::array>(value);
    if (a.ndim() > 0) {
      std::string shape;
      for (py::ssize_t k = 0; k < a.ndim(); ++k) shape += (k ? ", " : "") + std::to_string(a.shape(k));
      wrong_type(type_name(value) + " of shape (" + shape + (a.ndim() == 1 ? ",)" : ")"), name, point, dim);
    }
    if (a.dtype().kind() == 'c') wrong_type(type_name(value) + " of dtype complex", name, point, dim);
  } else if (!PyLong_Check(v) && py::hasattr(value, "dtype")) {  // a numpy scalar: complex64 is no complex
    const py::object dtype = value.attr("dtype");
    if (py::hasattr(dtype, "kind") && py::str(dtype.attr("kind")).cast<std::string>() == "c")
      wrong_type(type_name(value), name, point, dim);
  }
  double got = PyFloat_AsDouble(v);  // an int, a bool, a numpy number, anything with __float__
  if (got == -1 && PyErr_Occurred()) {
    if (PyErr_ExceptionMatches(PyExc_OverflowError) && PyLong_Check(v)) {  // an int past a double's range
      PyErr_Clear();
      got = (value < py::int_(0) ? -1 : 1) * std::numeric_limits<double>::infinity();
    } else if (PyErr_ExceptionMatches(PyExc_TypeError)) {
      PyErr_Clear();
      wrong_type(type_name(value), name, point, dim);
    } else {
      throw py::error_already_set();  // raised by its own __float__
    }
  }
  return finite_density(got, name, point, dim);
}

}  // namespace kdm::python
