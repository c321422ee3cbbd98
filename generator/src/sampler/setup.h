// From user options to the model's finest grid: grid size, the density sampled on it and scaled so its
// mass matches the requested count, and the pyramid of coarser densities (paper §3.2–3.3).
#pragma once

#include <vector>

#include "kdm/generator/sampler.h"
#include "sampler/grid.h"

namespace kdm::gen {

template <int D>
struct ModelSetup {
  std::vector<DensityGrid<D>> levels;  ///< [0] finest ... back() coarsest; ρ_{l+1} sums 2^D nodes of ρ_l
  double mass_per_point = 0;           ///< ∫ of one unit-weight kernel: J^D
  bool uniform = false;                ///< every node of the finest density has the same value
};

/// Validates `options` and `density` (throws InvalidArgument) and builds the pyramid. With n > 0 the
/// finest density is scaled so that Σρ = n · mass_per_point (and max ρ <= peak_density); with n == 0
/// the grid has `resolution` nodes on its shortest axis and max ρ = peak_density.
template <int D>
ModelSetup<D> build_model(const SamplerOptions& options, const Density& density);

/// The next coarser level of a pyramid: every coarse node is the sum of its 2^D children (a box filter
/// and subsampling; the factor 2^D of eq. 12 goes inside the values). `fine` dims must be even. Uses up to
/// `threads` threads on large grids; the result does not depend on how many. Not thread-safe.
template <int D>
std::vector<float> box_sum_half(const Grid<D>& fine, const std::vector<float>& values, int threads = 1);

/// Throws InvalidArgument naming the first bad option.
void validate_options(const SamplerOptions& options);

}  // namespace kdm::gen
