// Internal: finding the keyframes around an expected count, shared by loading (its tables) and queries.
#pragma once

#include <cstdint>
#include <cstring>

#include "query_tables.h"

namespace kdm {
namespace detail {

/// Buckets of expected counts for first_keyframe_at_least (query_tables.h): kBucketsPerOctave per power of
/// two from 2^-32 to 2^32 (smaller counts share the first, larger ones the last), from the double's exponent
/// and leading mantissa bits. A bucket's smallest count is (1 + m / kBucketsPerOctave) · 2^e, and none is
/// wider than 1 / kBucketsPerOctave of it (3.1%): keyframes farther apart than that are one step away.
inline constexpr int kMantissaBits = 5;
inline constexpr int kBucketsPerOctave = 1 << kMantissaBits;
inline constexpr int kCountBuckets = 64 * kBucketsPerOctave;
inline int count_bucket(double v) {
  std::uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  // The exponent and leading mantissa bits of a positive double: (e + 1023) · kBucketsPerOctave + m.
  const std::uint64_t b = (bits >> (52 - kMantissaBits)) - std::uint64_t(1023 - 32) * kBucketsPerOctave;
  if (b < kCountBuckets) return static_cast<int>(b);
  return v < 1 ? 0 : kCountBuckets - 1;  // beyond the table (or negative: sign bit set)
}

/// A set's keyframe tables as plain pointers (a query's copy: see TileJob).
struct KeyframeTable {
  const double* nominal = nullptr;  ///< K_g, then +∞ (QueryTables::keyframe_nominal)
  std::uint32_t n = 0;
  const GlideSpan* spans = nullptr;      ///< QueryTables::glide_spans
  bool one_step = false;                 ///< QueryTables::keyframe_one_step
  const std::uint16_t* guess = nullptr;  ///< the first keyframe at least each count_bucket's smallest count
  /// The first g with K_g >= expected (> 0), or n.
  std::uint32_t first_at_least(double expected) const {
    std::uint32_t g = guess[count_bucket(expected)];
    g += nominal[g] < expected;  // one step at most with a few keyframes per power of two: no branch
    if (!one_step)
      while (nominal[g] < expected) ++g;
    return g;
  }
};

/// Where between two keyframes an expected count per tile falls: keyframes g0 <= g1 and the weights of
/// their offsets, w0 = (1 − t) and w1 = t times each keyframe's unit (QueryTables::glide_scale), t the
/// fraction of the way from g0 to g1 (linear in the count; 0 below the first keyframe and above the last).
struct GlideBracket {
  std::uint32_t g0 = 0, g1 = 0;
  double w0 = 0, w1 = 0;
  GlideBracket() = default;
  GlideBracket(const KeyframeTable& k, double expected) {
    const GlideSpan& span = k.spans[k.first_at_least(expected)];
    const double t = (expected - span.base) * span.inverse_gap;
    g0 = span.g0, g1 = span.g1, w0 = (1 - t) * span.scale0, w1 = t * span.scale1;
  }
};

inline KeyframeTable keyframe_table(const Tileset& set) {
  const QueryTables& t = TilesetInternals::tables(set);
  KeyframeTable k;
  k.nominal = t.keyframe_nominal.data();
  k.n = static_cast<std::uint32_t>(set.data().keyframe_nominal.size());
  k.spans = t.glide_spans.data();
  k.one_step = t.keyframe_one_step;
  k.guess = t.keyframe_guess.data();
  return k;
}

}  // namespace detail
}  // namespace kdm
