// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320), as in zlib and PNG.
#pragma once

#include <cstddef>
#include <cstdint>

namespace kdm::detail {

/// Continues a CRC-32 over `size` bytes; start with crc = 0. Thread-safe.
std::uint32_t crc32(const void* data, std::size_t size, std::uint32_t crc = 0);

}  // namespace kdm::detail
