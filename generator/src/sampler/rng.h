// Counter-based random streams: every (seed, purpose, level, sweep, point) gets its own stream, so the
// sampler's output depends on the seed only — not on thread count or scheduling.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

#include "kdm/runtime/hash.h"

namespace kdm::gen {

/// The layers of the ziggurat for the standard normal (Marsaglia and Tsang, "The Ziggurat Method for
/// Generating Random Variables", J. Stat. Softw. 5(8), 2000), 256 layers of equal area.
struct NormalZiggurat {
  static constexpr int kLayers = 256;
  static constexpr double kTailStart = 3.6541528853610088;  ///< r: where the base layer's tail begins
  static constexpr double kLayerArea = 0.00492867323399;    ///< v: the area of every layer
  /// x[i]: layer i's half-width; x[0] is the base layer's equivalent width (area v / f(r)), x[256] = 0.
  std::array<double, kLayers + 1> x{};
  /// f(x[i]) with f(t) = exp(-t²/2), the unnormalised density.
  std::array<double, kLayers + 1> f{};
  /// x[i + 1] / x[i]: |u| below this is inside layer i's sure part.
  std::array<double, kLayers> inner{};

  NormalZiggurat() {
    const double fr = std::exp(-0.5 * kTailStart * kTailStart);
    x[0] = kLayerArea / fr;
    x[1] = kTailStart;
    for (int i = 1; i < kLayers - 1; ++i)
      x[i + 1] = std::sqrt(-2 * std::log(kLayerArea / x[i] + density(x[i])));
    x[kLayers] = 0;
    for (int i = 0; i <= kLayers; ++i) f[i] = density(x[i]);
    for (int i = 0; i < kLayers; ++i) inner[i] = x[i + 1] / x[i];
  }
  static double density(double t) { return std::exp(-0.5 * t * t); }
  static const NormalZiggurat& get() {
    static const NormalZiggurat table;
    return table;
  }
};

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
  /// Standard normal by the ziggurat: one 64-bit draw and a comparison 99% of the time. Box–Muller's log,
  /// sin and cos made normal_box_muller() a sixth of the sampler's run time.
  double normal() {
    const NormalZiggurat& z = NormalZiggurat::get();
    for (;;) {
      const std::uint64_t bits = next();
      const int layer = static_cast<int>(bits & (NormalZiggurat::kLayers - 1));
      // The top 53 bits as a signed fraction u in [-1, 1); the layer used the low 8.
      const double u = static_cast<double>(static_cast<std::int64_t>(bits) >> 11) * 0x1.0p-52;
      if (std::fabs(u) < z.inner[layer]) return u * z.x[layer];
      if (layer == 0) {  // the tail beyond r (Marsaglia 1964)
        double a, b;
        do {
          a = -std::log1p(-uniform()) / NormalZiggurat::kTailStart;
          b = -std::log1p(-uniform());
        } while (b + b < a * a);
        return u < 0 ? -(NormalZiggurat::kTailStart + a) : NormalZiggurat::kTailStart + a;
      }
      const double t = u * z.x[layer];
      // Layer i spans heights f(x[i]) .. f(x[i + 1]); accept t under the curve.
      if (z.f[layer] + uniform() * (z.f[layer + 1] - z.f[layer]) < NormalZiggurat::density(t)) return t;
    }
  }

  /// Standard normal by Box–Muller (the second value is cached): the stream tile baking keeps, so that a
  /// recipe bakes the same tiles in every kdm version.
  double normal_box_muller() {
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
