// Stippling an image with the runtime (`kdm stipple`'s default method, kdm.stipple in Python): the dots of
// a rectangle of the image, at a fixed dot size, so that regions and zoom frames of one image show the
// same dots. Built apart from the generator: nothing here includes its headers.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "density_spec.h"
#include "kdm/runtime/query.h"
#include "point_io.h"
#include "spec_density.h"

namespace kdm::tools {

/// The files a stipple is written to (`kdm stipple -o`, kdm.stipple's output): pictures and point files.
inline const std::vector<const char*> kStippleFormats = {".png", ".svg", ".txt", ".csv"};

/// The tile size leaves room for this many times more dots per axis than the whole image shows.
inline constexpr double kStippleZoomRoom = 2;

/// The largest picture a stipple reads, in pixels (16384 × 16384; other commands keep kMaxImagePixels):
/// it is averaged down as it is read (stipple_kept_pixels), so only the decoder holds every pixel, 1 to 8
/// bytes each (8-bit grey to 16-bit RGBA).
inline constexpr std::uint64_t kMaxStipplePixels = std::uint64_t(1) << 28;

/// How many of a picture's pixels a stipple keeps (KeptPixels): max(2^24, 64 · points) · zoom², or with
/// `scale` (points 0) max(2^24, 16 · scale · aspect) · zoom² (aspect: the longer side over the shorter),
/// `zoom` being the deepest zoom drawn (stipple_zoom, at least 1), and at most kMaxImagePixels. A dot's
/// spacing then spans about four kept pixels where the picture is darkest (with `scale`; with `points`,
/// on a picture at least a sixteenth dark), and no picture up to 4096 × 4096 is averaged.
KeptPixels stipple_kept_pixels(double points, double scale, double zoom);

/// Dots over a whole image of `inks` (one or more images of one size, over [0, aspect] × [0, 1]): `points`
/// when > 0, else `scale` dots per unit area at full darkness, scale · aspect · the inks' summed mean.
double stipple_dot_count(const std::vector<const DensitySpec*>& inks, double points, double scale);

/// The full sampler's count for `whole_dots` (stipple_dot_count; `scale` names the request in messages):
/// throws std::invalid_argument when it rounds to no dot or exceeds the sampler's 2^31.
std::int64_t full_stipple_count(double whole_dots, double scale);

/// A dot's radius in pixels when none is given: the whole image's `whole_dots` dots together cover as much
/// of the picture as the inks' densities do on average (a pale image, small dots; in colour each ink its
/// share, overlaps aside), whatever region is drawn, so that the picture's tone is the image's.
double stipple_dot_radius(double whole_dots, int width_px, double aspect,
                          const std::vector<const DensitySpec*>& inks);

/// "region x0,y0,x1,y1" for the UV rectangle `uv`, each number the shortest that reads back as it.
std::string stipple_region_text(const double uv[4]);

/// A stipple's header lines after its image's: the "region x0,y0,x1,y1" drawn (of the image's UV square),
/// then its picture's domain, a box of width over height `aspect` (domain_header), where kdm analyze
/// measures the dots.
std::vector<std::string> stipple_region_header(const double uv[4], double aspect);

/// The most a region may zoom into an image with `tileset` in `mode`: kStippleZoomRoom, times m^4 in
/// smooth mode with a set that hands over to m×m subtiles past its top level (query_density_limit).
double max_stipple_zoom(const Tileset& tileset, QueryMode mode);

/// The message for a region that zooms more than max_stipple_zoom.
std::string stipple_zoom_error(const char* what, const Tileset& tileset, QueryMode mode);

/// How much a UV rectangle magnifies the image: pictures have a fixed width in pixels, so 1 / its width
/// (a region as wide as the image but shorter is drawn at the whole image's size, only less tall).
double stipple_zoom(const double uv[4]);

/// The UV rectangle of frame i of k, zooming into `region` (frame k − 1) from the smallest rectangle of
/// its shape that holds the whole image (frame 0: the whole image when the region has the image's shape,
/// else the image with blank paper beside it). Every frame has the region's shape (pictures of one size);
/// the zoom grows geometrically about a fixed point of the region (where it lies in the image as the
/// region lies in the image), so each rectangle holds the next and zoom coherence keeps every dot that
/// stays in view.
void stipple_frame_region(const double region[4], int i, int k, double out[4]);

class TileStippler {
 public:
  /// The image `spec` (kImage, with some ink) over the world [0, aspect] × [0, 1], aspect its width /
  /// height. `points` dots over the whole image (> 0), or, when points is 0, `scale` dots per unit area at
  /// full darkness. `seed` picks where in the tile set's endless tiling the image lies (another seed, other
  /// dots; one seed, the same dots in every region and frame). With `scale`, the tiling depends on the scale
  /// and seed only, not on the image, where its inks sum to at most 1 (every grey image): frames of an
  /// animated image keep their dots where their tone stays, and a darker tone adds dots to a lighter one's
  /// (stable mode). `tileset` must outlive the stippler; so must `spec`. Throws std::invalid_argument.
  TileStippler(const DensitySpec& spec, const Tileset& tileset, double points, double scale, QueryMode mode,
               std::uint64_t seed);
  /// Several inks (1 … kMaxQueryClasses images of one size, highest priority first): `points` and `scale`
  /// count the dots of all of them, and render() gives each dot its ink's class.
  TileStippler(const std::vector<const DensitySpec*>& inks, const Tileset& tileset, double points,
               double scale, QueryMode mode, std::uint64_t seed);
  /// The dots of the UV rectangle `uv` (x0, y0, x1, y1, y up; past [0, 1]² is blank paper), normalised
  /// to it: [0, 1)²; drawn at stipple_zoom(uv), so that dots keep their size and spacing in a picture of
  /// fixed width.
  /// With `fade` > 0 each dot also gets a size (PointSet::sizes) that grows from 0 where it appears to 1
  /// once the density there has risen a fraction `fade` more (emission_threshold), its area in proportion:
  /// the ink of a zoom changes continuously instead of dots popping up. Throws std::invalid_argument when
  /// it zooms more than max_stipple_zoom, std::length_error when the query would emit more than 2^25
  /// dots.
  PointSet render(const double uv[4], double fade = 0) const;
  double aspect() const { return aspect_; }

  /// The image's tones that the tile set serves unevenly at `zoom` (stipple_zoom): those that ask fewer
  /// points per tile than its coarsest level holds, where a tile gives only part of that level (a set of
  /// few levels, of a narrow density range, places the image's light tones there).
  struct ThinTones {
    double share = 0;     ///< of the dots (the inks' density summed over the image), in [0, 1]
    double fewest = 0;    ///< points per tile that the lightest inked pixel asks
    double coarsest = 0;  ///< the set's coarsest level's points per tile
  };
  ThinTones thin_tones(double zoom) const;
  /// The warning for thin_tones' result, without a prefix, or "" when they hold under 1% of the dots (a
  /// few pale pixels' dots are not seen as clumps). `gamma` names the option that raises tones
  /// ("--gamma", "gamma="); `custom_set` adds that a set of more levels serves them.
  static std::string thin_tones_warning(const ThinTones& thin, const char* gamma, bool custom_set);

 private:
  ClassQueryParams class_params(const QueryParams& q) const;  ///< the inks' query over q
  PointSet with_sizes(const QueryParams& q, const double rect[4], double fade) const;

  const Tileset& tiles_;
  double aspect_ = 1, scale_ = 0, tile_size_ = 1;
  double offset_[2] = {0, 0};  ///< the image's world place: [offset, offset + (aspect, 1)]
  QueryMode mode_;
  std::vector<std::unique_ptr<SpecDensity>> densities_;  ///< each image over [0, aspect] × [0, 1]
  ClassImageSums sums_;  ///< several inks: their images' running sums (read_images_by_sums)
};

}  // namespace kdm::tools
