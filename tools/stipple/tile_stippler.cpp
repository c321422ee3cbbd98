#include "tile_stippler.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "runtime_query.h"

namespace kdm::tools {

namespace {

/// Mid-way (geometrically) between the keyframe at or below `count` and the one before: where a flat tone
/// of a smooth stipple is best. At a keyframe the points that appeared late in its interval stand a little
/// crowded (`glide_late`): the built-in set at 8,192 points per tile has 1.2% of its points nearer another
/// than 0.45 d_hex (at 7,961: 0.03%, for 0-10 circles above 0.85 d_hex per 10^5).
double between_keyframes(const Tileset& tileset, double count) {
  const auto& k = tileset.data().keyframe_nominal;
  std::size_t g = 0;  // the last keyframe at or below count
  while (g + 1 < k.size() && k[g + 1] <= count) ++g;
  if (g == 0 || k[g] > count) return count;
  return std::sqrt(double(k[g - 1]) * k[g]);
}

constexpr double kPi = 3.14159265358979323846;
}  // namespace

KeptPixels stipple_kept_pixels(double points, double scale, double zoom) {
  return [=](int width, int height) {
    const double aspect = double(std::max(width, height)) / std::min(width, height);
    const double dots = points > 0 ? 4 * points : scale * aspect;  // 16 kept pixels a dot, or 64 a mean one
    const double kept = std::max(double(1 << 24), 16 * dots) * std::max(1.0, zoom) * std::max(1.0, zoom);
    // At most what a density may hold: a deep zoom into a huge picture would keep every pixel of it.
    return kept >= double(kMaxImagePixels) ? kMaxImagePixels : static_cast<std::uint64_t>(kept);
  };
}

double stipple_zoom(const double uv[4]) {
  return 1 / (uv[2] - uv[0]);
}

void stipple_frame_region(const double region[4], int i, int k, double out[4]) {
  const double size[2] = {region[2] - region[0], region[3] - region[1]};
  const double first = 1 / std::min(size[0], size[1]);  // frame 0's size over the region's
  double whole[4];                                      // frame 0
  for (int j = 0; j < 2; ++j) {
    // Zoomed about the point of the region that lies in it as the region lies in the image; across the
    // image exactly where the region is the narrower way.
    const double fixed = size[j] < 1 ? region[j] / (1 - size[j]) : 0.5;
    // Equal sides within rounding (0.75 - 0.55 against 0.55 - 0.35) count as equal: frame 0 is then the
    // image exactly, not 1e-16 past it.
    const bool across = size[j] <= std::min(size[0], size[1]) * (1 + 1e-12);
    whole[j] = across ? 0.0 : fixed + (region[j] - fixed) * first;
    whole[j + 2] = across ? 1.0 : whole[j] + size[j] * first;
  }
  const double f = std::pow(first, k > 1 ? 1 - double(i) / (k - 1) : 0.0);  // this frame's size
  const double t = first > 1 ? (f - 1) / (first - 1) : 0;                   // 1: frame 0, 0: the region
  for (int j = 0; j < 4; ++j) out[j] = region[j] + (whole[j] - region[j]) * t;
  if (i == 0 && k > 1) std::copy(whole, whole + 4, out);  // exactly, whatever the rounding
  if (i == k - 1) std::copy(region, region + 4, out);
}

double stipple_dot_count(const std::vector<const DensitySpec*>& inks, double points, double scale) {
  if (points > 0) return points;
  double mean = 0;
  for (const DensitySpec* ink : inks) mean += ink->mean_value();
  return inks.empty() ? 0.0 : scale * double(inks.front()->width) / inks.front()->height * mean;
}

std::int64_t full_stipple_count(double whole_dots, double scale) {
  char message[160];
  if (!(whole_dots <= double(std::int64_t(1) << 31))) {  // before llround overflows
    std::snprintf(message, sizeof message, "scale %g asks for %.3g dots, more than the full sampler's 2^31",
                  scale, whole_dots);
    throw std::invalid_argument(message);
  }
  const std::int64_t count = std::llround(whole_dots);
  if (count < 1) {
    std::snprintf(message, sizeof message, "scale %g places no dot on this image", scale);
    throw std::invalid_argument(message);
  }
  return count;
}

double stipple_dot_radius(double whole_dots, int width_px, double aspect,
                          const std::vector<const DensitySpec*>& inks) {
  double coverage = 0;  // the inks' mean densities: the share of the paper their dots should cover
  for (const DensitySpec* ink : inks) coverage += ink->mean_value();
  const double pixels = double(width_px) * (width_px / aspect);
  return std::sqrt(coverage * pixels / (kPi * std::max(1.0, whole_dots)));
}

std::string stipple_region_text(const double uv[4]) {
  return "region " + shortest(uv[0]) + "," + shortest(uv[1]) + "," + shortest(uv[2]) + "," + shortest(uv[3]);
}

std::vector<std::string> stipple_region_header(const double uv[4], double aspect) {
  return {stipple_region_text(uv), domain_header(false, 2, nullptr, aspect)};
}

double max_stipple_zoom(const Tileset& tileset, QueryMode mode) {
  return kStippleZoomRoom * std::sqrt(query_density_limit(tileset, mode) / tileset.max_points_per_tile());
}

std::string stipple_zoom_error(const char* what, const Tileset& tileset, QueryMode mode) {
  char text[320];
  const bool deep = tileset.data().handover_zone > 0 && tileset.has_glide_track();
  std::snprintf(text, sizeof text, "%s zooms more than %.6g× (%s)", what, max_stipple_zoom(tileset, mode),
                mode != QueryMode::kSmooth
                    ? "stable mode: the image's darkest tone is placed a zoom of 2 below the tile set's top "
                      "level, and stable points cannot go past it; smooth mode zooms on"
                : deep
                    ? "smooth mode: as deep as the tile set's subtiles go"
                    : "the tile set has no hand-over to subtiles, so smooth mode stops at its top level as "
                      "stable mode does; the built-in set zooms on");
  return text;
}

TileStippler::TileStippler(const DensitySpec& spec, const Tileset& tileset, double points, double scale,
                           QueryMode mode, std::uint64_t seed)
    : TileStippler(std::vector<const DensitySpec*>{&spec}, tileset, points, scale, mode, seed) {}

TileStippler::TileStippler(const std::vector<const DensitySpec*>& inks, const Tileset& tileset, double points,
                           double scale, QueryMode mode, std::uint64_t seed)
    : tiles_(tileset), mode_(mode) {
  if (inks.empty() || inks.size() > kMaxQueryClasses)
    throw std::invalid_argument("stippling takes 1 to 8 inks, got " + std::to_string(inks.size()));
  const DensitySpec& first = *inks.front();
  double mean = 0;
  for (const DensitySpec* spec : inks) {
    if (spec->kind != DensitySpec::Kind::kImage) throw std::invalid_argument("stippling needs an image");
    if (spec->width != first.width || spec->height != first.height)
      throw std::invalid_argument("the inks' images differ in size");
    mean += spec->mean_value();
  }
  double peak = 0;  // of the inks' summed density, pixel by pixel (no image of sums: a large one is GBs)
  for (std::size_t i = 0; i < first.values.size(); ++i) {
    double sum = 0;
    for (const DensitySpec* spec : inks) sum += spec->values[i];
    peak = std::max(peak, sum);
  }
  if (!(peak > 0)) throw std::invalid_argument("the image has no ink: nothing to stipple");
  if (!(points > 0 || scale > 0)) throw std::invalid_argument("give a number of dots > 0 or a scale > 0");
  aspect_ = double(first.width) / first.height;  // world: [0, aspect] × [0, 1]
  // The scale that gives `points` dots over the whole image (∫ρ dA = mean · aspect).
  scale_ = points > 0 ? points / (mean * aspect_) : scale;
  // Tiles small enough that the image's peak density, zoomed kStippleZoomRoom times, fits the top level
  // (past it, smooth mode descends into subtiles). The tile size depends on the whole image only, so
  // every region and frame sees the same dots. With a scale given, it is set for full darkness unless the
  // inks sum to more: then it depends on the scale alone, and an animated picture keeps its dots where its
  // tones stay (with the image's own peak, one darker pixel would move every dot).
  double peak_count = tiles_.max_points_per_tile() / (kStippleZoomRoom * kStippleZoomRoom);
  if (mode == QueryMode::kSmooth) peak_count = between_keyframes(tiles_, peak_count);
  tile_size_ = std::sqrt(peak_count / (scale_ * (points > 0 ? peak : std::max(peak, 1.0))));
  // Said in the caller's terms (dots, scale) before a query would name the tile size derived from them.
  const double dots = scale_ * mean * aspect_;
  char text[160];
  if (!(dots <= double(kMaxCollectedPoints))) {
    std::snprintf(text, sizeof text, "%.3g dots over the image is more than one picture holds (2^25)", dots);
    throw std::invalid_argument(text);
  }
  if (!(tile_size_ > 0 && tile_size_ < HUGE_VAL)) {
    std::snprintf(text, sizeof text, "a scale of %.3g dots per unit area is too small to place a dot",
                  scale_);
    throw std::invalid_argument(text);
  }
  // The seed picks where in the endless tiling the image lies: another seed, other dots. Seeds step along
  // the R2 sequence (Roberts 2018: fractions of the plastic number's powers, in 64-bit fixed point), so
  // they spread evenly over 2^12 tiles, where positions keep their precision at every zoom; seed 1, the
  // default, lies at the world's origin.
  const std::uint64_t step = seed - 1, fraction[2] = {step * 0xC13FA9A902A6328Fu, step * 0x91E10DA5C79E7B1Du};
  for (int k = 0; k < 2; ++k) offset_[k] = double(fraction[k] >> 40) * 0x1p-24 * 4096 * tile_size_;
  const double world[4] = {offset_[0], offset_[1], offset_[0] + aspect_, offset_[1] + 1};
  for (const DensitySpec* spec : inks) densities_.push_back(std::make_unique<SpecDensity>(*spec, world));
  ClassQueryParams
      classes;  // the inks over the whole image, as a frame reads them: by their sums, built once
  classes.query.x0 = world[0], classes.query.y0 = world[1];
  classes.query.x1 = world[2], classes.query.y1 = world[3], classes.query.scale = scale_;
  classes.class_count = static_cast<std::uint32_t>(densities_.size());
  for (std::size_t k = 0; k < densities_.size(); ++k) classes.classes[k] = densities_[k]->density;
  read_images_by_sums(classes, sums_, HUGE_VAL);  // built once for every frame
}

TileStippler::ThinTones TileStippler::thin_tones(double zoom) const {
  ThinTones thin;
  thin.coarsest = tiles_.data().level_nominal.empty() ? 0 : tiles_.data().level_nominal[0];
  thin.fewest = HUGE_VAL;
  const double per_tile = scale_ * zoom * zoom * tile_size_ * tile_size_;  // per unit of density
  const std::vector<float>& first = densities_.front()->spec.values;
  double all = 0, under = 0;
  for (std::size_t i = 0; i < first.size(); ++i) {
    double density = 0;
    for (const auto& d : densities_) density += d->spec.values[i];
    if (!(density > 0)) continue;
    all += density;
    if (density * per_tile < thin.coarsest * (1 - 1e-3)) {  // not a tone that rounds to the level itself
      under += density;
      thin.fewest = std::min(thin.fewest, density * per_tile);
    }
  }
  thin.share = all > 0 ? under / all : 0;
  return thin;
}

std::string TileStippler::thin_tones_warning(const ThinTones& thin, const char* gamma, bool custom_set) {
  if (!(thin.share >= 0.01)) return "";
  char line[400];
  std::snprintf(
      line, sizeof line,
      "%.0f%% of the dots lie where the picture asks fewer points per tile (as few as %.3g) than the "
      "tile set's coarsest level holds (%.0f), and come out clumpy there: %s%s below 1 raises those "
      "tones",
      std::max(1.0, std::floor(100 * thin.share)), thin.fewest, thin.coarsest,
      custom_set ? "a tile set of more levels (a wider density range, as the built-in set's 1:1024) "
                   "serves them evenly, or "
                 : "",
      gamma);
  return line;
}

ClassQueryParams TileStippler::class_params(const QueryParams& q) const {
  ClassQueryParams cq;
  cq.query = q;
  cq.class_count = static_cast<std::uint32_t>(densities_.size());
  for (std::size_t k = 0; k < densities_.size(); ++k) cq.classes[k] = densities_[k]->density;
  if (sums_.count() == cq.class_count) cq.image_sums = &sums_;
  return cq;
}

PointSet TileStippler::with_sizes(const QueryParams& q, const double rect[4], double fade) const {
  std::vector<QueryPoint> points;  // the ids too, for their thresholds
  std::vector<std::uint8_t> classes;
  if (densities_.size() == 1) {
    query_all(tiles_, q, points);
  } else {
    query_all(tiles_, class_params(q), points, classes);
  }
  PointSet set = normalise_to_rect(points, rect);
  set.classes = std::move(classes);
  set.sizes.resize(points.size());
  if (keys_fit(tiles_))
    for (const QueryPoint& p : points) set.ids.push_back(point_key(p.id));
  const double m = tiles_.data().subtiles_per_side();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const QueryPoint& p = points[i];
    // The union's count (the inks together) in the dot's own (sub)tile, at its stable position, where the
    // query reads it: where the dot has glided to, its weight would blink across a change of tone.
    double x = q.origin_x + p.x, y = q.origin_y + p.y;
    stable_position(tiles_, p.id, q.tile_size, 0, 0, &x, &y);
    double density = 0;
    for (const auto& d : densities_) density += d->image.at(x, y);
    const double side = q.tile_size / std::pow(m, p.id.depth);
    const double count = density * q.scale * side * side, threshold = emission_threshold(tiles_, p.id);
    const double weight = threshold > 0 ? std::clamp((count / threshold - 1) / fade, 0.0, 1.0) : 1.0;
    set.sizes[i] = static_cast<float>(std::sqrt(weight));  // area, so ink, in proportion to the weight
  }
  return set;
}

PointSet TileStippler::render(const double uv[4], double fade) const {
  const double zoom = stipple_zoom(uv);
  if (zoom > max_stipple_zoom(tiles_, mode_) * (1 + 1e-9))
    throw std::invalid_argument(stipple_zoom_error("the region", tiles_, mode_));
  // Dots only on the image: a rectangle past its sides (a frame zoomed out) shows blank paper there.
  QueryParams q;
  q.x0 = offset_[0] + std::max(uv[0], 0.0) * aspect_, q.y0 = offset_[1] + std::max(uv[1], 0.0);
  q.x1 = offset_[0] + std::min(uv[2], 1.0) * aspect_, q.y1 = offset_[1] + std::min(uv[3], 1.0);
  q.origin_x = offset_[0] + uv[0] * aspect_, q.origin_y = offset_[1] + uv[1];
  q.tile_size = tile_size_;
  q.scale = scale_ * zoom * zoom;  // the same dots on screen, so the zoomed view shows more of them
  q.density = densities_.front()->density;
  q.mode = mode_;
  q.glide_together = true;  // a picture's tone changes from dot to dot
  const double rect[4] = {uv[0] * aspect_, uv[1], uv[2] * aspect_, uv[3]};
  if (fade > 0) return with_sizes(q, rect, fade);
  std::vector<float> xy;  // positions and keys: the compact output
  std::vector<std::uint64_t> keys;
  std::vector<std::uint8_t> classes;
  std::vector<std::uint64_t>* keyed = keys_fit(tiles_) ? &keys : nullptr;
  if (densities_.size() == 1)
    query_all_xy(tiles_, q, xy, keyed);
  else
    query_all_xy(tiles_, class_params(q), xy, classes, keyed);
  PointSet set = normalise_to_rect(xy, rect);
  set.classes = std::move(classes);
  set.ids = std::move(keys);
  return set;
}

}  // namespace kdm::tools
