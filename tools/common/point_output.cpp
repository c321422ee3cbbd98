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
#include "atomic_file.h"
#include "picture.h"

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

/// An SVG circle's number as the picture prints it (6 significant digits), read back.
double as_printed(double v) {
  return std::strtod(number(v).c_str(), nullptr);
}

/// A dot's centre `v` (in [lo + r, hi − r], v >= 0) such that the printed circle, centre and radius as a
/// reader parses them, lies within [lo, hi]: rounding to 6 digits could carry it past the edge by
/// thousandths of a pixel, so there it is moved in by the last printed digit while it does. Other centres
/// are kept.
double printed_within(double v, double lo, double hi, double printed_r) {
  double p = as_printed(v);
  if (p - printed_r >= lo && p + printed_r <= hi) return v;
  for (int step = 0; step < 4 && p > 0 && (p - printed_r < lo || p + printed_r > hi); ++step) {
    const double digit = std::pow(10.0, std::floor(std::log10(p)) - 5);
    p = as_printed(p - printed_r < lo ? p + digit : p - digit);
  }
  return p;
}

}  // namespace

std::vector<std::size_t> plotting_order(const std::vector<double>& xy) {
  const std::size_t n = xy.size() / 2;
  std::vector<std::size_t> order;
  order.reserve(n);
  if (n == 0) return order;
  // A grid of about two points a cell over the points' bounding box; each cell's points in a list.
  double lo[2] = {xy[0], xy[1]}, hi[2] = {xy[0], xy[1]};
  for (std::size_t i = 0; i < n; ++i)
    for (int a = 0; a < 2; ++a)
      lo[a] = std::min(lo[a], xy[2 * i + a]), hi[a] = std::max(hi[a], xy[2 * i + a]);
  const double w = std::max(hi[0] - lo[0], 1e-300), h = std::max(hi[1] - lo[1], 1e-300);
  const double cell = std::max(std::sqrt(w * h / (0.5 * double(n))), std::max(w, h) / 4096);
  const int gx = std::max(1, std::min(4096, int(w / cell) + 1)),
            gy = std::max(1, std::min(4096, int(h / cell) + 1));
  const auto cell_of = [&](std::size_t i, int a) {
    const int g = a ? gy : gx;
    return std::clamp(int((xy[2 * i + a] - lo[a]) / cell), 0, g - 1);
  };
  std::vector<std::size_t> start(std::size_t(gx) * gy + 1, 0), items(n);
  for (std::size_t i = 0; i < n; ++i) ++start[std::size_t(cell_of(i, 1)) * gx + cell_of(i, 0) + 1];
  for (std::size_t c = 1; c < start.size(); ++c) start[c] += start[c - 1];
  {
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) items[fill[std::size_t(cell_of(i, 1)) * gx + cell_of(i, 0)]++] = i;
  }
  std::vector<std::size_t> alive(start.size() - 1);  // points left per cell, kept at the front of its list
  for (std::size_t c = 0; c < alive.size(); ++c) alive[c] = start[c + 1] - start[c];
  std::vector<std::size_t> where(n);  // each point's place in `items`
  for (std::size_t k = 0; k < n; ++k) where[items[k]] = k;
  const auto take = [&](std::size_t i) {
    const std::size_t c = std::size_t(cell_of(i, 1)) * gx + cell_of(i, 0);
    const std::size_t last = start[c] + --alive[c], at = where[i];
    std::swap(items[at], items[last]);
    where[items[at]] = at, where[items[last]] = last;
    order.push_back(i);
  };
  // From the point nearest the bounding box's corner at the origin (the top left of a picture), each time
  // to the nearest point left: rings of cells around the current one until no closer point can lie
  // farther out.
  std::size_t current = 0;
  for (std::size_t i = 1; i < n; ++i)
    if (xy[2 * i] + xy[2 * i + 1] < xy[2 * current] + xy[2 * current + 1]) current = i;
  take(current);
  while (order.size() < n) {
    const int cx = cell_of(current, 0), cy = cell_of(current, 1);
    std::size_t best = n;
    double best_d = HUGE_VAL;
    for (int r = 0;; ++r) {
      // Every point in ring r or beyond is at least (r - 1) cells away.
      if (best < n && best_d <= (double(r) - 1) * (r - 1) * cell * cell) break;
      if (cx - r < 0 && cy - r < 0 && cx + r >= gx && cy + r >= gy) break;
      const auto visit = [&](int x, int y) {
        const std::size_t c = std::size_t(y) * gx + x;
        for (std::size_t k = start[c]; k < start[c] + alive[c]; ++k) {
          const std::size_t j = items[k];
          const double dx = xy[2 * j] - xy[2 * current], dy = xy[2 * j + 1] - xy[2 * current + 1];
          const double d = dx * dx + dy * dy;
          if (d < best_d || (d == best_d && j < best)) best = j, best_d = d;
        }
      };
      for (int y = std::max(0, cy - r); y <= std::min(gy - 1, cy + r); ++y)
        if (y == cy - r || y == cy + r) {
          for (int x = std::max(0, cx - r); x <= std::min(gx - 1, cx + r); ++x) visit(x, y);
        } else {
          if (cx - r >= 0) visit(cx - r, y);
          if (cx + r < gx) visit(cx + r, y);
        }
    }
    take(best);
    current = best;
  }
  return order;
}

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
  if (input == "-") return;  // standard input: no file to write over, and "-o -" is standard output
  std::error_code unknown;
  if (output == input || std::filesystem::equivalent(input, output, unknown))
    throw std::invalid_argument("the output '" + output + "' is the " + what + ": write another file");
}

double max_dot_radius(int width_px, int height_px) {
  return std::min(width_px, height_px) / 4.0;
}

int check_picture_size(int width_px, double aspect, const std::string& path, const std::string& format,
                       int height_px, const std::string& width_option, const std::string& height_option) {
  const int w = std::max(1, width_px);
  const double h = height_px > 0 ? height_px : std::max(1.0, std::round(w / aspect));  // the picture's shape
  const std::string size =
      "a picture of " + std::to_string(w) + "x" + std::to_string(std::llround(std::min(h, 1e18))) + " pixels";
  // The way out: lower the side that was given, or size a tall picture by its height where one can.
  const std::string lower = "lower " + (height_px > 0 ? height_option : width_option);
  if (!(h <= kMaxPictureSide))
    throw std::invalid_argument(
        size + " is too tall (sides 1 to 65536 pixels); " +
        (height_px > 0 || height_option.empty()
             ? lower
             : "give " + height_option + " (the width follows its shape) or " + lower));
  if (w > kMaxPictureSide)
    throw std::invalid_argument(size + " is too wide (sides 1 to 65536 pixels); " + lower);
  // 768 MiB of RGB and 512 of coverage: refused, not died of. (An SVG's size is two numbers.)
  if (output_format(path, format) == ".png" && !(double(w) * h <= double(1 << 28)))
    throw std::invalid_argument(size + " is too large (limit 2^28 pixels); " + lower);
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
  if (svg && style.dots_inside && !(r <= max_dot_radius(w, h)))  // margins half the picture wide
    throw std::invalid_argument("a dot radius of " + number(r) + " pixels is more than a quarter of the " +
                                std::to_string(w) + "x" + std::to_string(h) + " picture's shorter side (" +
                                number(max_dot_radius(w, h)) + " pixels)");
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
  // Each group an Inkscape layer, so that plotter software draws a layer per pen. White paper is no
  // element at all (a plotter would trace a rectangle's outline as a frame); paper of another colour is a
  // rectangle in a layer of its own whose name starts with % (AxiDraw's mark for a layer it does not plot;
  // hide it in other plotter software).
  // For a plotter, a margin as wide as the largest dot around the picture holds every whole circle, each
  // at its point: the drawing's coordinates stay the PNG's pixels (the viewBox starts at -margin).
  double largest = 0;
  for (std::size_t i = 0; i < points.size(); ++i) largest = std::max(largest, radius(i));
  const double margin = style.dots_inside ? as_printed(largest) : 0.0;
  char text[64];
  const auto print = [&](const char* format, double v, const char* unit = "") {
    std::snprintf(text, sizeof text, format, v, unit);
    return std::string(text);
  };
  const double drawn_w = w + 2 * margin, drawn_h = h + 2 * margin;
  std::string width = print("%.10g%s", drawn_w), height = print("%.10g%s", drawn_h);
  if (!style.paper_width.empty()) {  // the same drawing, printed at a size: a plotter's or printer's units
    check_paper_width(style.paper_width);
    double value = 0;
    std::string unit;
    parse_paper_width(style.paper_width, value, unit);
    width = print("%.10g%s", value, unit.c_str());
    height = print("%.10g%s", value * drawn_h / drawn_w, unit.c_str());
  }
  const std::string view_box = print("%.10g", margin > 0 ? -margin : 0.0) + ' ' +
                               print("%.10g", margin > 0 ? -margin : 0.0) + ' ' + print("%.10g", drawn_w) +
                               ' ' + print("%.10g", drawn_h);
  Ink paper;
  std::copy(style.background, style.background + 3, paper.rgb);
  const bool white = paper.hex() == "#ffffff";
  out << "<svg xmlns=\"http://www.w3.org/2000/svg\" "
         "xmlns:inkscape=\"http://www.inkscape.org/namespaces/inkscape\" width=\""
      << width << "\" height=\"" << height << "\" viewBox=\"" << view_box << "\""
      << (white ? "" : " style=\"background-color:" + paper.hex() + "\"") << ">\n";
  for (const std::string& line : header) out << "<!-- " << comment_safe(line) << " -->\n";
  const auto layer = [&](const std::string& name, const std::string& label) {
    return "<g id=\"" + name + "\" inkscape:groupmode=\"layer\" inkscape:label=\"" + label + "\"";
  };
  if (!white)
    out << layer("paper", "% paper (not plotted)") << "><rect x=\"" << view_box.substr(0, view_box.find(' '))
        << "\" y=\"" << view_box.substr(0, view_box.find(' ')) << "\" width=\"100%\" height=\"100%\" fill=\""
        << paper.hex() << "\" stroke=\"none\"/></g>\n";
  out.precision(6);        // as number() prints
  std::vector<double> xy;  // a layer's dot centres in the picture's pixels
  std::vector<double> radii;
  for (const std::size_t k : order) {
    const char* blend = style.blend == Blend::kMultiply ? " style=\"mix-blend-mode:multiply\""
                        : style.blend == Blend::kAdd    ? " style=\"mix-blend-mode:screen\""
                                                        : "";
    const std::string name = classed ? inks[k].name : "points";
    out << layer(name, name) << " fill=\"" << inks[k].hex() << "\"" << blend << ">\n";
    xy.clear(), radii.clear();
    for (std::size_t i = 0; i < points.size(); ++i)
      if ((!classed || (*style.classes)[i] == k) && radius(i) > 0) {
        const double ri = radius(i);
        const auto inside = [&](double v, double side) {  // (a point past [0, 1] clamped onto the edge)
          return style.dots_inside
                     ? printed_within(std::clamp(v, 0.0, side), -margin, side + margin, as_printed(ri))
                     : v;
        };
        xy.push_back(inside(points.coords[2 * i] * w, w));
        xy.push_back(inside((1 - points.coords[2 * i + 1]) * h, h));
        radii.push_back(ri);
      }
    // In plotting order: each dot the nearest of those left to the one before (plotting_order).
    for (const std::size_t i : plotting_order(xy))
      out << "<circle cx=\"" << xy[2 * i] << "\" cy=\"" << xy[2 * i + 1] << "\" r=\"" << radii[i] << "\"/>\n";
    out << "</g>\n";
  }
  out << "</svg>\n";
  if (!write_text_file_atomic(path, out.str(), error)) throw std::runtime_error(error);
}

}  // namespace kdm::tools
