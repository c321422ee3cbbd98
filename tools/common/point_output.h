// Writing point sets in the formats kdm offers: .txt (UTK/psa), .csv, .svg and .png.
#pragma once

#include <string>
#include <vector>

#include "point_io.h"

namespace kdm::tools {

struct DrawStyle {
  int width_px = 1024;       ///< PNG width; height follows the aspect ratio
  double dot_radius_px = 0;  ///< 0 = automatic from the point count
  double aspect = 1;         ///< width / height of the domain
};

/// Writes `points` (normalised [0,1)^dim, y up) to `path`, choosing the format by extension.
/// Throws std::invalid_argument on an unknown extension or a picture too large, std::runtime_error on a
/// write failure (one-line messages naming the file).
void write_points(const std::string& path, const PointSet& points, const std::vector<std::string>& header,
                  const DrawStyle& style);

}  // namespace kdm::tools
