// Image input for the command line and the Python package: greyscale and colour loading (8/16-bit PNG,
// Radiance .hdr and whatever else stb_image reads), safe on untrusted bytes. Pictures are written by
// picture.h.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace kdm::tools {

/// A greyscale image with values in [0, 1], row-major, row 0 at the top.
struct GreyImage {
  int width = 0;
  int height = 0;
  std::vector<float> pixels;  ///< composited on white paper
  std::vector<float> alpha;   ///< coverage in [0, 1] per pixel; empty for a file without alpha
  float at(int x, int y) const { return pixels[static_cast<std::size_t>(y) * width + x]; }
};

/// A colour image: red, green and blue in [0, 1] per pixel (3 floats), row-major, row 0 at the top.
struct ColourImage {
  int width = 0;
  int height = 0;
  std::vector<float> pixels;  ///< composited on white paper
  std::vector<float> alpha;   ///< coverage in [0, 1] per pixel; empty for a file without alpha
};

/// The largest image the loaders accept, in pixels (width · height): 2^26, e.g. 8192 × 8192. Images are
/// untrusted input and a header of a few bytes can claim any size: this is checked on the header alone,
/// before any pixel is allocated. At the limit, decoding takes up to 8 bytes per pixel (16-bit RGBA,
/// 512 MiB) and the luminance 4 more (256 MiB), besides the file's bytes. Larger images are refused with
/// an error naming the file, its size and this limit.
inline constexpr std::uint64_t kMaxImagePixels = std::uint64_t(1) << 26;

/// How many pixels a loader keeps of an image stored as `width` × `height` pixels. Fewer than width ·
/// height make it average the picture down as it converts it (area-weighted boxes, to about that many
/// pixels in the same shape, every side at least 1), so that no full-size copy of floats is made; the
/// tone of every region larger than a kept pixel stays. Empty, or a count not below width · height:
/// every pixel, bit for bit as without it.
using KeptPixels = std::function<std::uint64_t(int width, int height)>;

/// Loads an image as luminance in [0, 1] (16-bit PNGs keep their precision; a Radiance .hdr image its
/// range, as linear values divided by `white` (brighter ones clipped to 1), or when `white` is 0 by its
/// brightest pixel's; alpha is composited on white and kept; a JPEG is turned as its EXIF orientation
/// says, as viewers show it).
/// The file is read whole (at most 2 GiB); images of more than `max_pixels` pixels are refused from their
/// header (see kMaxImagePixels), and so are inputs that would reach a known fault of the system's stb_image
/// (tests/fuzz/crashes/README.md).
/// Returns false and sets `error` to a one-line message naming the file and the problem.
/// `kept`, if given, averages a large picture down while it is converted (KeptPixels).
bool load_grey_image(const std::string& path, GreyImage& out, std::string& error,
                     std::uint64_t max_pixels = kMaxImagePixels, const KeptPixels& kept = {},
                     double white = 0);

/// The same as red, green and blue (alpha composited on white; a grey image gives three equal channels; a
/// Radiance image's channels divided by `white`, or when it is 0 by its brightest pixel's luminance, and
/// clipped to 1).
bool load_colour_image(const std::string& path, ColourImage& out, std::string& error,
                       std::uint64_t max_pixels = kMaxImagePixels, const KeptPixels& kept = {},
                       double white = 0);
/// The same as load_grey_image for an image file's bytes in memory; `name` stands for the file in error
/// messages.
bool load_grey_image_memory(const void* data, std::size_t size, GreyImage& out, std::string& error,
                            const std::string& name = "image in memory",
                            std::uint64_t max_pixels = kMaxImagePixels, const KeptPixels& kept = {},
                            double white = 0);

/// The same as load_colour_image for an image file's bytes in memory.
bool load_colour_image_memory(const void* data, std::size_t size, ColourImage& out, std::string& error,
                              const std::string& name = "image in memory",
                              std::uint64_t max_pixels = kMaxImagePixels, const KeptPixels& kept = {},
                              double white = 0);

/// Reads all of standard input into `bytes`, as the loaders read a file (at most 2 GiB; a pipe whose first
/// 64 KiB begin no image header, nor a NumPy array's, is refused there, not read to its end). Returns false
/// with `error` set ("standard input" named as the image) when it cannot.
bool read_standard_input(std::vector<std::uint8_t>& bytes, std::string& error);

/// Whether `data` begins as a Radiance (.hdr) image does ("#?RADIANCE" or "#?RGBE" and a line break).
bool is_radiance(const void* data, std::size_t size);

}  // namespace kdm::tools
