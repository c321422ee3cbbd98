// What a Python density callable returned, as a density: one check and one wording for kdm.sample,
// kdm.analyze and queries. A wrong type is a TypeError naming it, a bad value a ValueError; both name the
// callable and the point it was called at.
#pragma once

#include <cstddef>
#include <string>

#include "bindings.h"

namespace kdm::python {

/// `value`, which the callable `name` ("density", "classes[1]") returned at `point` (`dim` coordinates),
/// as a double. Throws py::type_error for anything but one real number (None, a str, a complex number,
/// an array of one or more dimensions) and py::value_error for a value that is not finite and >= 0; an
/// exception raised while converting it (its own __float__'s) is left set, as py::error_already_set.
/// The GIL must be held.
double density_value(const py::handle& value, const std::string& name, const double* point, int dim);

/// What a vectorized callable `name` returned for `n` positions (the first at `first`, `dim` coordinates), as
/// float64 values: n of them, or one for all. Throws py::type_error for anything but an array of real
/// numbers (or one real number), naming what came back and the first position, and py::value_error for
/// another shape; the values themselves are the caller's to check. The GIL must be held.
py::array_t<double, py::array::c_style | py::array::forcecast> density_values(const py::handle& value,
                                                                              const std::string& name,
                                                                              std::size_t n,
                                                                              const double* first, int dim);

/// `v` if it is finite and >= 0, else py::value_error in density_value's words.
double finite_density(double v, const std::string& name, const double* point, int dim);

/// "(x, y)" or "(x, y, z)": `point`'s `dim` coordinates as the messages give them.
std::string point_text(const double* point, int dim);

/// `v` as the messages give a number (9 significant digits).
std::string number_text(double v);

}  // namespace kdm::python
