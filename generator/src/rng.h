// Counter-based random streams: every (seed, purpose, level, sweep, point) gets its own stream, so the
// sampler's output depends on the seed only — not on thread count or scheduling.
#pragma once

#include <cmath>
#include <cstdint>

namespace kdm::gen {

inline std::uint64_t mix64(std::uint64_t z) {
  // SplitMix64 finaliser (Steele, Lea, Flood 2014).
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

/// SplitMix64 generator with a keyed start. Small, fast, and good enough for proposals and tests.
class Rng {
 public:
  explicit Rng(std::uint64_t seed, std::uint64_t a = 0, std::uint64_t b = 0, std::uint64_t c = 0,
               std::uint64_t d = 0)
      : state_(keyed(seed, a, b, c) + d) {}

  /// Rng(seed, a, b, c, d) is Rng::from_key(keyed(seed, a, b, c), d): streams that differ only in d (one
  /// per point) share the first part, computed once.
  static std::uint64_t keyed(std::uint64_t seed, std::uint64_t a, std::uint64_t b, std::uint64_t c) {
    return mix64(mix64(mix64(mix64(seed ^ 0x6a09e667f3bcc909ull) + a) + b) + c);
  }
  static Rng from_key(std::uint64_t key, std::uint64_t d) { return Rng(key + d, Tag{}); }

  std::uint64_t next() {
    state_ += 0x9e3779b97f4a7c15ull;
    return mix64(state_);
  }
  /// Uniform in [0, 1).
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }
  /// Uniform integer in [0, bound), bound > 0 (Lemire's multiply-shift; bias < 2^-32 for our sizes).
  std::uint64_t below(std::uint64_t bound) {
    return static_cast<std::uint64_t>((static_cast<unsigned __int128>(next()) * bound) >> 64);
  }
  /// Standard normal (Box–Muller; the second value is cached).
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u1 = uniform();
    while (u1 <= 0.0) u1 = uniform();
    const double u2 = uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(6.283185307179586 * u2);
    has_spare_ = true;
    return r * std::cos(6.283185307179586 * u2);
  }

 private:
  struct Tag {};
  Rng(std::uint64_t state, Tag) : state_(state) {}
  std::uint64_t state_;
  double spare_ = 0;
  bool has_spare_ = false;
};

}  // namespace kdm::gen
