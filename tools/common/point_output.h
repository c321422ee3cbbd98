// Writing point sets in the formats kdm offers: .txt (UTK/psa), .csv, .svg and .png.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "point_io.h"

namespace kdm::tools {

/// A class's colour in pictures, and its name (an SVG group's id: one layer per pen on a plotter).
struct Ink {
  std::uint8_t rgb[3] = {0, 0, 0};
  std::string name;
  int layer = 0;            ///< its place among an SVG's layers, lowest first (ties in class order)
  std::string hex() const;  ///< "#rrggbb"
};

/// Distinct inks for `count` classes (at most 8), named class-0, class-1, …: black first, then colours.
std::vector<Ink> class_inks(std::size_t count);
/// The colours of class_inks, in words for help texts: "black (class 0), red, ...".
extern const char* const kClassInkNames;

/// How a dot's ink meets what is under it: painted over, multiplied (inks on paper: overlapping cyan and
/// yellow make green) or added (light on black).
enum class Blend { kOver, kMultiply, kAdd };

struct DrawStyle {
  int width_px = 1024;       ///< PNG width; height follows the aspect ratio
  int height_px = 0;         ///< > 0: the height, width_px being the width that shape rounds to
  double dot_radius_px = 0;  ///< 0 = automatic from the point count
  double aspect = 1;         ///< width / height of the domain
  /// Optional: every point's class, drawn in inks[class] (SVG: a layer per ink, in the inks' layer order);
  /// null draws every point black.
  const std::vector<std::uint8_t>* classes = nullptr;
  std::vector<Ink> inks;
  std::uint8_t background[3] = {255, 255, 255};  ///< the paper
  Blend blend = Blend::kOver;
  /// SVG only: the printed width, a number > 0 and a unit (mm, cm, in, pt, pc or px: "180mm"), the height
  /// in proportion; empty: width_px pixels. The drawing keeps its pixel coordinates (viewBox).
  std::string paper_width;
  /// SVG only: every whole circle inside the drawing, its numbers as printed (a pen plotter draws no
  /// further than the paper): the drawing is the picture with a margin of R on every side (R the largest
  /// dot's radius, at most max_dot_radius), its viewBox from (-R, -R), so that every dot stays at its
  /// point in the PNG's pixel coordinates; the printed width (paper_width) is the whole drawing's. Off: the
  /// picture alone, dots cut at its edge.
  bool dots_inside = false;
};

/// The largest dot radius a plotter's SVG of a `width_px` × `height_px` picture takes (DrawStyle::
/// dots_inside, whose margins are as wide): a quarter of its shorter side, in pixels.
double max_dot_radius(int width_px, int height_px);

/// An order of the points `xy` (x, y pairs) for a pen plotter's short travel: from the point nearest the
/// bounding box's low corner, each time to the nearest point not yet drawn (greedy nearest neighbour on a
/// grid; ties to the lower index: the same order every run). SVG pictures write each layer's dots so.
std::vector<std::size_t> plotting_order(const std::vector<double>& xy);

/// Checks `text` as DrawStyle::paper_width takes it; throws std::invalid_argument naming the problem.
void check_paper_width(const std::string& text);

/// Throws std::invalid_argument when `output` names the file `input` (the same path, or a link to it),
/// `what` saying what the input is ("input image"): a result written over what it came from. An `input` of
/// "-" (standard input) is no file.
void refuse_writing_over(const std::string& input, const std::string& output, const std::string& what);

/// The longest side of a picture, in pixels.
inline constexpr int kMaxPictureSide = 65536;

/// The height in pixels of a picture `width_px` wide of `aspect` (width / height) written to `path` (in
/// `format`, output_format's), or `height_px` if > 0 (`width_px` then the width that shape rounds to);
/// throws std::invalid_argument, naming the size and the way out (the caller's `width_option`, or its
/// `height_option` where it has one), for a side past kMaxPictureSide or a PNG past 2^28 pixels
/// (write_points checks it; a caller that computes points for a picture checks it first).
int check_picture_size(int width_px, double aspect, const std::string& path, const std::string& format = "",
                       int height_px = 0, const std::string& width_option = "the width",
                       const std::string& height_option = "");

/// Writes `points` (normalised [0,1)^dim, y up) to `path` (kStandardOutput: standard output) in `format`
/// (".txt", ".csv", ".svg", ".png"; by default the path's extension). Throws std::invalid_argument on an
/// unknown format or a picture too large, std::runtime_error on a write failure (one-line messages naming
/// the file).
void write_points(const std::string& path, const PointSet& points, const std::vector<std::string>& header,
                  const DrawStyle& style, const std::string& format = "");

}  // namespace kdm::tools
