// Checks that keep untrusted image bytes away from the faults of the system's stb_image (image_faults.cpp
// says which); image_io.cpp runs them before stb reads a file.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace kdm::tools {

// The first chunk of `type` before a PNG's first IDAT: its data's offset and length (of a chunk cut short,
// what is there), or false (for anything else too).
bool png_chunk(const std::uint8_t* data, std::size_t size, const char type[4], std::size_t& at,
               std::size_t& length);

// Whether a PNG holds a chunk of `type` before its first IDAT (false for anything else).
bool png_has_chunk(const std::uint8_t* data, std::size_t size, const char type[4]);

// A PNG's size from its IHDR chunk (the first), or false: stb refuses to read even the header of a PNG
// whose pixels would pass 2^30 bytes, and its reason then names no size.
bool png_size(const std::uint8_t* data, std::size_t size, std::uint64_t& w, std::uint64_t& h);

// A binary PGM/PPM header (P5, P6) as stbi__pnm_info reads it.
struct PnmHeader {
  bool pnm = false, overflow = false;  // overflow: a number past INT_MAX (undefined behaviour in stb)
  std::int64_t width = 0, height = 0, max_value = 0;
  int channels = 0;
  std::size_t pixels_at = 0;  // offset of the first sample
  std::uint64_t pixel_bytes() const {
    return std::uint64_t(width) * std::uint64_t(height) * channels * (max_value > 255 ? 2 : 1);
  }
};

// The header of a binary PGM/PPM file (pnm false for anything else).
PnmHeader pnm_header(const std::uint8_t* data, std::size_t size);

// What is wrong with a Radiance (.hdr) file that stb would read anyway, or "": stb's reader takes zeros for
// bytes past the end, so a file cut short gives a wrong density with no error, and the headers it does not
// read (another orientation, no FORMAT line) it calls an unknown type. Walks the header and the scanlines
// as stbi__hdr_load does.
std::string radiance_fault(const std::uint8_t* data, std::size_t size);

// stb_image reads a palette entry past a file's palette (a PNG's PLTE, a BMP's colour table) from its own
// uninitialised stack, so a corrupt file would decode differently each time. Such a file is decoded from
// a copy in `padded` whose palette is filled up with black entries, as libpng reads an index past the
// palette. Returns false when the file needs no copy.
bool pad_palette(const std::uint8_t* data, std::size_t size, std::vector<std::uint8_t>& padded);

// The input stb would fault on, or nullptr.
const char* stb_fault(const std::uint8_t* data, std::size_t size);

}  // namespace kdm::tools
