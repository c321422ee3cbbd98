// `kdm stipple --method full`: the dots of an image by the full KDM sampler. Apart from the command's
// tile method, so that what the tile method compiles includes no generator header.
#pragma once

#include <cstdint>

#include "density_spec.h"
#include "point_io.h"

namespace kdm::cli {

/// `points` dots (> 0) for the image `spec` over [0, aspect] × [0, 1] in a box, normalised to [0, 1)².
/// Throws CommandError.
tools::PointSet stipple_full(const tools::DensitySpec& spec, std::int64_t points, double aspect,
                             std::uint64_t seed);

}  // namespace kdm::cli
