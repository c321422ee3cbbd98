// kdm._kdm.DensitySpec: a density as `--density` names it (tools::DensitySpec: const:V, ramp:R, radial:R or
// an image file), or made from a numpy array of densities or of luminances. Arrays arrive with row 0 at
// the top, as pictures are stored; like the command line, this flips them once, here, to kdm's row 0 at
// the bottom.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "bindings.h"
#include "density_spec.h"
#include "image_io.h"

namespace kdm::python {
namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;
using tools::DensitySpec;

/// A refused value as a person reads it (std::to_string writes 1e300 in 301 digits).
std::string shown(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

/// An image of `rows` × `columns` pixels, checked: no larger than the images the command line reads.
/// Python checks an array's shape by it too, before converting the array.
void check_image_size(const std::string& what, py::ssize_t rows, py::ssize_t columns) {
  if (rows > 0 && columns > 0 && std::uint64_t(rows) * std::uint64_t(columns) > tools::kMaxImagePixels)
    throw std::invalid_argument(what + " has more than 2^26 pixels (the image size limit; " +
                                "kdm.stipple reads a larger picture from its file, averaged down)");
}

/// The array's size, checked: 2-D, not empty, no larger than the images the command line reads.
void check_shape(const Array& a, const char* what, int& width, int& height) {
  if (a.ndim() != 2)
    throw std::invalid_argument(std::string(what) + " must be a 2-D array (rows, columns), got " +
                                std::to_string(a.ndim()) + " dimensions");
  if (a.shape(0) < 1 || a.shape(1) < 1) throw std::invalid_argument(std::string(what) + " is empty");
  check_image_size(what, a.shape(0), a.shape(1));
  height = static_cast<int>(a.shape(0)), width = static_cast<int>(a.shape(1));
}

/// A kImage spec of `a`'s size with row y of the spec taken from row height - 1 - y of `a`: `f(i)` of the
/// index i of a's element.
template <class F>
DensitySpec flipped(const Array& a, const char* what, F f) {
  DensitySpec spec;
  spec.kind = DensitySpec::Kind::kImage;
  spec.text = "array";
  check_shape(a, what, spec.width, spec.height);
  spec.values.resize(std::size_t(spec.width) * spec.height);
  for (int y = 0; y < spec.height; ++y)
    for (int x = 0; x < spec.width; ++x)
      spec.values[std::size_t(y) * spec.width + x] =
          static_cast<float>(f(std::size_t(spec.height - 1 - y) * spec.width + x));
  return spec;
}

DensitySpec from_values(const Array& a) {
  for (py::ssize_t i = 0; i < a.size(); ++i)
    if (!(a.data()[i] >= 0 && a.data()[i] <= FLT_MAX))  // kept as floats, as images are
      throw std::invalid_argument(
          "density array values must be finite and >= 0, at most 3.4e38 (kept as floats), got " +
          shown(a.data()[i]) +
          (a.ndim() == 2
               ? " at [" + std::to_string(i / a.shape(1)) + ", " + std::to_string(i % a.shape(1)) + "]"
               : std::string()));
  return flipped(a, "density array", [&a](std::size_t i) { return a.data()[i]; });
}

/// A 3-D array (depth, height, width) of densities as a kVolume spec: slice k at z near 0 for k = 0, each
/// slice's rows flipped as a 2-D array's are (row 0 at the top).
DensitySpec from_volume(const py::array_t<double, py::array::c_style | py::array::forcecast>& a) {
  if (a.ndim() != 3)
    throw std::invalid_argument("a density volume must be a 3-D array (depth, height, width), got " +
                                std::to_string(a.ndim()) + " dimensions");
  const std::uint64_t d = std::uint64_t(a.shape(0)), rows = std::uint64_t(a.shape(1)),
                      cols = std::uint64_t(a.shape(2));
  if (d < 1 || rows < 1 || cols < 1) throw std::invalid_argument("density volume is empty");
  if (d * rows * cols > tools::kMaxImagePixels)
    throw std::invalid_argument("density volume has more than 2^26 values (the image size limit)");
  const double* in = a.data();
  for (std::uint64_t i = 0; i < d * rows * cols; ++i)
    if (!(in[i] >= 0 && in[i] <= FLT_MAX))  // kept as floats, as images are
      throw std::invalid_argument(
          "density volume values must be finite and >= 0, at most 3.4e38 (kept as floats), got " +
          shown(in[i]) + " at [" + std::to_string(i / (rows * cols)) + ", " +
          std::to_string(i / cols % rows) + ", " + std::to_string(i % cols) + "]");
  DensitySpec spec;
  spec.kind = DensitySpec::Kind::kVolume;
  spec.text = "array";
  spec.width = static_cast<int>(cols), spec.height = static_cast<int>(rows), spec.depth = static_cast<int>(d);
  spec.values.resize(static_cast<std::size_t>(d * rows * cols));
  for (std::uint64_t z = 0; z < d; ++z)
    for (std::uint64_t y = 0; y < rows; ++y)
      for (std::uint64_t x = 0; x < cols; ++x)
        spec.values[static_cast<std::size_t>((z * rows + y) * cols + x)] =
            static_cast<float>(in[(z * rows + (rows - 1 - y)) * cols + x]);
  return spec;
}

/// As tools::parse_density_spec reads a picture: darkness (or luminance, inverted) to the power gamma, by
/// tools::picture_tone. `a` is composited on white, as GreyImage's pixels; `alpha`, if given, their coverage.
DensitySpec from_luminance(const Array& a, double gamma, bool invert, const std::optional<Array>& alpha) {
  check_number("gamma", gamma, 0, true);
  for (py::ssize_t i = 0; i < a.size(); ++i)
    if (!(a.data()[i] >= 0 && a.data()[i] <= 1))
      throw std::invalid_argument(
          "image array values must be luminances in [0, 1], got " + shown(a.data()[i]) +
          (a.data()[i] > 1 ? " (8-bit pixels: pass them as uint8, or divide by 255)" : ""));
  if (alpha) {
    if (alpha->ndim() != a.ndim() || !std::equal(a.shape(), a.shape() + a.ndim(), alpha->shape()))
      throw std::invalid_argument("an image array's alpha must have its shape (rows, columns)");
    for (py::ssize_t i = 0; i < alpha->size(); ++i)
      if (!(alpha->data()[i] >= 0 && alpha->data()[i] <= 1))
        throw std::invalid_argument("image array alpha values must be in [0, 1], got " +
                                    shown(alpha->data()[i]));
  }
  DensitySpec spec = flipped(a, "image array", [&](std::size_t i) {
    return std::pow(tools::picture_tone(a.data()[i], alpha ? alpha->data()[i] : 1.0, invert), gamma);
  });
  spec.inverted = invert;
  return spec;
}

DensitySpec parse(const std::string& text, double gamma, bool invert) {
  py::gil_scoped_release release;  // an image is read and decoded
  try {
    return tools::parse_density_spec(text, gamma, invert);
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::runtime_error& e) {  // an image that cannot be read
    throw read_error(text, e.what());
  }
}

/// A picture file as luminance in [0, 1], row 0 at the top (for tests and examples).
py::array_t<float> load_luminance(const std::string& path) {
  tools::GreyImage image;
  std::string error;
  bool ok;
  {
    py::gil_scoped_release release;
    ok = tools::load_grey_image(path, image, error);
  }
  if (!ok) throw read_error(path, error);
  return owning_array(std::move(image.pixels), {image.height, image.width});
}

const char* kind_name(const DensitySpec& s) {
  switch (s.kind) {
    case DensitySpec::Kind::kConstant:
      return "const";
    case DensitySpec::Kind::kRamp:
      return "ramp";
    case DensitySpec::Kind::kRadial:
      return "radial";
    case DensitySpec::Kind::kVolume:
      return "volume";
    case DensitySpec::Kind::kImage:
      break;
  }
  return "image";
}

}  // namespace

void bind_density(py::module_& m) {
  py::class_<DensitySpec, std::shared_ptr<DensitySpec>>(
      m, "DensitySpec", "A density as --density names it (tools::DensitySpec)")
      .def_static("parse", &parse, py::arg("text"), py::arg("gamma") = 1.0, py::arg("invert") = false,
                  "const:V, ramp:R, radial:R or an image path (darkness**gamma; invert: luminance)")
      .def_static(
          "constant",
          [](double v) {
            check_number("density", v, 0, false);
            DensitySpec spec;
            spec.constant = v;
            spec.text = "number";
            return spec;
          },
          py::arg("value"))
      .def_static("from_values", &from_values, py::arg("values"),
                  "Densities (finite, >= 0), row 0 at the top")
      .def_static(
          "from_volume", &from_volume, py::arg("values"),
          "Densities (finite, >= 0) of shape (depth, height, width): slice 0 at z near 0, each slice's "
          "row 0 at the top")
      .def_static("from_luminance", &from_luminance, py::arg("values"), py::arg("gamma") = 1.0,
                  py::arg("invert") = false, py::arg("alpha").none(true) = py::none(),
                  "Luminances in [0, 1] composited on white, row 0 at the top, and their alpha (None: "
                  "opaque), read as a picture")
      .def_property_readonly("kind", &kind_name)
      .def_readonly("width", &DensitySpec::width)
      .def_readonly("height", &DensitySpec::height)
      .def_readonly("depth", &DensitySpec::depth)
      .def_readonly("text", &DensitySpec::text)
      .def_property_readonly(
          "values",
          [](const DensitySpec& s) {  // an image's densities as from_values takes them: row 0 at the top
            py::array_t<float> out({py::ssize_t(s.height), py::ssize_t(s.width)});
            for (int y = 0; y < s.height; ++y)
              std::copy_n(s.values.data() + std::size_t(s.height - 1 - y) * s.width, s.width,
                          out.mutable_data(y, 0));
            return out;
          },
          "An image's densities (float32, row 0 at the top); empty for other kinds")
      .def_property_readonly("max_value", &DensitySpec::max_value)
      .def_property_readonly("mean_value", &DensitySpec::mean_value)
      .def("__repr__", [](const DensitySpec& s) {
        return "<DensitySpec " + std::string(kind_name(s)) + " " + s.text + ">";
      });
  m.def(
      "check_image_size", &check_image_size, py::arg("what"), py::arg("rows"), py::arg("columns"),
      "Raises ValueError for an image of more pixels than kdm takes (2^26), as the arrays' conversion does");
  m.def("load_luminance", &load_luminance, py::arg("path"),
        "A picture file as luminance in [0, 1] (float32, row 0 at the top)");
}

}  // namespace kdm::python
