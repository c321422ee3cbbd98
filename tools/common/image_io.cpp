#include "image_io.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include <sys/stat.h>

#define STB_IMAGE_IMPLEMENTATION
#define STBI_FAILURE_USERMSG
// Zeroed memory: stb 2.27 reads some of its allocations before writing them, e.g. the Huffman tables of a
// JPEG scan that no DHT segment defined (whose garbage offsets then index out of bounds).
#define STBI_MALLOC(size) std::calloc(1, size)
#define STBI_REALLOC(p, size) std::realloc(p, size)
#define STBI_FREE(p) std::free(p)
#include <stb_image.h>

#include "image_faults.h"

namespace kdm::tools {
namespace {

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

// How a colour sample becomes a value in [0, 1]: divided by its full scale, or, for a PNG whose gAMA chunk
// says it is encoded otherwise than sRGB, through `curve` (one entry per integer sample) to the value an
// sRGB display shows for it.
struct SampleScale {
  float full = 1;
  const std::vector<float>* curve = nullptr;
  /// Sample `c` of a pixel of `channels` (the last of 2 or 4 is alpha, which is linear).
  template <class Sample>
  float value(Sample sample, int c, int channels) const {
    if constexpr (std::is_integral_v<Sample>)
      if (curve && !(c == channels - 1 && (channels == 2 || channels == 4)))
        return (*curve)[std::size_t(sample)];
    return static_cast<float>(sample) / full;
  }
};

// A PNG's gAMA chunk as a curve from its samples (0 … full) to sRGB-encoded values, or an empty one where
// it has none, or sRGB or an ICC profile (which take precedence), or where it says sRGB's exponent: a
// sample s shows light (s / full)^(1 / g), g = gAMA / 100000, which a 2.2 display encodes as its 1 / 2.2th
// power. A linear file (gAMA 100000) saved by compositing software is then as dark as a viewer shows it.
std::vector<float> png_gamma_curve(const std::uint8_t* bytes, std::size_t size, float full) {
  std::size_t at = 0, length = 0;
  if (!png_chunk(bytes, size, "gAMA", at, length) || length != 4 || png_has_chunk(bytes, size, "sRGB") ||
      png_has_chunk(bytes, size, "iCCP"))
    return {};
  const std::uint32_t gama = std::uint32_t(bytes[at]) << 24 | std::uint32_t(bytes[at + 1]) << 16 |
                             std::uint32_t(bytes[at + 2]) << 8 | bytes[at + 3];
  const double exponent = 100000.0 / (2.2 * gama);
  if (gama == 0 || std::abs(exponent - 1) < 0.01) return {};  // none, or sRGB's 45455
  std::vector<float> curve(std::size_t(full) + 1);
  for (std::size_t s = 0; s < curve.size(); ++s) curve[s] = float(std::pow(double(s) / full, exponent));
  return curve;
}

// Luminance of `channels`-channel samples of full scale `full`, composited on white paper. The samples are
// converted to float and divided first, as kdm always did, so that outputs stay bit for bit the same.
template <class Sample>
void to_luminance(const Sample* data, int channels, const SampleScale& scale, std::vector<float>& pixels) {
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    float p[4] = {0, 0, 0, 1};
    for (int c = 0; c < channels; ++c) p[c] = scale.value(data[i * channels + c], c, channels);
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
void to_rgb(const Sample* data, int channels, const SampleScale& scale, std::vector<float>& pixels) {
  for (std::size_t i = 0; i < pixels.size() / 3; ++i) {
    float p[4] = {0, 0, 0, 1};
    for (int c = 0; c < channels; ++c) p[c] = scale.value(data[i * channels + c], c, channels);
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
void convert(const Sample* data, int channels, const SampleScale& scale, Image& image) {
  if constexpr (std::is_same_v<Image, GreyImage>)
    to_luminance(data, channels, scale, image.pixels);
  else
    to_rgb(data, channels, scale, image.pixels);
  image.alpha.resize(image.pixels.size() / channels_of(image));
  to_alpha(data, channels, scale.full, image.alpha);
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
void convert_reduced(const Sample* data, int channels, const SampleScale& scale, int w, int h, int kw, int kh,
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
    convert(data + std::size_t(y) * w * channels, channels, scale, row);
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
  std::vector<float> curve;  // a PNG's gAMA, for its colour samples
  const auto convert_kept = [&](const auto* data, float full) {
    if (!hdr) curve = png_gamma_curve(bytes, size, full);
    const SampleScale scale{full, curve.empty() ? nullptr : &curve};
    if (kw == w && kh == h)
      convert(data, channels, scale, image);
    else
      convert_reduced(data, channels, scale, w, h, kw, kh, image);
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

}  // namespace kdm::tools
