// A kernel of the KDM model (Fattal 2011, §3): its centre and, in the multi-scale scheme (§3.3), the
// number of refinements it still splits in, which sets its weight.
#pragma once

#include <cmath>
#include <cstdint>

#include "sampler/grid.h"

namespace kdm::gen {

template <int D>
struct Particle {
  Vec<D> x{};               ///< grid units
  std::uint8_t splits = 0;  ///< refinements this kernel still splits in; weight w = 2^(D·splits)
  bool active = true;       ///< relaxed at this level (σ < σmax); inactive kernels are background
  bool fresh = true;        ///< placed (split, added) but not yet relaxed: freezes only past 2σmax
  double weight() const {
    return D * splits < 63 ? static_cast<double>(std::uint64_t(1) << (D * splits))
                           : std::ldexp(1.0, D * splits);
  }
};

}  // namespace kdm::gen
