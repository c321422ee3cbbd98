// Inputs that would reach a fault of the stb_image kdm builds with (2.27, Debian 12's libstb-dev), found by
// tests/fuzz/fuzz_image: they are refused (or padded) before stb reads them. Each check mirrors how stb walks
// the format and refuses only inputs stb cannot decode anyway (corrupt or truncated), so no valid image is
// turned away.
#include "image_faults.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <string_view>

#include "image_io.h"

namespace kdm::tools {
namespace {

struct Bytes {  // stb's reading conventions: zeros past the end
  const std::uint8_t* data;
  std::size_t size, pos = 0;
  bool eof() const { return pos >= size; }
  int get8() { return pos < size ? data[pos++] : 0; }
  int get16() {
    const int high = get8();
    return high << 8 | get8();
  }
  void skip(std::size_t n) { pos = n < size - std::min(pos, size) ? pos + n : size; }
};

enum class Segment { kRead, kFault, kStop };  // stb reads on; stb would write out of bounds; stb stops

// A JPEG DHT segment (after its marker) as stbi__process_marker reads it. A table of more than 256 codes
// makes stb write past its Huffman arrays (and later read through the damaged ones): heap corruption.
Segment jpeg_huffman_tables(Bytes& b) {
  int left = b.get16() - 2;
  while (left > 0) {
    const int q = b.get8();
    if ((q >> 4) > 1 || (q & 15) > 3) return Segment::kStop;
    int codes = 0;
    for (int i = 0; i < 16; ++i) codes += b.get8();
    if (codes > 256) return Segment::kFault;
    b.skip(static_cast<std::size_t>(codes));
    left -= 17 + codes;
  }
  return left == 0 ? Segment::kRead : Segment::kStop;
}

// Whether stb would fault on a JPEG's Huffman tables. The markers before the frame header are walked as
// stbi__decode_jpeg_header does, skipping what it skips (APPn and COM payloads, quantisation tables);
// from the frame header on, or wherever stb would give up, every FF C4 pair is taken for a DHT marker, as
// stb may take any of them for one (scans end at the first marker, and stb resynchronises on 0xFF).
bool jpeg_faults(const std::uint8_t* data, std::size_t size) {
  constexpr int kNone = 0xFF;  // stb's "no marker"
  Bytes b{data, size};
  auto marker = [&b] {
    int x = b.get8();
    if (x != 0xFF) return kNone;
    while (x == 0xFF) x = b.get8();
    return x;
  };
  if (marker() != 0xD8) return false;  // no SOI: stb does not read it as a JPEG
  for (int m = marker(); m != 0xC0 && m != 0xC1 && m != 0xC2;) {
    Segment s = Segment::kStop;
    if (m == 0xC4) {
      s = jpeg_huffman_tables(b);
    } else if (m == 0xDB) {  // quantisation tables
      int left = b.get16() - 2;
      s = Segment::kRead;
      while (left > 0 && s == Segment::kRead) {
        const int q = b.get8();
        if ((q >> 4) > 1 || (q & 15) > 3) s = Segment::kStop;
        b.skip(q >> 4 ? 128 : 64);
        left -= q >> 4 ? 129 : 65;
      }
      if (left != 0) s = Segment::kStop;
    } else if (m == 0xDD) {  // restart interval
      s = b.get16() == 4 ? Segment::kRead : Segment::kStop;
      b.skip(2);
    } else if ((m >= 0xE0 && m <= 0xEF) || m == 0xFE) {  // APPn, COM
      const int length = b.get16();
      if (length >= 2) s = Segment::kRead, b.skip(static_cast<std::size_t>(length - 2));
    }
    if (s == Segment::kFault) return true;
    if (s == Segment::kStop) break;
    m = marker();
    while (m == kNone) {  // stb scans over padding between segments
      if (b.eof()) return false;
      m = marker();
    }
  }
  for (std::size_t i = b.pos == 0 ? 0 : b.pos - 1; i + 1 < size; ++i)
    if (data[i] == 0xFF && data[i + 1] == 0xC4) {
      Bytes dht{data, size, i + 2};
      if (jpeg_huffman_tables(dht) == Segment::kFault) return true;
    }
  return false;
}

// Whether a PNG ends before its IEND chunk, or its chunks claim more bytes than there are: stb allocates
// an IDAT buffer of the claimed length before reading it (gigabytes from a few bytes), and a file cut
// inside a chunk header it reports as an unknown chunk type.
bool png_truncated(const std::uint8_t* data, std::size_t size) {
  static const std::uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (size < 8 || std::memcmp(data, kSignature, 8) != 0) return false;
  auto be32 = [data](std::size_t at) {
    return std::uint32_t(data[at]) << 24 | std::uint32_t(data[at + 1]) << 16 |
           std::uint32_t(data[at + 2]) << 8 | data[at + 3];
  };
  for (std::size_t pos = 8; size - pos >= 8;) {
    const std::uint32_t length = be32(pos), type = be32(pos + 4);
    if (type == 0x49454E44) return false;  // IEND: stb reads no further
    if (length > size - pos - 8) return true;
    pos += 8 + std::size_t(length);
    if (size - pos < 4) return true;  // no CRC
    pos += 4;
  }
  return true;  // no IEND: stb decodes nothing without one
}

}  // namespace

bool png_chunk(const std::uint8_t* data, std::size_t size, const char type[4], std::size_t& at,
               std::size_t& length) {
  static const std::uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (size < 8 || std::memcmp(data, kSignature, 8) != 0) return false;
  for (std::size_t pos = 8; size - pos >= 8;) {
    const std::uint32_t n = std::uint32_t(data[pos]) << 24 | std::uint32_t(data[pos + 1]) << 16 |
                            std::uint32_t(data[pos + 2]) << 8 | data[pos + 3];
    if (std::memcmp(data + pos + 4, type, 4) == 0) {
      at = pos + 8, length = std::min<std::size_t>(n, size - pos - 8);  // a chunk cut short: what is there
      return true;
    }
    if (std::memcmp(data + pos + 4, "IDAT", 4) == 0 || n > size - pos - 8) return false;
    pos += 12 + std::size_t(n);
    if (pos > size) return false;
  }
  return false;
}

bool png_has_chunk(const std::uint8_t* data, std::size_t size, const char type[4]) {
  std::size_t at = 0, length = 0;
  return png_chunk(data, size, type, at, length);
}

// A PNG's size from its IHDR chunk (the first), or false: stb refuses to read even the header of a PNG
// whose pixels would pass 2^30 bytes, and its reason then names no size.
bool png_size(const std::uint8_t* data, std::size_t size, std::uint64_t& w, std::uint64_t& h) {
  static const std::uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (size < 24 || std::memcmp(data, kSignature, 8) != 0 || std::memcmp(data + 12, "IHDR", 4) != 0)
    return false;
  auto be32 = [data](std::size_t at) {
    return std::uint32_t(data[at]) << 24 | std::uint32_t(data[at + 1]) << 16 |
           std::uint32_t(data[at + 2]) << 8 | data[at + 3];
  };
  w = be32(16), h = be32(20);
  return true;
}

PnmHeader pnm_header(const std::uint8_t* data, std::size_t size) {
  PnmHeader header;
  Bytes b{data, size};
  const int p = b.get8(), t = b.get8();
  if (p != 'P' || (t != '5' && t != '6')) return header;
  header.pnm = true;
  header.channels = t == '6' ? 3 : 1;
  // As stb: c is the last byte read; "eof" means nothing is left after it.
  int c = b.get8();
  auto space = [](int ch) {
    return ch == ' ' || ch == '\t' || ch == '\n' || ch == '\v' || ch == '\f' || ch == '\r';
  };
  auto skip_space = [&] {
    for (;;) {
      while (!b.eof() && space(c)) c = b.get8();
      if (b.eof() || c != '#') break;
      while (!b.eof() && c != '\n' && c != '\r') c = b.get8();
    }
  };
  auto integer = [&] {
    std::int64_t value = 0;
    while (!b.eof() && c >= '0' && c <= '9') {
      value = value * 10 + (c - '0');
      if (value > std::numeric_limits<int>::max())
        header.overflow = true, value = std::numeric_limits<int>::max();
      c = b.get8();
    }
    return value;
  };
  skip_space();
  header.width = integer();
  skip_space();
  header.height = integer();
  skip_space();
  header.max_value = integer();
  header.pixels_at = b.pos;
  return header;
}

namespace {

// Whether a PGM/PPM header overflows stb's int parser, or its pixels are cut short (stb ignores that and
// returns the missing ones uninitialised).
bool pnm_faults(const std::uint8_t* data, std::size_t size) {
  const PnmHeader h = pnm_header(data, size);
  if (!h.pnm) return false;
  if (h.overflow) return true;
  return h.max_value <= 65535 && h.pixel_bytes() > size - h.pixels_at;  // (stb refuses larger maxima)
}

}  // namespace

// What is wrong with a Radiance (.hdr) file that stb would read anyway, or "": stb's reader takes zeros for
// bytes past the end, so a file cut short gives a wrong density with no error, and the headers it does not
// read (another orientation, no FORMAT line) it calls an unknown type. Walks the header and the scanlines
// as stbi__hdr_load does.
std::string radiance_fault(const std::uint8_t* data, std::size_t size) {
  const std::string_view all(reinterpret_cast<const char*>(data), size);
  if (!is_radiance(data, size)) return "";
  std::size_t pos = all.find('\n') + 1;
  bool format = false;
  for (;;) {  // header lines up to an empty one
    const std::size_t end = all.find('\n', pos);
    if (end == std::string_view::npos) return "a Radiance image cut short in its header";
    const std::string_view line = all.substr(pos, end - pos);
    pos = end + 1;
    if (line.empty()) break;
    format = format || line == "FORMAT=32-bit_rle_rgbe";
  }
  if (!format) return "a Radiance image without the line FORMAT=32-bit_rle_rgbe (the only format read)";
  const std::size_t end = all.find('\n', pos);
  if (end == std::string_view::npos) return "a Radiance image cut short in its size line";
  const std::string_view line = all.substr(pos, end - pos);
  long long h = 0, w = 0;
  if (std::sscanf(std::string(line).c_str(), "-Y %lld +X %lld", &h, &w) != 2 || h <= 0 || w <= 0)
    return "a Radiance image whose size line is '" + std::string(line.substr(0, 40)) +
           "': only '-Y height +X width' (rows from the top, left to right) is read";
  pos = end + 1;
  const auto flat_from = [&](std::size_t at) {  // stb then reads the whole image as plain 4-byte pixels
    return std::uint64_t(size - at) / 4 / std::uint64_t(w) < std::uint64_t(h);
  };
  if (w < 8 || w >= 32768) return flat_from(pos) ? "a Radiance image cut short in its pixels" : "";
  for (long long j = 0; j < h; ++j) {
    if (size - pos < 4) return "a Radiance image cut short in its pixels";
    if (data[pos] != 2 || data[pos + 1] != 2 || (data[pos + 2] & 0x80))
      return flat_from(pos) ? "a Radiance image cut short in its pixels" : "";
    pos += 4;
    for (int channel = 0; channel < 4; ++channel)
      for (long long i = 0; i < w;) {
        if (pos >= size) return "a Radiance image cut short in its pixels";
        const int count = data[pos++], n = count > 128 ? count - 128 : count;
        // stb 2.27 never leaves a run of length 0 (it reads on in place); a longer run than the
        // scanline's rest it refuses itself.
        if (n == 0) return "corrupt Radiance image (a run of length 0)";
        if (n > w - i) return "";
        pos += count > 128 ? 1 : std::size_t(n);
        i += n;
      }
    if (pos > size) return "a Radiance image cut short in its pixels";
  }
  return "";
}

namespace {

// A BMP of 1, 4 or 8 bits a pixel: its palette as stb_image counts it from the pixels' offset (the count
// for the 12-byte header reads four fewer entries than the file holds, and can be negative).
struct BmpPalette {
  int bits = 0;
  std::int64_t offset = 0, header = 0, entry = 0, entries = 0;  // entries 0: no palette BMP
};

BmpPalette bmp_palette(const std::uint8_t* data, std::size_t size) {
  BmpPalette bmp;
  if (size < 2 || data[0] != 'B' || data[1] != 'M') return bmp;
  const auto byte = [&](std::size_t at) { return at < size ? std::uint32_t(data[at]) : 0u; };  // as stb reads
  const auto le32 = [&](std::size_t at) {
    return byte(at) | byte(at + 1) << 8 | byte(at + 2) << 16 | byte(at + 3) << 24;
  };
  bmp.offset = std::int32_t(le32(10)), bmp.header = le32(14);
  if (bmp.header != 12 && bmp.header != 40 && bmp.header != 56 && bmp.header != 108 && bmp.header != 124)
    return bmp;
  bmp.bits = int(bmp.header == 12 ? byte(24) | byte(25) << 8 : byte(28) | byte(29) << 8);
  if ((bmp.bits != 1 && bmp.bits != 4 && bmp.bits != 8) || bmp.offset < 0) return bmp;
  bmp.entry = bmp.header == 12 ? 3 : 4;
  bmp.entries = bmp.header == 12 ? (bmp.offset - 14 - 24) / 3 : (bmp.offset - 14 - bmp.header) >> 2;
  return bmp;
}

}  // namespace

// stb_image reads a palette entry past a file's palette (a PNG's PLTE, a BMP's colour table) from its own
// uninitialised stack, so a corrupt file would decode differently each time. Such a file is decoded from
// a copy in `padded` whose palette is filled up with black entries, as libpng reads an index past the
// palette. Returns false when the file needs no copy.
bool pad_palette(const std::uint8_t* data, std::size_t size, std::vector<std::uint8_t>& padded) {
  static const std::uint8_t kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  const auto be32 = [data](std::size_t at) {
    return std::uint32_t(data[at]) << 24 | std::uint32_t(data[at + 1]) << 16 |
           std::uint32_t(data[at + 2]) << 8 | data[at + 3];
  };
  if (size >= 26 && std::memcmp(data, kPng, 8) == 0 && std::memcmp(data + 12, "IHDR", 4) == 0 &&
      data[25] == 3) {
    for (std::size_t pos = 8; size - pos >= 12;) {  // a palette image: its PLTE chunk (stb reads one)
      const std::uint32_t length = be32(pos);
      if (length > size - pos - 12) return false;  // cut short: refused elsewhere, or read as zeros
      if (std::memcmp(data + pos + 4, "IDAT", 4) == 0) return false;
      if (std::memcmp(data + pos + 4, "PLTE", 4) == 0) {
        if (length % 3 != 0 || length >= 768) return false;  // stb refuses the first; the second is whole
        padded.assign(data, data + pos);
        for (int shift = 24; shift >= 0; shift -= 8) padded.push_back(std::uint8_t(768 >> shift));
        padded.insert(padded.end(), data + pos + 4, data + pos + 8 + length);
        padded.resize(padded.size() + 768 - length, 0);
        padded.insert(padded.end(), 4, 0);  // the CRC, which stb does not check
        padded.insert(padded.end(), data + pos + 12 + length, data + size);
        return true;
      }
      pos += 12 + std::size_t(length);
    }
    return false;
  }
  if (const BmpPalette bmp = bmp_palette(data, size); bmp.entries > 0) {
    const std::int64_t end = 14 + bmp.header + bmp.entries * bmp.entry;  // where stb stops reading it
    const std::int64_t needed = std::int64_t(1) << bmp.bits;
    if (bmp.entries >= needed || end > std::int64_t(size)) return false;
    const std::int64_t added = (needed - bmp.entries) * bmp.entry;
    if (bmp.offset + added > INT32_MAX) return false;
    padded.assign(data, data + end);
    padded.resize(padded.size() + std::size_t(added), 0);
    padded.insert(padded.end(), data + end, data + size);
    const auto moved = std::uint32_t(bmp.offset + added);
    for (int i = 0; i < 4; ++i) padded[10 + i] = std::uint8_t(moved >> (8 * i));
    return true;
  }
  return false;
}

// The input stb would fault on, or nullptr.
const char* stb_fault(const std::uint8_t* data, std::size_t size) {
  if (jpeg_faults(data, size)) return "corrupt JPEG (a Huffman table of more than 256 codes)";
  if (png_truncated(data, size)) return "corrupt PNG (cut short: it ends inside a chunk or before IEND)";
  if (pnm_faults(data, size)) return "corrupt PGM/PPM (a header number too large, or pixels cut short)";
  // stb would read no palette and draw every pixel from its uninitialised stack.
  if (bmp_palette(data, size).entries < 0) return "corrupt BMP (its pixels start inside its header)";
  return nullptr;
}

}  // namespace kdm::tools
