// Shared by `kdm stipple` and `kdm query`: the runtime's density from a --density argument, and the
// tile set from --tileset (or the built-in one).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "density_arg.h"
#include "kdm/runtime/query.h"

namespace kdm::cli {

/// A runtime density over the world rectangle [x0, x1) × [y0, y1): constant, or the image stretched over
/// it (rows flipped so that y grows upwards). Owns the image data and its max-mip.
struct RuntimeDensity {
  QueryDensity density;
  DensityImage image;
  std::vector<float> values, mip;
  double max_value = 0, mean_value = 0;
};

/// Builds the runtime density for `arg` (image or constant) over the given world rectangle.
std::unique_ptr<RuntimeDensity> make_runtime_density(const DensityArg& arg, double x0, double y0, double x1,
                                                     double y1);

/// Loads --tileset or returns the built-in set; throws CommandError naming the problem.
const Tileset& tileset_for(const std::string& path, Tileset& storage);

/// Most points a command-line query collects (2^25, 1 GiB as QueryPoint) before it gives up.
inline constexpr std::size_t kMaxCommandLinePoints = std::size_t(1) << 25;

/// Runs a query to completion into `out` (growing it), throwing CommandError on bad parameters or when
/// more than kMaxCommandLinePoints points would be emitted.
void query_all(const Tileset& tileset, const QueryParams& params, std::vector<QueryPoint>& out);

}  // namespace kdm::cli
