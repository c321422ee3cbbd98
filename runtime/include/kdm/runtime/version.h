// kdm runtime: library and tile-set format versions.
#pragma once

#include <cstdint>

#include "kdm/runtime/export.h"

namespace kdm {

/// Version of the tile-set file format this build writes. Bumped on any incompatible change.
inline constexpr std::uint32_t kTilesetFormatVersion = 7;
/// The oldest version this build still reads (2: no glide track; 3: 16-bit glide offsets; 4: no hand-over,
/// which is also what a set without one is written in; 5: a hand-over onto the subtiles' level 0, also
/// what such a set is written in; 6: onto a finer level, without slack).
inline constexpr std::uint32_t kOldestTilesetFormatVersion = 2;

/// The library version, "MAJOR.MINOR.PATCH". Thread-safe; returns a static string.
KDM_RUNTIME_API const char* version_string();
/// The same as a number to compare: MAJOR · 10000 + MINOR · 100 + PATCH (0.5.0: 500).
KDM_RUNTIME_API std::uint32_t version_number();

}  // namespace kdm
