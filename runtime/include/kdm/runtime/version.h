// kdm runtime: library and tile-set format versions.
#pragma once

#include <cstdint>

namespace kdm {

/// Version of the tile-set file format this build reads and writes. Bumped on any incompatible change.
inline constexpr std::uint32_t kTilesetFormatVersion = 2;

/// The library version, "MAJOR.MINOR.PATCH". Thread-safe; returns a static string.
const char* version_string();

}  // namespace kdm
