#include "point_output.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include <stdexcept>
#include "image_io.h"

namespace kdm::tools {
namespace {

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

double auto_radius(const PointSet& points, double width_px, double height_px) {
  // Dots a quarter of the mean spacing across: distinct at uniform density, dark where points crowd.
  const double spacing = std::sqrt(width_px * height_px / std::max<std::size_t>(1, points.size()));
  return std::max(0.5, 0.25 * spacing);
}

}  // namespace

void write_points(const std::string& path, const PointSet& points, const std::vector<std::string>& header,
                  const DrawStyle& style) {
  std::string error;
  if (ends_with(path, ".txt") || ends_with(path, ".csv")) {
    if (!write_point_set(path, points, header, error)) throw std::runtime_error(error);
    return;
  }
  const bool png = ends_with(path, ".png"), svg = ends_with(path, ".svg");
  if (!png && !svg)
    throw std::invalid_argument("unknown output format for '" + path + "' (use .txt, .csv, .svg or .png)");
  if (points.dim != 2)
    throw std::invalid_argument("pictures (.png, .svg) need 2D points; write .txt or .csv for 3D");
  const int w = std::max(16, style.width_px);
  const int h = std::max(16, static_cast<int>(std::lround(w / style.aspect)));
  if (double(w) * h > double(1 << 28))  // 768 MiB of RGB: refuse rather than die allocating
    throw std::invalid_argument("a picture of " + std::to_string(w) + "x" + std::to_string(h) +
                                " pixels is too large (limit 2^28 pixels); lower the width");
  const double r = style.dot_radius_px > 0 ? style.dot_radius_px : auto_radius(points, w, h);
  if (png) {
    RgbImage image(w, h, 255);
    const std::uint8_t ink[3] = {0, 0, 0};
    for (std::size_t i = 0; i < points.size(); ++i)
      draw_disc(image, points.coords[2 * i] * w, (1 - points.coords[2 * i + 1]) * h, r, ink);
    if (!write_png(path, image, error)) throw std::runtime_error(error);
    return;
  }
  std::ostringstream out;
  out << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << w << "\" height=\"" << h
      << "\" viewBox=\"0 0 " << w << ' ' << h << "\">\n";
  for (const std::string& line : header) out << "<!-- " << line << " -->\n";
  out << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n<g fill=\"black\">\n";
  out.precision(6);
  for (std::size_t i = 0; i < points.size(); ++i)
    out << "<circle cx=\"" << points.coords[2 * i] * w << "\" cy=\"" << (1 - points.coords[2 * i + 1]) * h
        << "\" r=\"" << r << "\"/>\n";
  out << "</g>\n</svg>\n";
  if (!write_text_file_atomic(path, out.str(), error)) throw std::runtime_error(error);
}

}  // namespace kdm::tools
