// Stippling an image with the full KDM sampler (`kdm stipple --method full`): the highest fidelity, no
// zoom. Apart from tile_stippler.h, so that the runtime's method compiles without the generator.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "density_spec.h"
#include "point_io.h"

namespace kdm::tools {

/// `points` dots (> 0) for the image `spec` over [0, aspect] × [0, 1] in a box, normalised to [0, 1)²,
/// on `threads` threads (0: the default count; the dots do not depend on it). Throws
/// std::invalid_argument (gen::InvalidArgument) for an image with no ink or a count out of range.
/// `progress` (optional) is the sampler's (SamplerOptions::progress): an exception it throws stops it.
PointSet stipple_full(const DensitySpec& spec, std::int64_t points, double aspect, std::uint64_t seed,
                      int threads = 0, const std::function<void(double)>& progress = {});

/// The same for several inks (images of one size, highest priority first): `points` dots of all of them,
/// each with its ink's class (gen::sample_classes).
PointSet stipple_full(const std::vector<const DensitySpec*>& inks, std::int64_t points, double aspect,
                      std::uint64_t seed, int threads = 0, const std::function<void(double)>& progress = {});

}  // namespace kdm::tools
