// Shared by `kdm stipple` and `kdm query`: the runtime's density from a --density argument, and the
// tile set from --tileset (or the built-in one). Nothing here (nor in what it includes) is the generator's.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "density_spec.h"
#include "kdm/runtime/query.h"
#include "point_io.h"
#include "runtime_query.h"

namespace kdm::cli {

/// A runtime density over the world rectangle [x0, x1) × [y0, y1): constant, an image stretched over it
/// (its texels are the spec's, not a copy), or a test map called back at every candidate.
struct RuntimeDensity {
  QueryDensity density;
  DensityImageView image;
  std::vector<float> mip;
  const tools::DensitySpec* spec = nullptr;
  double x0 = 0, y0 = 0, x1 = 1, y1 = 1;
  double max_value = 0, mean_value = 0;
};

/// Builds the runtime density for `spec` over the given world rectangle; `spec` must outlive it.
std::unique_ptr<RuntimeDensity> make_runtime_density(const tools::DensitySpec& spec, double x0, double y0,
                                                     double x1, double y1);

/// Loads --tileset or returns the built-in set; throws CommandError naming the problem.
const Tileset& tileset_for(const std::string& path, Tileset& storage);

/// "stable" or "smooth" (the --mode values, checked by CLI11) as a QueryMode.
inline QueryMode parse_mode(const std::string& text) {
  return text == "smooth" ? QueryMode::kSmooth : QueryMode::kStable;
}

/// Parses `text`, the value of `option` (named in errors), as "x0,y0,x1,y1": four finite numbers with
/// x0 < x1 and y0 < y1. Throws CommandError.
void parse_rect(const std::string& text, const char* option, double r[4]);

/// How refusals name the query's parameters on the command line.
inline constexpr tools::ParameterNames kCommandLineNames{"--scale", "--tile-size"};

}  // namespace kdm::cli
