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
#include "spec_density.h"

namespace kdm::cli {

/// Loads --tileset or returns the built-in set; throws CommandError naming the problem.
const Tileset& tileset_for(const std::string& path, Tileset& storage);

/// "stable" or "smooth" (the --mode values, checked by CLI11) as a QueryMode.
inline QueryMode parse_mode(const std::string& text) {
  return text == "smooth" ? QueryMode::kSmooth : QueryMode::kStable;
}

/// Warns on standard error, as `command`, that smooth mode gives stable positions when `tiles` has no glide
/// track (the runtime's rule, said rather than refused: the points are still right, only not gliding).
void warn_without_glide_track(const char* command, const Tileset& tiles, QueryMode mode);

/// Parses `text`, the value of `option` (named in errors), as "x0,y0,x1,y1": four finite numbers with
/// x0 < x1 and y0 < y1. Throws CommandError.
void parse_rect(const std::string& text, const char* option, double r[4]);

/// How refusals name the query's parameters on the command line.
inline constexpr QueryParameterNames kCommandLineNames{"--scale", "--tile-size", nullptr};

}  // namespace kdm::cli
