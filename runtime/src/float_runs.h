// Internal: the compact output's whole runs of points (compact_query.h, emit_tile.h's CompactSink), the
// loops that bound its speed, compiled for several instruction sets with the same bits (run_clones.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "kdm/runtime/tileset_format.h"

namespace kdm::detail {

/// A rectangle in the compact output's coordinates: x0 ≤ x < x1 and y0 ≤ y < y1.
struct FloatBox {
  float x0, y0, x1, y1;
};

/// What box_flags finds of a position: outside `may`, inside `sure` (which lies inside `may`), or between.
constexpr std::uint8_t kBoxOut = 0, kBoxIn = 1, kBoxUnsure = 2;

/// The first k in [i, count) whose flag is kBoxUnsure, else count.
inline std::uint32_t next_unsure(const std::uint8_t* flags, std::uint32_t i, std::uint32_t count) {
  constexpr std::uint64_t kAnyUnsure = 0x0202020202020202u;  // eight at a time: few are unsure
  for (std::uint64_t w; i + 8 <= count; i += 8)
    if (std::memcpy(&w, flags + i, 8), (w & kAnyUnsure) != 0) break;
  while (i < count && flags[i] != kBoxUnsure) ++i;
  return i;
}

/// The first k in [i, count) whose flag is not kBoxIn, else count.
inline std::uint32_t next_unsettled(const std::uint8_t* flags, std::uint32_t i, std::uint32_t count) {
  constexpr std::uint64_t kAllIn = 0x0101010101010101u;  // eight at a time: nearly all are in
  for (std::uint64_t w; i + 8 <= count; i += 8)
    if (std::memcpy(&w, flags + i, 8), w != kAllIn) break;
  while (i < count && flags[i] == kBoxIn) ++i;
  return i;
}

}  // namespace kdm::detail

// Outside namespace kdm: GCC gives a target_clones function's ifunc default visibility whatever
// -fvisibility says, and the shared library's version script exports kdm::* (run_clones.h).
namespace kdm_runs {
using namespace kdm;
using namespace kdm::detail;

/// to[2k], to[2k + 1] = rx + from[k].x · unit, ry + from[k].y · unit, for k < count.
void stable_run_xy(const TilePoint* from, std::size_t count, float rx, float ry, float unit, float* to);

/// The same plus the glide: o0[2k] · w0 + o1[2k] · w1 in x (and o0[2k + 1], o1[2k + 1] in y).
void glided_run_xy(const TilePoint* from, const std::int8_t* o0, const std::int8_t* o1, std::size_t count,
                   float rx, float ry, float unit, float w0, float w1, float* to);

/// flags[k] for the position xy[2k], xy[2k + 1], k < count.
void box_flags(const float* xy, std::size_t count, FloatBox sure, FloatBox may, std::uint8_t* flags);

/// to[k] = first + k · step, for k < count.
void key_run(std::uint64_t* to, std::size_t count, std::uint64_t first, std::uint64_t step);

}  // namespace kdm_runs

namespace kdm::detail {
using kdm_runs::box_flags;
using kdm_runs::glided_run_xy;
using kdm_runs::key_run;
using kdm_runs::stable_run_xy;
}  // namespace kdm::detail
