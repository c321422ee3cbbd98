// Algorithm 2 of Fattal 2011: multi-scale sampling. Greedy initial configuration on the coarsest grid
// (random-order scan, a kernel is kept when it lowers E), Algorithm 1 at every level, the square
// refinement rule y -> 2y + σ z^l (|z^l| = 1) for kernels of weight w > 1, and kernels with σ >= σmax
// left as frozen background. We add: exact point counts (insertions/removals that keep Σw = n, made
// where they change E least, before the relaxation that follows) and a per-seed deterministic order.
#pragma once

#include "kdm/generator/sampler.h"
#include "sampler/setup.h"

namespace kdm::gen {

template <int D>
SampleResult run_multiscale(const SamplerOptions& options, ModelSetup<D>& setup);

}  // namespace kdm::gen
