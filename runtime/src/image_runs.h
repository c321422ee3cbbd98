// Internal: bilinear image densities at a block of a tile's candidates at once (emit_tile.h), in loops the
// compiler vectorises (run_clones.h), bit for bit as ImageSampler reads one position.
#pragma once

#include <cstddef>
#include <cstdint>

#include "image_sampler.h"
#include "kdm/runtime/tileset_format.h"

namespace kdm::detail {

/// Most candidates one call reads.
inline constexpr std::uint32_t kImageBlock = 64;

/// Whether the runs below can read `image`: fewer than 2^31 texels (their indices are 32-bit, which the
/// vector gathers take).
inline bool image_runs_fit(const DensityImageView& image) {
  return std::uint64_t(image.width) * std::uint64_t(image.height) < (std::uint64_t(1) << 31);
}

}  // namespace kdm::detail

// Outside namespace kdm: GCC gives a target_clones function's ifunc default visibility whatever
// -fvisibility says, and the shared library's version script exports kdm::* (run_clones.h).
namespace kdm_runs {
using namespace kdm;
using namespace kdm::detail;

/// Candidates from[0 … count) (count ≤ kImageBlock) of a tile at (wx, wy) of side S: their stable world
/// positions into x[k], y[k] and the density of `sampler`'s image there into rho[k], as
/// sampler.at(x[k], y[k]) reads it.
void image_run(const TilePoint* from, std::size_t count, double wx, double wy, double S,
               const ImageSampler& sampler, double* x, double* y, double* rho);

/// The density of `sampler`'s image at world positions (x[k], y[k]), k < count ≤ kImageBlock, into rho[k],
/// as sampler.at reads it.
void image_read_run(const double* x, const double* y, std::size_t count, const ImageSampler& sampler,
                    double* rho);

/// The same for `images` images on `sampler`'s grid of texels (ImageSampler::same_grid), values[i] the
/// i-th one's: their running sums into sums[i · kImageBlock + k] (image 0's value, then plus image 1's,
/// …), as sampler.texels and ImageSampler::blend add them up one by one.
void image_sums_run(const TilePoint* from, std::size_t count, double wx, double wy, double S,
                    const ImageSampler& sampler, const float* const* values, std::uint32_t images, double* x,
                    double* y, double* sums);

/// Classes by the images of their running sums on `sampler`'s grid (ClassImageSums), of candidates
/// from[0 … count) of a tile at (wx, wy) of side S: cls[k] = first_class plus how many of sums[0 … planes),
/// read at the candidate's stable position and times `area`, do not pass thresholds[k].
void image_sum_classes_run(const TilePoint* from, std::size_t count, double wx, double wy, double S,
                           const ImageSampler& sampler, const float* const* sums, std::uint32_t planes,
                           const float* thresholds, double area, std::uint8_t first_class, std::uint8_t* cls);

/// The same for classes by the images of their running sums on `sampler`'s grid (ClassImageSums), sums[i]
/// the i-th one's texels, `classes` of them: sampler's image (the last sum) read into rho[k] as image_run
/// reads it, and for each candidate it emits (TilesetShape::emits(thresholds[k], rho[k] · area_scale))
/// its class into cls[k]: how many of sums 0 … classes - 2, read at the same texels and times `area`, do
/// not pass its threshold. Sum c times `area` lies in [lo[c], hi[c]] at every candidate, so a threshold
/// outside every such band is classed without reading the sums. cls[k] of a candidate not emitted is left
/// as it was.
void image_classes_run(const TilePoint* from, std::size_t count, double wx, double wy, double S,
                       const ImageSampler& sampler, const float* const* sums, std::uint32_t classes,
                       const double* lo, const double* hi, const float* thresholds, double area_scale,
                       double area, double* x, double* y, double* rho, std::uint8_t* cls);

}  // namespace kdm_runs

namespace kdm::detail {
using kdm_runs::image_classes_run;
using kdm_runs::image_read_run;
using kdm_runs::image_run;
using kdm_runs::image_sum_classes_run;
using kdm_runs::image_sums_run;
}  // namespace kdm::detail
