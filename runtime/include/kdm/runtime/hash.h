// The one integer hash of kdm: the runtime colours tile-grid vertices with it, and the generator keys its
// random streams with it. Changing it changes every tile layout and every sampled point set.
#pragma once

#include <cstdint>

namespace kdm {

/// SplitMix64's finaliser (G. Steele, D. Lea, C. Flood, "Fast splittable pseudorandom number generators",
/// OOPSLA 2014): a bijection of 64-bit integers whose every output bit depends on every input bit.
constexpr std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

}  // namespace kdm
