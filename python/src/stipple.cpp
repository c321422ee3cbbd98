// kdm._kdm.stipple: one picture of `kdm stipple` (tools/cli/cmd_stipple.cpp) — the runtime's TileStippler
// or the full sampler's stipple_full, the same checks, dot size and file header — returning the dots.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "colour_separation.h"
#include "full_stippler.h"
#include "image_io.h"
#include "point_output.h"
#include "tile_stippler.h"

namespace kdm::python {
namespace {

using tools::DensitySpec;
using Region = std::array<double, 4>;
using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

/// The used inks' (name, "#rrggbb") in class order, which Python makes its Ink names.
py::list names_and_colours(const tools::ColourSeparation& inks) {
  py::list out;
  for (const tools::Ink& ink : inks.inks) out.append(py::make_tuple(ink.name, ink.hex()));
  return out;
}

/// Refuses `white` (> 0: given) for the file `path` unless it is a Radiance picture, as kdm stipple --white
/// does; an empty or missing file is left to the loader to name.
void check_white(const std::string& path, double white) {
  check_number("white", white, 0, false);  // 0: not given
  if (white == 0) return;
  char start[16];
  std::size_t size = 0;
  if (std::FILE* file = std::fopen(path.c_str(), "rb")) {
    size = std::fread(start, 1, sizeof start, file);
    std::fclose(file);
  }
  if (size > 0 && !tools::is_radiance(start, size))
    throw std::invalid_argument("white sets the luminance that is white in a Radiance .hdr picture, and '" +
                                path + "' is none (its white is already its format's)");
}

/// A colour image for the separation: from `rgb` ((rows, columns, 3) in [0, 1], composited on white, row 0
/// at the top) and its `alpha` when given (kdm._checks.colour made them as load_colour_image reads a file),
/// else read from the file `label`, a Radiance picture's luminance `white` being white (0: its largest).
/// A file is read as kdm stipple reads it: `kept` averages a large picture down (tools::KeptPixels).
tools::ColourImage colour_image(const std::string& label, const std::optional<FloatArray>& rgb,
                                const std::optional<FloatArray>& alpha, double white,
                                const tools::KeptPixels& kept = {}) {
  tools::ColourImage image;
  if (!rgb) {
    check_white(label, white);
    std::string error;
    if (!tools::load_colour_image(label, image, error,
                                  kept ? tools::kMaxStipplePixels : tools::kMaxImagePixels, kept, white))
      throw read_error(label, error);
    return image;
  }
  if (rgb->ndim() != 3 || rgb->shape(2) != 3 ||
      (alpha && (alpha->ndim() != 2 || alpha->shape(0) != rgb->shape(0) || alpha->shape(1) != rgb->shape(1))))
    throw std::invalid_argument("a colour image is (rows, columns, 3) with an alpha of (rows, columns)");
  image.height = static_cast<int>(rgb->shape(0)), image.width = static_cast<int>(rgb->shape(1));
  image.pixels.assign(rgb->data(), rgb->data() + rgb->size());
  if (alpha) image.alpha.assign(alpha->data(), alpha->data() + alpha->size());
  return image;
}

/// The deepest zoom a stipple of `region` draws (tools::stipple_zoom; 1 for none or one refused later).
double region_zoom(const std::optional<Region>& region) {
  if (!region) return 1;
  const double width = (*region)[2] - (*region)[0];
  return std::isfinite(width) && width > 0 ? tools::stipple_zoom(region->data()) : 1;
}

/// The image file `path` as kdm stipple reads its one ink (a large picture averaged down for the dots that
/// `points` or `scale` and `region` ask for, tools::stipple_kept_pixels; a Radiance picture's luminance
/// `white` is white, 0: its brightest pixel's).
DensitySpec stipple_density(const std::string& path, double gamma, bool invert, std::int64_t points,
                            double scale, std::optional<Region> region, double white) {
  check_white(path, white);
  const tools::KeptPixels kept = tools::stipple_kept_pixels(scale > 0 ? 0.0 : double(points),
                                                            scale > 0 ? scale : 0.0, region_zoom(region));
  py::gil_scoped_release release;  // an image is read and decoded
  try {
    return tools::parse_density_spec(path, gamma, invert, tools::kMaxStipplePixels, kept, white);
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::runtime_error& e) {  // an image that cannot be read
    throw read_error(path, e.what());
  }
}

py::object stipple(const DensitySpec& spec, const std::string& label, std::int64_t points, double scale,
                   const std::string& method, const std::string& mode, std::optional<Region> region,
                   std::uint64_t seed, const TilesetHandle* tileset, std::optional<std::string> output,
                   int width, double dot_size, int threads, std::optional<std::string> colours, double gamma,
                   double fade, std::optional<FloatArray> rgb, std::optional<FloatArray> alpha,
                   const std::string& paper_width, int height, double white) {
  if (scale > 0) points = 0;  // as kdm stipple: --scale overrides --points
  if (points <= 0 && !(scale > 0 && std::isfinite(scale)))
    throw std::invalid_argument("give points > 0 or a finite scale > 0");
  if (method != "tiles" && method != "full")
    throw std::invalid_argument("method must be 'tiles' or 'full', got '" + method + "'");
  if (mode != "stable" && mode != "smooth")
    throw std::invalid_argument("mode must be 'stable' or 'smooth', got '" + mode + "'");
  if (!(width >= 1 && width <= 65536)) throw std::invalid_argument("width must be 1 to 65536 pixels");
  if (!(height >= 0 && height <= 65536)) throw std::invalid_argument("height must be 1 to 65536 pixels");
  if (output) {
    tools::refuse_writing_over(label, *output, "input image");
    const std::string format = tools::output_format(*output);
    if (std::none_of(tools::kStippleFormats.begin(), tools::kStippleFormats.end(), [&](const char* e) {
          return format == e;
        }))  // as kdm stipple -o says it, before the dots
      throw std::invalid_argument("unknown output format for '" + *output + "' (use " +
                                  tools::extension_list(tools::kStippleFormats) + ")");
  }
  if (!paper_width.empty()) {
    if (!output || tools::output_format(*output) != ".svg")
      throw std::invalid_argument("paper_width sizes an SVG for print: give output a .svg file");
    try {
      tools::check_paper_width(paper_width);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("paper_width ") + e.what());
    }
  }
  check_number("dot_size", dot_size, 0, false);
  if (threads < 0) throw std::invalid_argument("threads must be >= 0 (0: the default count)");
  // Before the dots are placed, as kdm stipple says them.
  const auto picture = [&] {
    return tools::has_extension(*output, ".png") || tools::has_extension(*output, ".svg");
  };
  if (fade > 0 && output && !picture())
    throw std::invalid_argument(
        "fade grows dots in pictures: write .png or .svg (points files have no dot sizes)");
  if (colours && output && !picture() && !tools::has_extension(*output, ".csv"))
    throw std::invalid_argument(
        "colours writes each dot's ink as a class: write .csv (x,y,class), .svg or .png");
  if (tileset && method == "full")
    throw std::invalid_argument("tileset applies to method='tiles' (the full sampler has no tiles)");
  if (spec.kind != DensitySpec::Kind::kImage)
    throw std::invalid_argument("stipple needs an image; for a constant density use kdm.sample");
  // With `colours`, the image file separated into inks, one class of dots each (kdm stipple --colours).
  tools::ColourSeparation inks;
  std::vector<const DensitySpec*> specs = {&spec};
  if (colours) {
    const tools::ColourImage image =
        colour_image(label, rgb, alpha, white,
                     tools::stipple_kept_pixels(scale > 0 ? 0.0 : double(points), scale > 0 ? scale : 0.0,
                                                region_zoom(region)));
    py::gil_scoped_release release;  // a clustering of every pixel: seconds for a large photograph
    inks = tools::separate_colours(image, *colours, gamma);
    specs.clear();
    for (const DensitySpec& channel : inks.channels) specs.push_back(&channel);
  }
  const double aspect = double(spec.width) / spec.height;  // world: [0, aspect] × [0, 1]
  Region uv = {0, 0, 1, 1};
  if (region) {
    uv = *region;
    const bool finite = std::all_of(uv.begin(), uv.end(), [](double v) { return std::isfinite(v); });
    // Past the image's square is blank paper, as a zoom's first frames show it (zoom_regions).
    if (!(finite && uv[0] < uv[2] && uv[1] < uv[3] && uv[0] < 1 && uv[1] < 1 && uv[2] > 0 && uv[3] > 0))
      throw std::invalid_argument(
          "region must be (x0, y0, x1, y1) with x0 < x1 and y0 < y1, meeting the image's [0, 1]^2");
    if (method == "full")
      throw std::invalid_argument("region needs method='tiles' (the full sampler has no zoom)");
  }
  const QueryMode query_mode = mode == "smooth" ? QueryMode::kSmooth : QueryMode::kStable;
  const Tileset* given = tileset ? tileset->set.get() : nullptr;
  if (region && tools::stipple_zoom(uv.data()) >
                    tools::max_stipple_zoom(given ? *given : builtin_tileset(), query_mode) * (1 + 1e-9))
    throw std::invalid_argument(
        tools::stipple_zoom_error("region", given ? *given : builtin_tileset(), query_mode));
  if (height > 0)  // the width follows the picture's shape (kdm stipple --height)
    width = int(std::clamp(std::lround(height * aspect * (uv[2] - uv[0]) / (uv[3] - uv[1])), 1L, 1L << 30));
  double largest_dot = HUGE_VAL;  // pixels, as kdm stipple --dot-size takes them
  if (output && picture()) {
    const int drawn_height = tools::check_picture_size(width, aspect * (uv[2] - uv[0]) / (uv[3] - uv[1]),
                                                       *output, "", height, "width", "height");
    largest_dot = tools::max_dot_radius(width, drawn_height);
    if (dot_size > largest_dot)
      throw std::invalid_argument("dot_size " + tools::shortest(dot_size) +
                                  " is more than a quarter of the " + std::to_string(width) + "x" +
                                  std::to_string(drawn_height) + " picture's shorter side: at most " +
                                  tools::shortest(largest_dot) + " pixels");
  }
  tools::PointSet set;
  std::string thin;  // warned of once the GIL is back
  {
    py::gil_scoped_release release;
    const Tileset& tiles = given ? *given : builtin_tileset();
    // No ink (in colour: in no ink): no dots, as kdm stipple gives an empty picture.
    const bool blank = colours ? specs.empty() : !(spec.max_value() > 0);
    const double whole_dots = blank ? 0.0 : tools::stipple_dot_count(specs, double(points), scale);
    const std::int64_t count = method == "full" && !blank ? tools::full_stipple_count(whole_dots, scale) : 0;
    if (blank) {
      set.dim = 2;
    } else if (method == "full") {
      set = colours ? tools::stipple_full(specs, count, aspect, seed, threads, stop_on_signal)
                    : tools::stipple_full(spec, count, aspect, seed, threads, stop_on_signal);
    } else {
      const tools::TileStippler stippler(specs, tiles, double(points), scale, query_mode, seed);
      thin = tools::TileStippler::thin_tones_warning(stippler.thin_tones(tools::stipple_zoom(uv.data())),
                                                     "gamma", given && given != &builtin_tileset());
      set = stippler.render(uv.data(), fade);
    }
    if (colours && set.classes.empty()) set.classes.assign(set.size(), 0);  // one ink left
    if (output) {
      tools::DrawStyle style;
      style.width_px = width;
      style.paper_width = paper_width;
      style.dots_inside = true;  // for pen plotters, as kdm stipple
      style.height_px = height;
      style.aspect = aspect * (uv[2] - uv[0]) / (uv[3] - uv[1]);
      style.dot_radius_px =
          dot_size > 0 ? dot_size
          : blank      ? 1.0
                       : std::min(tools::stipple_dot_radius(whole_dots, width, aspect, specs), largest_dot);
      if (colours) {
        style.classes = &set.classes, style.inks = inks.layers(), style.blend = inks.blend;
        std::copy(inks.background, inks.background + 3, style.background);
      }
      const std::string how = blank ? "no ink" : method == "full" ? "full KDM sampler" : "runtime tiles";
      try {
        std::vector<std::string> header = {
            tools::stipple_summary(set.size(), how, colours.value_or(""), inks), "image " + label};
        for (std::string& more : tools::stipple_region_header(uv.data(), style.aspect))
          header.push_back(std::move(more));
        tools::write_points(*output, set, header, style);
      } catch (const std::invalid_argument&) {
        throw;
      } catch (const std::runtime_error& e) {
        throw FileError(e.what());
      }
    }
  }
  // Level 2: the warning names the line that called kdm.stipple.
  if (!thin.empty() && PyErr_WarnEx(PyExc_UserWarning, thin.c_str(), 2) < 0) throw py::error_already_set();
  const auto count = static_cast<py::ssize_t>(set.size());
  py::array_t<double> dots = owning_array(std::move(set.coords), {count, py::ssize_t(2)});
  // Ids where the tiles name the dots (empty from the full sampler); kdm.stipple returns what was asked.
  py::object ids = py::none();
  if (!set.ids.empty() && set.ids.size() == std::size_t(count))
    ids = owning_array(std::move(set.ids), {count});
  if (!colours) return py::make_tuple(dots, py::none(), py::none(), ids);
  return py::make_tuple(dots, owning_array(std::move(set.classes), {count}), names_and_colours(inks), ids);
}

/// The inks of an image file as kdm stipple --colours separates them: (k, height, width) float32 densities,
/// row 0 at the top as in the picture, and the inks' names, in class order.
py::tuple separate(const std::string& path, const std::string& colours, double gamma,
                   std::optional<FloatArray> rgb, std::optional<FloatArray> alpha, double white) {
  check_number("gamma", gamma, 0, true);
  const tools::ColourImage image = colour_image(path, rgb, alpha, white);
  tools::ColourSeparation inks;
  {
    py::gil_scoped_release release;
    inks = tools::separate_colours(image, colours, gamma);
  }
  const auto k = static_cast<py::ssize_t>(inks.channels.size());
  py::array_t<float> channels({k, py::ssize_t(image.height), py::ssize_t(image.width)});
  float* out = channels.mutable_data();
  const std::size_t w = std::size_t(image.width), h = std::size_t(image.height);
  for (std::size_t c = 0; c < inks.channels.size(); ++c)
    for (std::size_t y = 0; y < h; ++y)  // DensitySpec's rows run from the bottom
      std::copy_n(inks.channels[c].values.data() + (h - 1 - y) * w, w, out + (c * h + y) * w);
  return py::make_tuple(channels, names_and_colours(inks));
}

}  // namespace

void bind_stipple(py::module_& m) {
  m.def("stipple_density", &stipple_density, py::arg("path"), py::arg("gamma"), py::arg("invert"),
        py::arg("points"), py::arg("scale"), py::arg("region").none(true), py::arg("white") = 0.0,
        "An image file's one ink as kdm stipple reads it (a large picture averaged down for its dots)");
  m.def("separate", &separate, py::arg("path"), py::arg("colours"), py::arg("gamma"),
        py::arg("rgb").none(true) = py::none(), py::arg("alpha").none(true) = py::none(),
        py::arg("white") = 0.0,
        "The inks of an image file as kdm stipple --colours separates them (channels, names)");
  m.def(
      "zoom_regions",
      [](const std::array<double, 4>& region, int frames) {
        py::array_t<double> out({py::ssize_t(frames), py::ssize_t(4)});
        for (int i = 0; i < frames; ++i)
          tools::stipple_frame_region(region.data(), i, frames, out.mutable_data(i, 0));
        return out;
      },
      py::arg("region"), py::arg("frames"), "The UV rectangles of kdm stipple --frames, one row per frame");
  m.def("stipple", &stipple, py::arg("spec"), py::arg("label"), py::arg("points"), py::arg("scale"),
        py::arg("method"), py::arg("mode"), py::arg("region").none(true), py::arg("seed"),
        py::arg("tileset").none(true), py::arg("output").none(true), py::arg("width"), py::arg("dot_size"),
        py::arg("threads"), py::arg("colours").none(true), py::arg("gamma"), py::arg("fade"),
        py::arg("rgb").none(true) = py::none(), py::arg("alpha").none(true) = py::none(),
        py::arg("paper_width") = std::string(), py::arg("height") = 0, py::arg("white") = 0.0,
        "One picture of kdm stipple (with colours: the dots, their inks and the inks' names)");
}

}  // namespace kdm::python
