#include "point_output.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>

#include <stdexcept>
#include "image_io.h"

namespace kdm::tools {
namespace {

double auto_radius(const PointSet& points, double width_px, double height_px) {
  // Dots a quarter of the mean spacing across: distinct at uniform density, dark where points crowd.
  const double spacing = std::sqrt(width_px * height_px / std::max<std::size_t>(1, points.size()));
  return std::max(0.5, 0.25 * spacing);
}

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

}  // namespace

std::string Ink::hex() const {
  char text[8];
  std::snprintf(text, sizeof text, "#%02x%02x%02x", rgb[0], rgb[1], rgb[2]);
  return text;
}

const char* const kClassInkNames = "black (class 0), red, blue, green, orange, purple, brown, pink (class 7)";

std::vector<Ink> class_inks(std::size_t count) {
  // The order of kClassInkNames.
  static constexpr std::uint8_t kColours[8][3] = {{0, 0, 0},     {214, 39, 40},  {31, 119, 180},
                                                  {44, 160, 44}, {255, 127, 14}, {148, 103, 189},
                                                  {140, 86, 75}, {227, 119, 194}};
  std::vector<Ink> inks(std::min<std::size_t>(count, 8));
  for (std::size_t k = 0; k < inks.size(); ++k) {
    std::copy(kColours[k], kColours[k] + 3, inks[k].rgb);
    inks[k].name = "class-" + std::to_string(k);
  }
  return inks;
}

void refuse_writing_over(const std::string& input, const std::string& output, const std::string& what) {
  std::error_code unknown;
  if (output == input || std::filesystem::equivalent(input, output, unknown))
    throw std::invalid_argument("the output '" + output + "' is the " + what + ": write another file");
}

int check_picture_size(int width_px, double aspect, const std::string& path, const std::string& format,
                       int height_px) {
  const int w = std::max(1, width_px);
  const double h = height_px > 0 ? height_px : std::max(1.0, std::round(w / aspect));  // the picture's shape
  const auto refuse = [&](const char* limit) {
    throw std::invalid_argument("a picture of " + std::to_string(w) + "x" +
                                std::to_string(std::llround(std::min(h, 1e18))) + " pixels is too large (" +
                                limit + "); lower the width" + (height_px > 0 ? " or height" : ""));
  };
  if (output_format(path, format) !=
      ".png") {  // an SVG's size is two numbers: only the height's int is a limit
    if (!(h <= double(1 << 30))) refuse("limit 2^30 pixels high");
  } else if (!(double(w) * h <= double(1 << 28))) {  // 768 MiB of RGB and 512 of coverage: refuse, not die
    refuse("limit 2^28 pixels");
  }
  return static_cast<int>(h);
}

namespace {

/// `text` as a paper width: a plain decimal number (digits, at most one point, no sign or exponent) and a
/// unit; false if it is not one.
bool parse_paper_width(const std::string& text, double& value, std::string& unit) {
  std::size_t i = 0, digits = 0, points = 0;
  for (; i < text.size() && (std::isdigit(static_cast<unsigned char>(text[i])) || text[i] == '.'); ++i)
    (text[i] == '.' ? points : digits) += 1;
  if (digits == 0 || points > 1 || text[i - 1] == '.') return false;
  unit = text.substr(i);
  value = std::strtod(text.substr(0, i).c_str(), nullptr);
  return unit == "mm" || unit == "cm" || unit == "in" || unit == "pt" || unit == "pc" || unit == "px";
}

}  // namespace

void check_paper_width(const std::string& text) {
  double value = 0;
  std::string unit;
  if (!parse_paper_width(text, value, unit) || !(value >= 0.001 && value <= 1e6))
    throw std::invalid_argument(
        "must be a number from 0.001 to 1000000 and a unit (mm, cm, in, pt, pc or px), "
        "as 180mm or 7.5in, got '" +
        text + "'");
}

void write_points(const std::string& path, const PointSet& points, const std::vector<std::string>& header,
                  const DrawStyle& style, const std::string& format) {
  std::string error;
  const std::string ext = output_format(path, format);
  if (ext == ".txt" || ext == ".csv" || ext == ".npy") {
    if (!write_point_set(path, points, header, error, ext)) throw std::runtime_error(error);
    return;
  }
  const bool png = ext == ".png", svg = ext == ".svg";
  if (!png && !svg)
    throw std::invalid_argument("unknown output format for '" + path +
                                "' (use .txt, .csv, .npy, .svg or .png)");
  if (points.dim != 2)
    throw std::invalid_argument("pictures (.png, .svg) need 2D points; write .txt, .csv or .npy for 3D");
  const int w = std::max(1, style.width_px);
  const int h = check_picture_size(style.width_px, style.aspect, path, ext, style.height_px);
  const double r = style.dot_radius_px > 0 ? style.dot_radius_px : auto_radius(points, w, h);
  // A dot wider than the picture only blackens it, and painting large dots costs their area each.
  if (!(r <= std::max(w, h)))
    throw std::invalid_argument("a dot size of " + number(r) + " pixels is larger than the " +
                                std::to_string(w) + "x" + std::to_string(h) + " picture");
  if (png && double(points.size()) * (2 * r + 3) * (2 * r + 3) > double(std::uint64_t(1) << 32))
    throw std::invalid_argument("painting " + std::to_string(points.size()) + " dots of " + number(r) +
                                " pixels would take too long: lower the dot size or the point count");
  const bool classed = style.classes != nullptr;
  if (classed && style.classes->size() != points.size())
    throw std::invalid_argument("a picture's classes do not match its points");
  if (!points.sizes.empty() && points.sizes.size() != points.size())
    throw std::invalid_argument("a picture's dot sizes do not match its points");
  const auto radius = [&](std::size_t i) { return points.sizes.empty() ? r : r * points.sizes[i]; };
  std::vector<Ink> inks = style.inks.empty() ? class_inks(1) : style.inks;
  if (classed)
    for (std::uint8_t c : *style.classes)
      if (c >= inks.size()) throw std::invalid_argument("a point's class has no ink");
  // The inks in their layer order (a plotter's pens, the SVG's layers).
  std::vector<std::size_t> order(classed ? inks.size() : 1);
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return inks[a].layer < inks[b].layer; });
  if (png) {  // each ink's dots as one coverage layer, laid on the paper in turn
    RgbImage image(w, h, 255);
    for (std::size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = style.background[i % 3];
    CoverageImage layer(w, h);
    for (const std::size_t k : order) {
      std::fill(layer.values.begin(), layer.values.end(), 0);
      for (std::size_t i = 0; i < points.size(); ++i)
        if (!classed || (*style.classes)[i] == k)
          add_disc(layer, points.coords[2 * i] * w, (1 - points.coords[2 * i + 1]) * h, radius(i));
      composite(image, layer, inks[k].rgb, static_cast<int>(style.blend));
    }
    if (!write_png(path, image, error)) throw std::runtime_error(error);
    return;
  }
  std::ostringstream out;
  // Each group an Inkscape layer, so that plotter software draws a layer per pen; the paper is a layer of
  // its own, to hide before plotting (a plotter would trace its outline).
  std::string width = std::to_string(w), height = std::to_string(h);
  if (!style.paper_width.empty()) {  // the same drawing, printed at a size: a plotter's or printer's units
    check_paper_width(style.paper_width);
    double value = 0;
    std::string unit;
    parse_paper_width(style.paper_width, value, unit);
    char text[64];
    std::snprintf(text, sizeof text, "%.10g%s", value, unit.c_str());
    width = text;
    std::snprintf(text, sizeof text, "%.10g%s", value * h / w, unit.c_str());
    height = text;
  }
  out << "<svg xmlns=\"http://www.w3.org/2000/svg\" "
         "xmlns:inkscape=\"http://www.inkscape.org/namespaces/inkscape\" width=\""
      << width << "\" height=\"" << height << "\" viewBox=\"0 0 " << w << ' ' << h << "\">\n";
  for (const std::string& line : header) out << "<!-- " << comment_safe(line) << " -->\n";
  const auto layer = [&](const std::string& name) {
    return "<g id=\"" + name + "\" inkscape:groupmode=\"layer\" inkscape:label=\"" + name + "\"";
  };
  Ink paper;
  std::copy(style.background, style.background + 3, paper.rgb);
  out << layer("paper") << "><rect width=\"100%\" height=\"100%\" fill=\"" << paper.hex() << "\"/></g>\n";
  out.precision(6);
  for (const std::size_t k : order) {
    const char* blend = style.blend == Blend::kMultiply ? " style=\"mix-blend-mode:multiply\""
                        : style.blend == Blend::kAdd    ? " style=\"mix-blend-mode:screen\""
                                                        : "";
    out << layer(classed ? inks[k].name : "points") << " fill=\"" << inks[k].hex() << "\"" << blend << ">\n";
    for (std::size_t i = 0; i < points.size(); ++i)
      if ((!classed || (*style.classes)[i] == k) && radius(i) > 0)
        out << "<circle cx=\"" << points.coords[2 * i] * w << "\" cy=\"" << (1 - points.coords[2 * i + 1]) * h
            << "\" r=\"" << radius(i) << "\"/>\n";
    out << "</g>\n";
  }
  out << "</svg>\n";
  if (!write_text_file_atomic(path, out.str(), error)) throw std::runtime_error(error);
}

}  // namespace kdm::tools
