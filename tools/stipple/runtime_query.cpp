#include "runtime_query.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace kdm::tools {
std::string describe(const QueryProblem& p, const QueryParameterNames& names) {
  char text[400];
  describe_query_problem(p, text, sizeof text, names);
  return text;
}

std::string tile_size_warning(const TileSizeAdvice& advice, const char* tile_size) {
  char text[400];
  if (advice.kind == TileSizeAdvice::Kind::kUnderOnePoint)
    std::snprintf(
        text, sizeof text,
        "at most %.3g points per tile; below 1 a tile's expected count rounds to steps of 1/%zu of a "
        "point%s (use a %s of at least %.3g)",
        advice.points_per_tile, advice.tiles,
        advice.points_per_tile < 0.5 / double(advice.tiles) ? ", and this one to none" : "", tile_size,
        advice.tile_size);
  else if (advice.kind == TileSizeAdvice::Kind::kUnderCoarsestLevel)
    std::snprintf(
        text, sizeof text,
        "at most %.3g points per tile, under the tile set's coarsest level (%.0f): a tile then gives "
        "part of that level, the same few places in every tile where the density is that low, a pattern "
        "that repeats with the tiles (use a %s of at least %.3g)",
        advice.points_per_tile, advice.coarsest, tile_size, advice.tile_size);
  else
    return "";
  return text;
}

std::vector<std::string> class_count_warnings(const Tileset& tileset, const std::vector<double>& peaks,
                                              double scale, double tile_size, const char* tile_size_name) {
  std::vector<std::string> warnings;
  if (tileset.empty() || tileset.data().level_nominal.empty()) return warnings;
  const double area = scale * tile_size * tile_size, coarsest = tileset.data().level_nominal.front();
  // Class 0 is the one-class query at its own density: too sparse for the coarsest level, it takes the
  // same few places in every tile, and the classes' summed peak keeps the tiles from growing to fit it.
  const TileSizeAdvice own_advice = tile_size_advice(tileset, peaks.empty() ? 0 : peaks[0], scale, tile_size);
  if (peaks.size() > 1 && own_advice.kind != TileSizeAdvice::Kind::kEven) {
    char text[480];
    std::snprintf(text, sizeof text,
                  "class 0 expects at most %.3g points per tile, under the tile set's coarsest level (%.0f): "
                  "its points take the same few places in every tile, a pattern that repeats with the tiles; "
                  "query it on its own with a %s of at least %.3g (one query serves classes within about "
                  "1:%.0f of the classes' summed peak)",
                  own_advice.points_per_tile, coarsest, tile_size_name, own_advice.tile_size,
                  tileset.max_points_per_tile() / coarsest);
    warnings.push_back(text);
  }
  double before = 0;  // the classes before k, points per tile at their peaks
  for (std::size_t k = 0; k < peaks.size(); ++k) {
    const double own = peaks[k] * area;
    if (k > 0 && own > 0 && own < kFewestForALaterClass && before >= coarsest) {
      char text[400];
      std::snprintf(
          text, sizeof text,
          "class %zu expects at most %.3g points per tile after up to %.3g of the classes before it: "
          "a later class gets what their counts leave, off by up to about 2 points per tile where "
          "they are constant; query it on its own with a %s that gives it at least %.0f",
          k, own, before, tile_size_name, coarsest);
      warnings.push_back(text);
      break;  // the first such class: the others share its cause
    }
    before += std::isfinite(own) ? own : 0;
  }
  return warnings;
}

namespace {

/// A lower bound of the density's integral over the region (exact for a constant); NaN for a callback.
double density_integral_at_least(const QueryDensity& d, const QueryParams& q) {
  const double w = q.x1 - q.x0, h = q.y1 - q.y0;
  if (!(w > 0 && h > 0)) return 0;
  switch (d.kind) {
    case QueryDensity::Kind::kConstant:
      return d.constant * w * h;
    case QueryDensity::Kind::kImage: {
      if (!d.image) return std::nan("");
      if (!(d.image->max_over(q.x0, q.y0, q.x1, q.y1) * w * h * q.scale > 0.5 * double(kMaxCollectedPoints)))
        return 0;  // surely collectable: no need to look closer
      // Each block's lower bound (the min-mip) over its area: never more than the integral, whatever detail
      // the image has between a grid's samples.
      constexpr int kBlocks = 64;
      double sum = 0;
      for (int j = 0; j < kBlocks; ++j)
        for (int i = 0; i < kBlocks; ++i)
          sum += d.image->min_over(q.x0 + i * w / kBlocks, q.y0 + j * h / kBlocks,
                                   q.x0 + (i + 1) * w / kBlocks, q.y0 + (j + 1) * h / kBlocks);
      return sum / (kBlocks * kBlocks) * w * h;
    }
    case QueryDensity::Kind::kCallback:
      break;
  }
  return std::nan("");
}

/// Whether `densest` (the most any point of the region may ask) passes what the tile set serves.
bool past_the_set(const Tileset& tileset, const QueryParams& q, double densest) {
  return densest * q.scale * q.tile_size * q.tile_size > query_density_limit(tileset, q.mode);
}

double upper_bound(const QueryDensity& d, const QueryParams& q) {
  switch (d.kind) {
    case QueryDensity::Kind::kConstant:
      return d.constant;
    case QueryDensity::Kind::kImage:
      return d.image ? d.image->max_over(q.x0, q.y0, q.x1, q.y1) : 0;
    case QueryDensity::Kind::kCallback:
      break;
  }
  return d.callback_max;
}

/// Runs `step` (one call of a query writing points [from, from + room) into `out`, `per_point` elements
/// each, and returning its status) until the region is complete; `out` ends holding exactly the points.
/// The one rule of every collecting query: chunks of 2^16 points, at most kMaxCollectedPoints, refusals
/// as describe()'s line.
template <class T, class Step>
void collect(std::vector<T>& out, std::size_t per_point, const QueryParameterNames& names, Step&& step) {
  out.clear();
  QueryCursor cursor;
  for (std::size_t m = 0;;) {
    const std::size_t room = std::size_t(1) << 16;
    out.resize(per_point * (m + room));
    std::size_t written = 0;
    QueryProblem problem;
    const Status s = step(m, room, &written, &cursor, &problem);
    m += written;
    out.resize(per_point * m);
    if (m > kMaxCollectedPoints)  // 1 GiB of QueryPoint records: stop before memory runs out
      throw std::length_error("the query emits more than 2^25 points; lower the scale or split the region");
    if (s == Status::kOk) return;
    if (s != Status::kBufferFull) throw std::invalid_argument("query: " + describe(problem, names));
  }
}

/// collect for a class query: `step` also takes where the chunk's classes go, and `classes` ends holding
/// one per point.
template <class T, class Step>
void collect_classes(std::vector<T>& out, std::size_t per_point, std::vector<std::uint8_t>& classes,
                     const QueryParameterNames& names, Step&& step) {
  classes.clear();
  collect(out, per_point, names,
          [&](std::size_t from, std::size_t room, std::size_t* written, QueryCursor* cursor,
              QueryProblem* problem) {
            classes.resize(from + room);
            const Status s = step(from, room, classes.data() + from, written, cursor, problem);
            classes.resize(from + *written);
            return s;
          });
}

}  // namespace

double points_at_least(const Tileset& tileset, const QueryParams& params) {
  if (past_the_set(tileset, params, upper_bound(params.density, params))) return std::nan("");
  return density_integral_at_least(params.density, params) * params.scale;
}

double points_at_least(const Tileset& tileset, const ClassQueryParams& params) {
  const std::uint32_t n = params.class_count;
  if (n == 0 || n > kMaxQueryClasses || params.joint.densities || params.joint.batch_densities)
    return std::nan("");
  double densest = 0, integral = 0;
  for (std::uint32_t k = 0; k < n; ++k) {
    densest += upper_bound(params.classes[k], params.query);
    integral += density_integral_at_least(params.classes[k], params.query);
  }
  if (past_the_set(tileset, params.query, densest)) return std::nan("");
  return integral * params.query.scale;
}

namespace {

void check_collectable(double least, const QueryParameterNames& names) {
  // 5% of margin for the tiles' own counts around the density.
  if (!(least > 1.05 * double(kMaxCollectedPoints))) return;
  char text[200];
  std::snprintf(
      text, sizeof text,
      "the query would emit at least %.3g points, more than 2^25; lower the scale (%s) or split the "
      "region",
      least, names.scale);
  throw std::length_error(text);
}

}  // namespace

void check_before_collecting(const Tileset& tileset, const QueryParams& params,
                             const QueryParameterNames& names) {
  // A call with no room checks the parameters and stops at the first point.
  std::size_t written = 0;
  QueryCursor cursor;
  QueryProblem problem;
  if (query_points(tileset, params, nullptr, 0, &written, &cursor, &problem) == Status::kInvalidArgument)
    throw std::invalid_argument("query: " + describe(problem, names));
  check_collectable(points_at_least(tileset, params), names);
}

void check_before_collecting(const Tileset& tileset, const ClassQueryParams& params,
                             const QueryParameterNames& names) {
  std::size_t written = 0;
  QueryCursor cursor;
  QueryProblem problem;
  if (query_classes(tileset, params, nullptr, nullptr, 0, &written, &cursor, &problem) ==
      Status::kInvalidArgument)
    throw std::invalid_argument("query: " + describe(problem, names));
  check_collectable(points_at_least(tileset, params), names);
}

void query_all(const Tileset& tileset, const QueryParams& params, std::vector<QueryPoint>& out,
               const QueryParameterNames& names) {
  check_before_collecting(tileset, params, names);
  collect(out, 1, names,
          [&](std::size_t from, std::size_t room, std::size_t* written, QueryCursor* cursor,
              QueryProblem* problem) {
            return query_points(tileset, params, out.data() + from, room, written, cursor, problem);
          });
}

void query_all_xy(const Tileset& tileset, const QueryParams& params, std::vector<float>& xy,
                  std::vector<std::uint64_t>* keys, const QueryParameterNames& names) {
  check_before_collecting(tileset, params, names);
  if (keys) keys->clear();
  collect(xy, 2, names,
          [&](std::size_t from, std::size_t room, std::size_t* written, QueryCursor* cursor,
              QueryProblem* problem) {
            if (keys) keys->resize(from + room);
            const Status s = query_points_compact(
                tileset, params, CompactPoints{xy.data() + 2 * from, keys ? keys->data() + from : nullptr},
                room, written, cursor, problem);
            if (keys) keys->resize(from + *written);
            return s;
          });
}

void query_all_xy(const Tileset& tileset, const ClassQueryParams& params, std::vector<float>& xy,
                  std::vector<std::uint8_t>& classes, std::vector<std::uint64_t>* keys,
                  const QueryParameterNames& names) {
  check_before_collecting(tileset, params, names);
  if (keys) keys->clear();
  collect_classes(xy, 2, classes, names,
                  [&](std::size_t from, std::size_t room, std::uint8_t* to, std::size_t* written,
                      QueryCursor* cursor, QueryProblem* problem) {
                    if (keys) keys->resize(from + room);
                    const Status s = query_classes_compact(
                        tileset, params,
                        CompactPoints{xy.data() + 2 * from, keys ? keys->data() + from : nullptr}, to, room,
                        written, cursor, problem);
                    if (keys) keys->resize(from + *written);
                    return s;
                  });
}

bool keys_fit(const Tileset& tileset) {
  return tileset.max_points_per_tile() <= (std::uint64_t(1) << kKeyRankBits);
}

void query_all(const Tileset& tileset, const ClassQueryParams& params, std::vector<QueryPoint>& out,
               std::vector<std::uint8_t>& classes, const QueryParameterNames& names) {
  check_before_collecting(tileset, params, names);
  collect_classes(out, 1, classes, names,
                  [&](std::size_t from, std::size_t room, std::uint8_t* to, std::size_t* written,
                      QueryCursor* cursor, QueryProblem* problem) {
                    return query_classes(tileset, params, out.data() + from, to, room, written, cursor,
                                         problem);
                  });
}

PointSet normalise_to_rect(const std::vector<QueryPoint>& points, const double r[4]) {
  const double w = r[2] - r[0], h = r[3] - r[1], below_one = std::nextafter(1.0, 0.0);
  PointSet set;
  set.dim = 2;
  set.coords.reserve(points.size() * 2);
  for (const QueryPoint& p : points)
    set.coords.insert(set.coords.end(), {std::min(p.x / w, below_one), std::min(p.y / h, below_one)});
  return set;
}

PointSet normalise_to_rect(const std::vector<float>& xy, const double r[4]) {
  const double w = r[2] - r[0], h = r[3] - r[1], below_one = std::nextafter(1.0, 0.0);
  PointSet set;
  set.dim = 2;
  set.coords.resize(xy.size());
  // A float position just below the region's far side may round onto it; clamp as for doubles, and at 0.
  for (std::size_t i = 0; i < xy.size(); i += 2) {
    set.coords[i] = std::clamp(xy[i] / w, 0.0, below_one);
    set.coords[i + 1] = std::clamp(xy[i + 1] / h, 0.0, below_one);
  }
  return set;
}

}  // namespace kdm::tools
