// A refused query's problem in words: the kind's static text, and one line naming the parameter, the
// limit it broke and what would be accepted, for logs and error messages (kdm, its CLI and Python share it).
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "kdm/runtime/query.h"

namespace kdm {
namespace {

/// `v` (> 0) to six significant digits, rounded down: advice of "X or less" must itself be accepted.
void six_digits_down(double v, char (&text)[40]) {
  std::snprintf(text, sizeof text, "%.6g", v);
  if (std::strtod(text, nullptr) <= v) return;
  const double unit = std::pow(10.0, std::floor(std::log10(v)) - 5);
  for (double w = std::floor(v / unit) * unit;; w -= unit) {
    std::snprintf(text, sizeof text, "%.6g", w);
    if (std::strtod(text, nullptr) <= v) return;
  }
}

/// snprintf into text[0 … size) that tolerates size 0 (returns the full length, as snprintf does).
std::size_t print(char* text, std::size_t size, const char* format, ...) {
  char none[1];
  va_list args;
  va_start(args, format);
  const int n = std::vsnprintf(size ? text : none, size ? size : 1, format, args);
  va_end(args);
  return n > 0 ? static_cast<std::size_t>(n) : 0;
}

}  // namespace

const char* query_problem_message(QueryProblem::Kind kind) {
  switch (kind) {
    case QueryProblem::Kind::kNone:
      return "no problem";
    case QueryProblem::Kind::kMissingArgument:
      return "a required argument is null or empty (the tile set, an output), or a parallel query's "
             "scratch was not made";
    case QueryProblem::Kind::kNotFinite:
      return "a parameter is not a finite number";
    case QueryProblem::Kind::kNotPositive:
      return "a parameter must be greater than 0 (a C struct's struct_size: at least the limit)";
    case QueryProblem::Kind::kNegative:
      return "a parameter must not be negative";
    case QueryProblem::Kind::kBadDensity:
      return "the density's image (with its max-mip), callback or image sums are missing or do not fit the "
             "query "
             "(or both callbacks are set)";
    case QueryProblem::Kind::kTooManyTiles:
      return "the region covers more tiles than one query may (split it)";
    case QueryProblem::Kind::kDensityTooHigh:
      return "the density asks for more points per tile than the tile set serves in this mode (stable mode "
             "stops at its top level, smooth mode at its depth cap)";
    case QueryProblem::Kind::kCursorMismatch:
      return "the cursor was started by a query with other parameters or on another tile set, or is damaged";
    case QueryProblem::Kind::kBadMode:
      return "the mode is neither stable nor smooth";
    case QueryProblem::Kind::kBadClassCount:
      return "a query needs between 1 and 8 classes";
    case QueryProblem::Kind::kKeysUnsupported:
      return "the tile set's tiles hold more points than a 64-bit point key can number";
    case QueryProblem::Kind::kTooFarFromOrigin:
      return "the region lies too far from the origin (the world's, or the query's for its output) for its "
             "points to keep their places";
    case QueryProblem::Kind::kRunnerIncomplete:
      return "a parallel query's task runner returned before its tasks had done the query";
  }
  return "unknown problem";
}

std::size_t describe_query_problem(const QueryProblem& p, char* text, std::size_t size,
                                   const QueryParameterNames& names) {
  // The parameter as the caller spells it ("--tile-size", "tile_size="), not as QueryParams does.
  const char* parameter = p.parameter ? p.parameter : "";
  char shown[64];
  const char* spelled = std::strcmp(parameter, "scale") == 0       ? names.scale
                        : std::strcmp(parameter, "tile_size") == 0 ? names.tile_size
                                                                   : parameter;
  std::snprintf(shown, sizeof shown, "%s", spelled ? spelled : "");
  const std::size_t len = std::strlen(shown);
  if (len > 0 && shown[len - 1] == '=' && spelled != parameter) shown[len - 1] = 0;
  switch (p.kind) {
    case QueryProblem::Kind::kNone:  // nothing refused: no parameter to name
      return print(text, size, "%s", query_problem_message(p.kind));
    case QueryProblem::Kind::kDensityTooHigh: {
      // Only advice that can be followed: a scale or tile size that fits and is still > 0.
      char scale[120] = "", tile[120] = "", number[40];
      if (p.largest_valid > 0) {
        six_digits_down(p.largest_valid, number);
        std::snprintf(scale, sizeof scale, "%s %s or less", names.scale, number);
      }
      if (p.largest_tile_size > 0) {
        six_digits_down(p.largest_tile_size, number);
        std::snprintf(tile, sizeof tile, "%s %s or less", names.tile_size, number);
      }
      return print(text, size, "%s: %.6g points per tile where it serves at most %.0f; use %s%s%s",
                   query_problem_message(p.kind), p.value, p.limit, scale, *scale && *tile ? ", or " : "",
                   *scale || *tile ? tile : "a lower density");
    }
    case QueryProblem::Kind::kTooManyTiles:
      return print(text, size, "%s: %.6g tiles, at most %.0f; use a larger %s or a smaller region",
                   query_problem_message(p.kind), p.value, p.limit, names.tile_size);
    case QueryProblem::Kind::kTooFarFromOrigin:
      // "origin_x" / "origin_y": the output's numbers are too coarse, not the world's.
      if (std::strncmp(parameter, "origin", 6) == 0 && names.origin)
        return print(text, size,
                     "the region lies too far from the query's origin ('%s') for the output to keep its "
                     "points apart: %.6g from it, at most %.6g for this density; use an %s nearer the "
                     "region, or ask for fewer points per unit area",
                     parameter, p.value, p.limit, names.origin);
      return print(text, size,
                   "the region lies too far from the world origin for doubles to place its points: %.6g "
                   "from it, at most %.6g for this density and region; keep the world's coordinates nearer "
                   "its origin (move the origin), or ask for fewer points per unit area",
                   p.value, p.limit);
    case QueryProblem::Kind::kNotPositive:  // a C struct's struct_size has a limit, its first version's size
      if (p.limit > 0)
        return print(text, size, "'%s' must be at least %.6g, got %.6g", shown, p.limit, p.value);
      return print(text, size, "'%s' must be > 0, got %.6g", shown, p.value);
    case QueryProblem::Kind::kNegative:
      return print(text, size, "'%s' must be >= 0, got %.6g", shown, p.value);
    case QueryProblem::Kind::kKeysUnsupported:
      return print(text, size, "%s: its tiles hold %.0f points, a key numbers at most %.0f; ask for no '%s'",
                   query_problem_message(p.kind), p.value, p.limit, shown);
    case QueryProblem::Kind::kBadDensity:
      if (std::strcmp(parameter, "image_sums") == 0 && p.value > 0)  // built for another class count
        return print(text, size, "'%s' holds the sums of %.6g classes, the query has %.6g", shown, p.limit,
                     p.value);
      if (!std::strstr(parameter, "kind"))  // a function or image missing or doubled: no number to show
        return print(text, size, "%s ('%s')", query_problem_message(p.kind), shown);
      break;
    case QueryProblem::Kind::kCursorMismatch:
      return print(text, size, "%s ('%s')", query_problem_message(p.kind), shown);
    case QueryProblem::Kind::kMissingArgument:  // a null has no value to show
      return print(text, size, "%s: '%s'", query_problem_message(p.kind), shown);
    case QueryProblem::Kind::kRunnerIncomplete: {
      const char* rule =
          "a runner must call the tasks it is given and return once those it started have returned";
      if (p.value == 0)
        return print(text, size, "the task runner ('%s') returned without running any task: %s", shown, rule);
      return print(text, size,
                   "the task runner ('%s') returned before its tasks had done the query (%.6g of %.6g units "
                   "taken): %s",
                   shown, p.value, p.limit, rule);
    }
    case QueryProblem::Kind::kNotFinite:
      if (!std::isfinite(p.value))  // the kind also covers places too far out for a finite value
        return print(text, size, "'%s' is not a finite number (%g)", shown, p.value);
      break;
    case QueryProblem::Kind::kBadMode:
    case QueryProblem::Kind::kBadClassCount:
      break;  // the value refused, below
    default:  // a kind this library does not know (a C caller's number): the number, not a blank field
      return print(text, size, "%s (kind %d)", query_problem_message(p.kind), static_cast<int>(p.kind));
  }
  if (!*shown) return print(text, size, "%s", query_problem_message(p.kind));
  return print(text, size, "%s ('%s' = %.6g)", query_problem_message(p.kind), shown, p.value);
}

}  // namespace kdm
