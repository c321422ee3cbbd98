// Writing point sets in the formats the command line offers: .txt (UTK/psa), .csv, .svg and .png.
#pragma once

#include <string>
#include <vector>

#include "point_io.h"

namespace kdm::cli {

struct DrawStyle {
  int width_px = 1024;       ///< PNG width; height follows the aspect ratio
  double dot_radius_px = 0;  ///< 0 = automatic from the point count
  double aspect = 1;         ///< width / height of the domain
};

/// Writes `points` (normalized [0,1)^dim, y up) to `path`, choosing the format by extension.
/// Throws CommandError on an unknown extension or a write failure.
void write_points(const std::string& path, const tools::PointSet& points,
                  const std::vector<std::string>& header, const DrawStyle& style);

}  // namespace kdm::cli
