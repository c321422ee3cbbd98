// Internal: glide offsets (signed bytes) as doubles by a table lookup (emit_tile.h, subtile_loops.h).
#pragma once

namespace kdm::detail {

/// Every signed byte as a double: a load instead of a conversion with its false dependency.
struct SignedByteTable {
  double value[256];
  constexpr SignedByteTable() : value() {
    for (int i = 0; i < 256; ++i) value[i] = i - 128;
  }
};
inline constexpr SignedByteTable kSignedByte;

}  // namespace kdm::detail
