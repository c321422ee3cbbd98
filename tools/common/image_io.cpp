#include "image_io.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include <sys/stat.h>
#include <unistd.h>

#define STB_IMAGE_IMPLEMENTATION
#define STBI_FAILURE_USERMSG
// Zeroed memory: stb 2.27 reads some of its allocations before writing them, e.g. the Huffman tables of a
// JPEG scan that no DHT segment defined (whose garbage offsets then index out of bounds).
#define STBI_MALLOC(size) std::calloc(1, size)
#define STBI_REALLOC(p, size) std::realloc(p, size)
#define STBI_FREE(p) std::free(p)
#include <stb_image.h>
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>

namespace kdm::tools {
namespace {

std::string temp_path_for(const std::string& path) {
  return path + ".tmp~";
}

// The temporary file being written, for a signal handler to remove: marked only where the handlers are
// installed (one writing thread), so that a library's threads never share it.
std::atomic<bool> signals_handled{false};
char marked_path[4096];
std::atomic<bool> marked{false};  // lock-free: a handler on any thread reads it; the path is whole once set
static_assert(std::atomic<bool>::is_always_lock_free, "a signal handler may only read lock-free atomics");

extern "C" void remove_marked_and_reraise(int signal) {
  if (marked.load(std::memory_order_acquire)) unlink(marked_path);  // async-signal-safe
  struct sigaction fallback = {};
  fallback.sa_handler = SIG_DFL;
  sigaction(signal, &fallback, nullptr);
  raise(signal);
}

/// Marks `path` (or nothing, for null) as the temporary file being written.
void mark(const std::string* path) {
  if (!signals_handled.load(std::memory_order_relaxed)) return;
  marked.store(false, std::memory_order_release);
  if (!path || path->size() >= sizeof marked_path) return;
  std::memcpy(marked_path, path->c_str(), path->size() + 1);
  marked.store(true, std::memory_order_release);
}

bool commit_temp(const std::string& tmp, const std::string& path, std::string& error) {
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    error = "cannot write '" + path + "': " + std::strerror(errno);
    std::remove(tmp.c_str());
    return false;
  }
  return true;
}

// ---- Faults of the stb_image kdm builds with (2.27, Debian 12's libstb-dev), found by
// tests/fuzz/fuzz_image: inputs that reach them are refused before stb reads them. Each check mirrors how stb
// walks the format and refuses only inputs stb cannot decode anyway (corrupt or truncated), so no valid image
// is turned away.

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

// Whether a PNG holds a chunk of `type` before its first IDAT (false for anything else).
bool png_has_chunk(const std::uint8_t* data, std::size_t size, const char type[4]) {
  static const std::uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (size < 8 || std::memcmp(data, kSignature, 8) != 0) return false;
  for (std::size_t pos = 8; size - pos >= 8;) {
    const std::uint32_t length = std::uint32_t(data[pos]) << 24 | std::uint32_t(data[pos + 1]) << 16 |
                                 std::uint32_t(data[pos + 2]) << 8 | data[pos + 3];
    if (std::memcmp(data + pos + 4, type, 4) == 0) return true;
    if (std::memcmp(data + pos + 4, "IDAT", 4) == 0 || length > size - pos - 8) return false;
    pos += 12 + std::size_t(length);
    if (pos > size) return false;
  }
  return false;
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

// Whether a PGM/PPM header overflows stb's int parser, or its pixels are cut short (stb ignores that and
// returns the missing ones uninitialised).
bool pnm_faults(const std::uint8_t* data, std::size_t size) {
  const PnmHeader h = pnm_header(data, size);
  if (!h.pnm) return false;
  if (h.overflow) return true;
  return h.max_value <= 65535 && h.pixel_bytes() > size - h.pixels_at;  // (stb refuses larger maxima)
}

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

std::string stb_reason() {
  const char* reason = stbi_failure_reason();
  return reason ? reason : "unknown format";
}

// Why stb read no header: a format it does not read named, with the ones it does; else its reason.
std::string unread_format(const std::uint8_t* bytes, std::size_t size) {
  const auto starts = [&](const auto& magic, std::size_t at = 0) {  // a literal: its bytes, NULs too
    const std::size_t n = sizeof magic - 1;
    return size >= at + n && std::memcmp(bytes + at, magic, n) == 0;
  };
  const char* kind = starts("II*") || (starts("MM") && size >= 4 && bytes[2] == 0 && bytes[3] == 42) ? "TIFF"
                     : starts("RIFF") && starts("WEBP", 8)                                           ? "WebP"
                     : starts("ftyp", 4)                              ? "HEIF/AVIF"
                     : starts("\xff\x0a") || starts("\0\0\0\x0cJXL ") ? "JPEG XL"
                                                                      : nullptr;
  const std::string reason = stb_reason();
  if (!kind && reason != "unknown image type") return reason;
  return std::string(kind ? "a " + std::string(kind) + " image, a format" : "not a format") +
         " kdm does not read (it reads PNG, JPEG, BMP, GIF, TGA, PSD, HDR, PIC and PGM/PPM): convert it to "
         "PNG";
}

// Luminance of `channels`-channel samples of full scale `full`, composited on white paper. The samples are
// converted to float and divided first, as kdm always did, so that outputs stay bit for bit the same.
template <class Sample>
void to_luminance(const Sample* data, int channels, float full, std::vector<float>& pixels) {
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    float p[4] = {0, 0, 0, 1};
    for (int c = 0; c < channels; ++c) p[c] = static_cast<float>(data[i * channels + c]) / full;
    float lum = 0, alpha = 1;
    switch (channels) {
      case 1:
        lum = p[0];
        break;
      case 2:
        lum = p[0];
        alpha = p[1];
        break;
      case 3:
        lum = 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2];
        break;
      default:
        lum = 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2];
        alpha = p[3];
        break;
    }
    pixels[i] = std::clamp(lum * alpha + (1.0f - alpha), 0.0f, 1.0f);
  }
}

// Red, green and blue in [0, 1] composited on white paper (grey images give three equal values).
template <class Sample>
void to_rgb(const Sample* data, int channels, float full, std::vector<float>& pixels) {
  for (std::size_t i = 0; i < pixels.size() / 3; ++i) {
    float p[4] = {0, 0, 0, 1};
    for (int c = 0; c < channels; ++c) p[c] = static_cast<float>(data[i * channels + c]) / full;
    const bool grey = channels < 3;
    const float alpha = channels == 2 ? p[1] : channels == 4 ? p[3] : 1.0f;
    for (int c = 0; c < 3; ++c)
      pixels[3 * i + c] = std::clamp((grey ? p[0] : p[c]) * alpha + (1.0f - alpha), 0.0f, 1.0f);
  }
}

constexpr std::size_t channels_of(const GreyImage&) {
  return 1;
}
constexpr std::size_t channels_of(const ColourImage&) {
  return 3;
}

// The alpha channel alone (grey + alpha, or RGBA), for densities that composite on black paper instead.
template <class Sample>
void to_alpha(const Sample* data, int channels, float full, std::vector<float>& alpha) {
  if (channels != 2 && channels != 4) return alpha.clear();
  for (std::size_t i = 0; i < alpha.size(); ++i)
    alpha[i] = std::clamp(static_cast<float>(data[i * channels + channels - 1]) / full, 0.0f, 1.0f);
}

template <class Sample, class Image>
void convert(const Sample* data, int channels, float full, Image& image) {
  if constexpr (std::is_same_v<Image, GreyImage>)
    to_luminance(data, channels, full, image.pixels);
  else
    to_rgb(data, channels, full, image.pixels);
  image.alpha.resize(image.pixels.size() / channels_of(image));
  to_alpha(data, channels, full, image.alpha);
}

// One axis of an area-weighted reduction of n source pixels to m <= n: source pixel i, covering [i, i + 1),
// gives `share[i]` of itself to kept pixel `first[i]`, which covers [j n / m, (j + 1) n / m), and the rest
// to the next one (a kept pixel is at least a source pixel wide, so a source pixel meets at most two).
struct BoxAxis {
  std::vector<int> first;
  std::vector<double> share;
  BoxAxis(int n, int m) : first(std::size_t(n)), share(std::size_t(n)) {
    const double step = double(n) / m;
    for (int i = 0; i < n; ++i) {
      const int j = std::min(m - 1, static_cast<int>(i / step));
      first[std::size_t(i)] = j;
      share[std::size_t(i)] = j + 1 < m ? std::clamp((j + 1) * step - i, 0.0, 1.0) : 1.0;
    }
  }
};

// `convert` into `kw` × `kh` pixels that average the picture's `w` × `h`: a row is converted at a time
// (values composited as `convert` does them, so averages keep the tone on paper) and summed into the kept
// rows it meets, so that no full-size copy of floats is made.
template <class Sample, class Image>
void convert_reduced(const Sample* data, int channels, float full, int w, int h, int kw, int kh,
                     Image& image) {
  const std::size_t c = channels_of(image), stride = c + 1;  // the values, then alpha, per kept pixel
  const bool has_alpha = channels == 2 || channels == 4;
  const BoxAxis ax(w, kw), ay(h, kh);
  Image row;
  row.pixels.resize(std::size_t(w) * c);
  std::vector<double> sums[2] = {std::vector<double>(std::size_t(kw) * stride),
                                 std::vector<double>(std::size_t(kw) * stride)};
  image.pixels.assign(std::size_t(kw) * kh * c, 0.0f);
  image.alpha.assign(has_alpha ? std::size_t(kw) * kh : 0, 0.0f);
  const double area = double(w) / kw * (double(h) / kh);
  const auto flush = [&](int j) {  // kept row j is whole
    std::vector<double>& sum = sums[j & 1];
    for (std::size_t x = 0; x < std::size_t(kw); ++x) {
      const std::size_t at = std::size_t(j) * kw + x;
      for (std::size_t k = 0; k < c; ++k)
        image.pixels[at * c + k] = static_cast<float>(std::clamp(sum[x * stride + k] / area, 0.0, 1.0));
      if (has_alpha) image.alpha[at] = static_cast<float>(std::clamp(sum[x * stride + c] / area, 0.0, 1.0));
    }
    std::fill(sum.begin(), sum.end(), 0.0);
  };
  int flushed = 0;
  for (int y = 0; y < h; ++y) {
    convert(data + std::size_t(y) * w * channels, channels, full, row);
    const int j = ay.first[std::size_t(y)];
    while (flushed < j) flush(flushed++);
    for (int dy = 0; dy < 2 && j + dy < kh; ++dy) {
      const double wy = dy == 0 ? ay.share[std::size_t(y)] : 1.0 - ay.share[std::size_t(y)];
      if (wy <= 0) continue;
      std::vector<double>& sum = sums[(j + dy) & 1];
      for (std::size_t x = 0; x < std::size_t(w); ++x) {
        const std::size_t i = std::size_t(ax.first[x]);
        const double share = ax.share[x];
        for (std::size_t dx = 0; dx < 2 && i + dx < std::size_t(kw); ++dx) {
          const double weight = wy * (dx == 0 ? share : 1.0 - share);
          if (weight <= 0) continue;
          double* to = &sum[(i + dx) * stride];
          for (std::size_t k = 0; k < c; ++k) to[k] += weight * row.pixels[x * c + k];
          to[c] += weight * (has_alpha ? row.alpha[x] : 1.0f);
        }
      }
    }
  }
  while (flushed < kh) flush(flushed++);
}

// The size `kept` asks a `w` × `h` picture to be kept at: the same shape, each side at least 1.
std::pair<int, int> kept_size(int w, int h, const KeptPixels& kept) {
  const std::uint64_t pixels = std::uint64_t(w) * std::uint64_t(h);
  const std::uint64_t keep = kept ? kept(w, h) : pixels;
  if (keep >= pixels) return {w, h};
  const double factor = std::sqrt(double(pixels) / double(std::max<std::uint64_t>(keep, 1)));
  return {std::clamp(static_cast<int>(std::lround(w / factor)), 1, w),
          std::clamp(static_cast<int>(std::lround(h / factor)), 1, h)};
}

/// Whether every PGM/PPM sample is at most the file's maxval (else `error`: the file is corrupt).
template <class Sample>
bool samples_within(const Sample* data, std::size_t count, std::int64_t max_value, const std::string& name,
                    std::string& error) {
  for (std::size_t i = 0; i < count; ++i)
    if (data[i] > max_value) {
      error = "cannot read image '" + name + "': corrupt PGM/PPM (a sample above its maxval of " +
              std::to_string(max_value) + ")";
      return false;
    }
  return true;
}

// A JPEG's EXIF orientation (1 to 8: how the stored pixels turn to be seen; 1, the default, as stored),
// every read bounds-checked: a file is anyone's.
int jpeg_orientation(const std::uint8_t* bytes, std::size_t size) {
  if (size < 4 || bytes[0] != 0xFF || bytes[1] != 0xD8) return 1;
  std::size_t at = 2;
  while (at + 4 <= size && bytes[at] == 0xFF) {
    const int marker = bytes[at + 1];
    if (marker == 0xD9 || marker == 0xDA) break;  // the image data: no EXIF past it
    const std::size_t length = std::size_t(bytes[at + 2]) << 8 | bytes[at + 3];
    if (length < 2 || at + 2 + length > size) break;
    if (marker == 0xE1 && length >= 16 && std::memcmp(bytes + at + 4, "Exif\0\0", 6) == 0) {
      const std::uint8_t* tiff = bytes + at + 10;
      const std::size_t n = length - 8;
      const bool little = tiff[0] == 'I' && tiff[1] == 'I';
      if (!little && !(tiff[0] == 'M' && tiff[1] == 'M')) return 1;
      auto u16 = [&](std::size_t i) {
        return little ? tiff[i] | tiff[i + 1] << 8 : tiff[i] << 8 | tiff[i + 1];
      };
      auto u32 = [&](std::size_t i) {
        return little ? std::uint32_t(u16(i)) | std::uint32_t(u16(i + 2)) << 16
                      : std::uint32_t(u16(i)) << 16 | std::uint32_t(u16(i + 2));
      };
      if (u16(2) != 42) return 1;
      const std::size_t ifd = u32(4);
      if (ifd > n || n - ifd < 2) return 1;
      const std::size_t entries = std::size_t(u16(ifd));
      for (std::size_t e = 0; e < entries && ifd + 2 + 12 * (e + 1) <= n; ++e) {
        const std::size_t entry = ifd + 2 + 12 * e;
        if (u16(entry) == 0x0112 && u16(entry + 2) == 3) {  // Orientation, a SHORT
          const int value = u16(entry + 8);
          return value >= 1 && value <= 8 ? value : 1;
        }
      }
      return 1;
    }
    at += 2 + length;
  }
  return 1;
}

// The image turned as its EXIF `orientation` says it is seen (rows top first; 5 to 8 swap the sides).
template <class Image>
void apply_orientation(Image& image, int orientation) {
  if (orientation == 1) return;
  const int w = image.width, h = image.height;
  const bool swap = orientation >= 5;
  const int ow = swap ? h : w, oh = swap ? w : h;
  const std::size_t c = channels_of(image);
  auto source = [&](int x, int y) {  // the stored pixel shown at (x, y)
    switch (orientation) {
      case 2:
        return std::pair{w - 1 - x, y};
      case 3:
        return std::pair{w - 1 - x, h - 1 - y};
      case 4:
        return std::pair{x, h - 1 - y};
      case 5:
        return std::pair{y, x};
      case 6:
        return std::pair{y, h - 1 - x};
      case 7:
        return std::pair{w - 1 - y, h - 1 - x};
      default:
        return std::pair{w - 1 - y, x};  // 8
    }
  };
  std::vector<float> pixels(image.pixels.size()), alpha(image.alpha.size());
  for (int y = 0; y < oh; ++y)
    for (int x = 0; x < ow; ++x) {
      const auto [sx, sy] = source(x, y);
      const std::size_t to = std::size_t(y) * ow + x, from = std::size_t(sy) * w + sx;
      for (std::size_t k = 0; k < c; ++k) pixels[to * c + k] = image.pixels[from * c + k];
      if (!alpha.empty()) alpha[to] = image.alpha[from];
    }
  image.pixels = std::move(pixels), image.alpha = std::move(alpha);
  image.width = ow, image.height = oh;
}

// Both loaders end here, with the image file's bytes: the known faults of stb refused, then the header
// read (its size; nothing is allocated) and refused over `max_pixels`; only then are the pixels decoded.
template <class Image>
bool load_image(const std::uint8_t* bytes, std::size_t size, const std::string& name,
                std::uint64_t max_pixels, Image& out, std::string& error, const KeptPixels& kept,
                double white) {
  if (size == 0) {
    error = "cannot read image '" + name + "': the file is empty";
    return false;
  }
  if (size > static_cast<std::size_t>(std::numeric_limits<int>::max())) {  // stb's byte count is an int
    error = "cannot read image '" + name + "': larger than 2 GiB";
    return false;
  }
  if (const char* fault = stb_fault(bytes, size)) {
    error = "cannot read image '" + name + "': " + fault;
    return false;
  }
  if (const std::string fault = radiance_fault(bytes, size); !fault.empty()) {
    error = "cannot read image '" + name + "': " + fault;
    return false;
  }
  std::vector<std::uint8_t> padded;
  if (pad_palette(bytes, size, padded)) {
    if (padded.size() > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
      error = "cannot read image '" + name + "': larger than 2 GiB";
      return false;
    }
    bytes = padded.data(), size = padded.size();
  }
  // stb reads PGM/PPM samples as they are, whatever the file's maxval: full scale is the maxval here.
  const PnmHeader pnm = pnm_header(bytes, size);
  if (pnm.pnm && pnm.max_value == 0) {
    error = "cannot read image '" + name + "': corrupt PGM/PPM (a maxval of 0)";
    return false;
  }
  const int length = static_cast<int>(size);
  int w = 0, h = 0, header_channels = 0;  // PNGs may decode to one more channel (a tRNS chunk): not used
  if (!stbi_info_from_memory(bytes, length, &w, &h, &header_channels)) {
    std::uint64_t pw = 0, ph = 0;
    if (png_size(bytes, size, pw, ph) && pw * ph > max_pixels) {
      w = int(std::min<std::uint64_t>(pw, INT32_MAX)), h = int(std::min<std::uint64_t>(ph, INT32_MAX));
    } else {
      error = "cannot read image '" + name + "': " + unread_format(bytes, size);
      return false;
    }
  }
  // A BMP stored top row first says so by a negative height (stb reads it so, and says it so here).
  if (size >= 2 && bytes[0] == 'B' && bytes[1] == 'M' && h < 0 && h != std::numeric_limits<int>::min())
    h = -h;
  if (w <= 0 || h <= 0) {
    error = "image '" + name + "' is empty or has a corrupt header";
    return false;
  }
  const std::uint64_t pixels = std::uint64_t(w) * std::uint64_t(h);
  if (pixels > max_pixels) {
    const auto side = static_cast<std::uint64_t>(std::sqrt(double(max_pixels)));
    error =
        "image '" + name + "' is " + std::to_string(w) + "x" + std::to_string(h) +
        " pixels, more than the limit of " + std::to_string(max_pixels) + " pixels" +
        (side * side == max_pixels ? " (" + std::to_string(side) + "x" + std::to_string(side) + ")" : "") +
        ": scale it down (a density needs no more pixels than the dots it places)";
    return false;
  }
  // stb counts its buffer's bytes in an int: said here, not as its "too large" (a PNG's tRNS adds alpha).
  const bool hdr = stbi_is_hdr_from_memory(bytes, length) != 0;
  const int sample_bytes = hdr ? 4 : stbi_is_16_bit_from_memory(bytes, length) ? 2 : 1;
  const int decoded_channels = std::min(4, header_channels + (png_has_chunk(bytes, size, "tRNS") ? 1 : 0));
  const std::uint64_t buffer = pixels * std::uint64_t(decoded_channels) * std::uint64_t(sample_bytes);
  if (buffer > std::uint64_t(std::numeric_limits<int>::max())) {
    error = "image '" + name + "' is " + std::to_string(w) + "x" + std::to_string(h) + " pixels of " +
            std::to_string(decoded_channels) + " channels of " + std::to_string(8 * sample_bytes) +
            " bits: decoding it takes 2 GiB or more; scale it down" +
            (hdr                 ? ""
             : sample_bytes == 2 ? " or convert it to 8 bits"
                                 : "");
    return false;
  }
  int lw = 0, lh = 0, channels = 0;
  const std::pair<int, int> kept_wh = kept_size(w, h, kept);  // not a binding: lambdas capture these
  const int kw = kept_wh.first, kh = kept_wh.second;
  Image image;
  // The decoder must return the header's size, so that the limit holds for what is kept.
  auto decoded = [&](const void* data) {
    if (!data) {
      // stb's reason is its last decoder's, which for a PNG whose pixel data fails may be another format's
      // ("Corrupt JPEG").
      const bool png = size >= 8 && std::memcmp(bytes, "\x89PNG\r\n\x1a\n", 8) == 0;
      error = "cannot read image '" + name +
              "': " + (png ? std::string("corrupt PNG (its compressed pixels do not decode)") : stb_reason());
      return false;
    }
    if (lw != w || lh != h || channels < 1 || channels > 4) {
      error = "cannot read image '" + name + "': its header and its pixels disagree";
      return false;
    }
    if (kw == w && kh == h) image.pixels.resize(pixels * channels_of(image));
    return true;
  };
  const auto convert_kept = [&](const auto* data, float full) {
    if (kw == w && kh == h)
      convert(data, channels, full, image);
    else
      convert_reduced(data, channels, full, w, h, kw, kh, image);
  };
  if (hdr) {
    // Radiance files hold linear values of any range: scaled by `white`, or else by the brightest pixel's
    // luminance, so that a density keeps every ratio the file holds and a colour picture the tones of its
    // grey reading (its brightest channel made a grey 0.5 beside a red of 4 near black); a brighter pixel
    // or channel than `white` is clipped to white.
    std::unique_ptr<float, void (*)(void*)> data(
        stbi_loadf_from_memory(bytes, length, &lw, &lh, &channels, 0), stbi_image_free);
    if (!decoded(data.get())) return false;
    if (!(channels == 3 || channels == 1)) {
      error =
          "cannot read image '" + name + "': a Radiance image of " + std::to_string(channels) + " channels";
      return false;
    }
    double largest = 0;
    for (std::size_t i = 0; i < pixels; ++i) {
      const float* p = data.get() + i * channels;
      const double value = channels == 3 ? 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2] : p[0];
      if (value > largest && std::isfinite(value)) largest = value;
    }
    convert_kept(data.get(), static_cast<float>(white > 0 ? white : largest > 0 ? largest : 1.0));
  } else if (stbi_is_16_bit_from_memory(bytes, length)) {
    std::unique_ptr<stbi_us, void (*)(void*)> data(
        stbi_load_16_from_memory(bytes, length, &lw, &lh, &channels, 0), stbi_image_free);
    if (!decoded(data.get())) return false;
    // stb 2.27 copies 16-bit PGM/PPM samples in host byte order; Netpbm stores them big-endian.
    if (pnm.pnm && pnm.max_value > 255 && pnm.channels == channels)
      for (std::size_t i = 0; i < pixels * channels; ++i)
        data.get()[i] =
            static_cast<stbi_us>(bytes[pnm.pixels_at + 2 * i] << 8 | bytes[pnm.pixels_at + 2 * i + 1]);
    if (pnm.pnm && !samples_within(data.get(), pixels * channels, pnm.max_value, name, error)) return false;
    convert_kept(data.get(), pnm.pnm ? float(pnm.max_value) : 65535.0f);
  } else {
    std::unique_ptr<stbi_uc, void (*)(void*)> data(
        stbi_load_from_memory(bytes, length, &lw, &lh, &channels, 0), stbi_image_free);
    if (!decoded(data.get())) return false;
    if (pnm.pnm && !samples_within(data.get(), pixels * channels, pnm.max_value, name, error)) return false;
    convert_kept(data.get(), pnm.pnm ? float(pnm.max_value) : 255.0f);
  }
  image.width = kw;
  image.height = kh;
  apply_orientation(image, jpeg_orientation(bytes, size));  // as a photo is seen, not as it is stored
  out = std::move(image);
  return true;
}

}  // namespace

namespace {

/// Reads `file` whole into `bytes` (at most 2 GiB, stb's byte count), `name` standing for it in messages.
bool read_whole(std::FILE* file, const std::string& name, std::vector<std::uint8_t>& bytes,
                std::string& error) {
  struct stat info {};  // a directory opens, and then reads as an error or as a huge size
  const bool stated = fstat(fileno(file), &info) == 0;
  if (stated && S_ISDIR(info.st_mode)) {
    error = "cannot read image '" + name + "': it is a directory";
    return false;
  }
  const auto too_large = [&] {
    error = "cannot read image '" + name + "': larger than 2 GiB";
    return false;
  };
  constexpr auto kMaxBytes = static_cast<std::size_t>(std::numeric_limits<int>::max());  // stb's byte count
  bytes.clear();
  if (std::fseek(file, 0, SEEK_END) == 0) {  // a regular file: its size up front
    const long size = std::ftell(file);
    if (size > 0 && static_cast<std::size_t>(size) > kMaxBytes) return too_large();
    if (size > 0) bytes.reserve(static_cast<std::size_t>(size));
    std::rewind(file);
  }
  std::uint8_t chunk[1 << 16];
  for (std::size_t n; (n = std::fread(chunk, 1, sizeof chunk, file)) > 0;) {
    if (bytes.size() + n > kMaxBytes) return too_large();
    bytes.insert(bytes.end(), chunk, chunk + n);
    // A device or a pipe has no size to check up front: /dev/zero would be read to 2 GiB. Its first
    // 64 KiB must begin an image stb_image knows (or a NumPy array of densities, for standard input).
    int w, h, channels;
    if (bytes.size() == n && stated && !S_ISREG(info.st_mode) &&
        !stbi_info_from_memory(bytes.data(), static_cast<int>(bytes.size()), &w, &h, &channels) &&
        !(n >= 6 && std::memcmp(bytes.data(), "\x93NUMPY", 6) == 0)) {
      error = "cannot read image '" + name + "': not a file, and its first bytes are no image header";
      return false;
    }
  }
  if (std::ferror(file)) {
    error = "cannot read image '" + name + "': " + std::strerror(errno);
    return false;
  }
  return true;
}

template <class Image>
bool load_image_file(const std::string& path, Image& out, std::string& error, std::uint64_t max_pixels,
                     const KeptPixels& kept, double white) {
  // Read whole, once: the checks and the decoder see the same bytes, whatever happens to the file.
  std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(path.c_str(), "rb"), std::fclose);
  if (!file) {
    error = "cannot read image '" + path + "': " + std::strerror(errno);
    return false;
  }
  std::vector<std::uint8_t> bytes;
  if (!read_whole(file.get(), path, bytes, error)) return false;
  return load_image(bytes.data(), bytes.size(), path, max_pixels, out, error, kept, white);
}

}  // namespace

bool read_standard_input(std::vector<std::uint8_t>& bytes, std::string& error) {
  return read_whole(stdin, "standard input", bytes, error);
}

bool load_grey_image(const std::string& path, GreyImage& out, std::string& error, std::uint64_t max_pixels,
                     const KeptPixels& kept, double white) {
  return load_image_file(path, out, error, max_pixels, kept, white);
}

bool load_colour_image(const std::string& path, ColourImage& out, std::string& error,
                       std::uint64_t max_pixels, const KeptPixels& kept, double white) {
  return load_image_file(path, out, error, max_pixels, kept, white);
}

bool load_grey_image_memory(const void* data, std::size_t size, GreyImage& out, std::string& error,
                            const std::string& name, std::uint64_t max_pixels, const KeptPixels& kept,
                            double white) {
  return load_image(static_cast<const std::uint8_t*>(data), size, name, max_pixels, out, error, kept, white);
}

bool load_colour_image_memory(const void* data, std::size_t size, ColourImage& out, std::string& error,
                              const std::string& name, std::uint64_t max_pixels, const KeptPixels& kept,
                              double white) {
  return load_image(static_cast<const std::uint8_t*>(data), size, name, max_pixels, out, error, kept, white);
}

bool is_radiance(const void* data, std::size_t size) {
  const std::string_view start(static_cast<const char*>(data), size);
  return start.rfind("#?RADIANCE\n", 0) == 0 || start.rfind("#?RGBE\n", 0) == 0;
}

bool write_png(const std::string& path, const RgbImage& image, std::string& error) {
  if (image.width <= 0 || image.height <= 0) {
    error = "cannot write an empty image to '" + path + "'";
    return false;
  }
  // Encoded in memory, then written with checked writes: stbi_write_png ignores fwrite and fclose errors
  // (a full disk or a file size limit would leave a truncated PNG reported as written).
  std::string png;
  const auto append = [](void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data),
                                               static_cast<std::size_t>(size));
  };
  if (!stbi_write_png_to_func(append, &png, image.width, image.height, 3, image.pixels.data(),
                              image.width * 3)) {
    error = "cannot write '" + path + "': PNG encoding failed";
    return false;
  }
  return write_text_file_atomic(path, png, error);
}

namespace {

/// Calls f(pixel index, coverage) for each pixel of a w × h picture that the disc of radius r at (cx, cy)
/// covers. Coverage by distance to the edge, a one-pixel ramp, so that a disc's coverages sum to its area
/// π r² (a picture keeps its tone): the ramp adds π/12 of a pixel, taken off the radius; below 4 pixels,
/// where pixels round a disc most, its partly covered pixels are scaled to the area, and it keeps a
/// footprint of at least one pixel wherever it lies (an edge radius of 0.75 reaches a pixel centre from
/// any point).
template <class F>
void for_each_disc_pixel(int w, int h, double cx, double cy, double r, F&& f) {
  if (!(r > 0)) return;
  const double edge = std::max(std::sqrt(std::max(0.0, r * r - 1.0 / 12)), 0.25) + 0.5;
  // Clamped in double first: a far or huge disc's bounds do not fit an int.
  auto pixel = [](double v, int last) { return static_cast<int>(std::clamp(v, -1.0, double(last) + 1)); };
  const int x0 = std::max(0, pixel(std::floor(cx - edge), w)),
            x1 = std::min(w - 1, pixel(std::ceil(cx + edge), w));
  const int y0 = std::max(0, pixel(std::floor(cy - edge), h)),
            y1 = std::min(h - 1, pixel(std::ceil(cy + edge), h));
  if (x0 > x1 || y0 > y1) return;  // wholly off the picture (and its footprint's bounds may not fit an int)
  auto coverage_at = [&](int x, int y) {
    return std::clamp(edge - std::hypot(x + 0.5 - cx, y + 0.5 - cy), 0.0, 1.0);
  };
  // Below 4 pixels the partly covered pixels take what the full ones leave of the area.
  double full = 0, partial = 0, gain = 1;
  if (r < 4) {  // the whole footprint, pixels past the picture's sides included
    for (int y = int(std::floor(cy - edge)); y <= int(std::ceil(cy + edge)); ++y)
      for (int x = int(std::floor(cx - edge)); x <= int(std::ceil(cx + edge)); ++x) {
        const double c = coverage_at(x, y);
        (c >= 1 ? full : partial) += c;
      }
    if (partial > 0) gain = std::max(0.0, 3.141592653589793 * r * r - full) / partial;
  }
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const double c = coverage_at(x, y);
      if (const double coverage = c >= 1 ? 1.0 : std::min(1.0, c * gain); coverage > 0)
        f(static_cast<std::size_t>(y) * w + x, coverage);
    }
}

/// `under` with `ink` laid over it at `coverage` (`mode` as draw_disc's: 0 over, 1 multiply, 2 add).
std::uint8_t blend(std::uint8_t under, std::uint8_t ink, double coverage, int mode) {
  const double u = under;
  const double top = mode == 1 ? u * ink / 255.0 : mode == 2 ? std::min(255.0, u + ink) : double(ink);
  return static_cast<std::uint8_t>(std::lround(u + (top - u) * coverage));
}

}  // namespace

void draw_disc(RgbImage& image, double cx, double cy, double r, const std::uint8_t rgb[3], int mode) {
  for_each_disc_pixel(image.width, image.height, cx, cy, r, [&](std::size_t i, double coverage) {
    for (int c = 0; c < 3; ++c)
      image.pixels[3 * i + c] = blend(image.pixels[3 * i + c], rgb[c], coverage, mode);
  });
}

void add_disc(CoverageImage& layer, double cx, double cy, double r) {
  for_each_disc_pixel(layer.width, layer.height, cx, cy, r, [&](std::size_t i, double coverage) {
    const long sum = layer.values[i] + std::lround(coverage * 65535);
    layer.values[i] = static_cast<std::uint16_t>(std::min(sum, 65535L));
  });
}

void composite(RgbImage& image, const CoverageImage& layer, const std::uint8_t rgb[3], int mode) {
  for (std::size_t i = 0; i < layer.values.size(); ++i)
    if (layer.values[i])
      for (int c = 0; c < 3; ++c)
        image.pixels[3 * i + c] = blend(image.pixels[3 * i + c], rgb[c], layer.values[i] / 65535.0, mode);
}

bool write_text_file_atomic(const std::string& given_path, const std::string& text, std::string& error) {
  if (given_path == "-") {  // standard output (point_io.h's kStandardOutput): a pipe's reader sees it all
    const bool written = std::fwrite(text.data(), 1, text.size(), stdout) == text.size();
    if (written && std::fflush(stdout) == 0) return true;
    error = std::string("cannot write to standard output: ") + std::strerror(errno);
    return false;
  }
  // A device or a pipe (/dev/null, /dev/stdout, a FIFO) is written into, as a shell's > does: a rename
  // would replace it with a regular file.
  struct stat info;
  const bool special =
      stat(given_path.c_str(), &info) == 0 && !S_ISREG(info.st_mode) && !S_ISDIR(info.st_mode);
  // A symbolic link is written through, as cp and a shell's > do: the rename replaces its target.
  std::string path = given_path;
  std::error_code ec;
  if (!special && std::filesystem::is_symlink(std::filesystem::symlink_status(path, ec))) {
    const std::filesystem::path target = std::filesystem::weakly_canonical(path, ec);
    if (!ec) path = target.string();
  }
  const std::string tmp = special ? path : temp_path_for(path);
  if (!special) mark(&tmp);
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) {
    mark(nullptr);
    error = "cannot write '" + path + "': " + std::strerror(errno);
    return false;
  }
  // fclose too can fail (delayed write errors); either failure leaves no file behind.
  const bool written = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  const int write_errno = errno;
  if (std::fclose(f) != 0 || !written) {
    error = "cannot write '" + path + "': " + std::strerror(written ? errno : write_errno);
    if (!special) std::remove(tmp.c_str());
    mark(nullptr);
    return false;
  }
  const bool done = special || commit_temp(tmp, path, error);
  mark(nullptr);
  return done;
}

void remove_temporary_files_on_signals() {
  signals_handled.store(true);
  for (int signal : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction current = {};
    // A signal the process was started ignoring (nohup, a script's background job) stays ignored.
    if (sigaction(signal, nullptr, &current) != 0 || current.sa_handler == SIG_IGN) continue;
    struct sigaction handler = {};
    handler.sa_handler = remove_marked_and_reraise;
    sigemptyset(&handler.sa_mask);
    sigaction(signal, &handler, nullptr);
  }
}

void detail::mark_temporary_file(const char* path) {
  const std::string text = path ? path : "";
  mark(path ? &text : nullptr);
}

}  // namespace kdm::tools
