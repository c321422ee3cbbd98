#include "output.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "commands.h"
#include "image_io.h"

namespace kdm::cli {
namespace {

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

double auto_radius(const tools::PointSet& points, double width_px, double height_px) {
  // Dots a quarter of the mean spacing across: distinct at uniform density, dark where points crowd.
  const double spacing = std::sqrt(width_px * height_px / std::max<std::size_t>(1, points.size()));
  return std::max(0.5, 0.25 * spacing);
}

}  // namespace

void write_points(const std::string& path, const tools::PointSet& points,
                  const std::vector<std::string>& header, const DrawStyle& style) {
  std::string error;
  if (ends_with(path, ".txt") || ends_with(path, ".csv")) {
    if (!tools::write_point_set(path, points, header, error)) throw CommandError(error);
    return;
  }
  const bool png = ends_with(path, ".png"), svg = ends_with(path, ".svg");
  if (!png && !svg)
    throw CommandError("unknown output format for '" + path + "' (use .txt, .csv, .svg or .png)");
  if (points.dim != 2) throw CommandError("pictures (.png, .svg) need 2D points; write .txt or .csv for 3D");
  const int w = std::max(16, style.width_px);
  const int h = std::max(16, static_cast<int>(std::lround(w / style.aspect)));
  if (double(w) * h > double(1 << 28))  // 768 MiB of RGB: refuse rather than die allocating
    throw CommandError("a picture of " + std::to_string(w) + "x" + std::to_string(h) +
                       " pixels is too large (limit 2^28 pixels); lower --width");
  const double r = style.dot_radius_px > 0 ? style.dot_radius_px : auto_radius(points, w, h);
  if (png) {
    tools::RgbImage image(w, h, 255);
    const std::uint8_t ink[3] = {0, 0, 0};
    for (std::size_t i = 0; i < points.size(); ++i)
      tools::draw_disc(image, points.coords[2 * i] * w, (1 - points.coords[2 * i + 1]) * h, r, ink);
    if (!tools::write_png(path, image, error)) throw CommandError(error);
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
  if (!tools::write_text_file_atomic(path, out.str(), error)) throw CommandError(error);
}

}  // namespace kdm::cli
