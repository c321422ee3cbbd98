// A parsed density (tools/common/density_spec.h) as a query's density: what `kdm query --density` and
// the Python package's queries share, so both give the same points.
#pragma once

#include <vector>

#include "density_spec.h"
#include "kdm/runtime/class_image_sums.h"
#include "kdm/runtime/class_query.h"
#include "kdm/runtime/query.h"

namespace kdm::tools {

/// The runtime density for `spec` over the world rectangle r = (x0, y0, x1, y1): constant, the image's
/// texels stretched over r (the spec's own, not a copy, with their max-mip; an array kept divided, the
/// values it holds), or a test map called back at every candidate. `spec` must outlive it; it does not move
/// (queries keep pointers into it). Throws std::invalid_argument for an image the runtime refuses.
struct SpecDensity {
  SpecDensity(const DensitySpec& spec, const double r[4]);
  SpecDensity(const SpecDensity&) = delete;
  SpecDensity& operator=(const SpecDensity&) = delete;

  QueryDensity density;
  DensityImageView image;
  std::vector<float> mip;
  std::vector<float> undivided;  ///< an array's values times DensitySpec::divided_by, when that is not 1
  const DensitySpec& spec;
  double rect[4];
};

/// Most texels (all classes') whose running sums read_images_by_sums builds: about 1.5 ms of building a call.
inline constexpr double kMaxSummedTexels = double(1 << 20);

/// Classes that are all images on one grid of at most `max_texels` texels in all are read by the images
/// of their running sums: builds `sums` and points params.image_sums at it (the query then reads one
/// image where it would read every class's). The choice depends on the images alone, never on the
/// region, since the two ways give different bits: any partition of a region gives the whole's points.
/// (A caller that builds once for many queries, as the stippler does for its frames, may pass infinity.)
/// Returns whether it did; otherwise it leaves both as they are.
bool read_images_by_sums(ClassQueryParams& params, ClassImageSums& sums,
                         double max_texels = kMaxSummedTexels);

}  // namespace kdm::tools
