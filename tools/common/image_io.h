// Image input and output for the command line: greyscale loading (8/16-bit PNG and whatever else
// stb_image reads) and PNG writing. Not thread-safe to call concurrently on the same path.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace kdm::tools {

/// A greyscale image with values in [0, 1], row-major, row 0 at the top.
struct GreyImage {
  int width = 0;
  int height = 0;
  std::vector<float> pixels;
  float at(int x, int y) const { return pixels[static_cast<std::size_t>(y) * width + x]; }
};

/// An 8-bit RGB image, row-major, row 0 at the top.
struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;  // 3 bytes per pixel
  RgbImage() = default;
  RgbImage(int w, int h, std::uint8_t fill = 255)
      : width(w), height(h), pixels(static_cast<std::size_t>(w) * h * 3, fill) {}
};

/// Loads an image as luminance in [0, 1] (16-bit PNGs keep their precision; alpha is composited on white).
/// Returns false and sets `error` to a one-line message naming the file and the problem.
bool load_grey_image(const std::string& path, GreyImage& out, std::string& error);

/// Writes `image` as PNG atomically (temporary file, then rename). Returns false with `error` set on failure.
bool write_png(const std::string& path, const RgbImage& image, std::string& error);

/// Draws an antialiased filled disc of radius `r` pixels centred at (cx, cy) (pixel units, y down).
void draw_disc(RgbImage& image, double cx, double cy, double r, const std::uint8_t rgb[3]);

/// Writes `text` to `path` atomically (temporary file, then rename).
bool write_text_file_atomic(const std::string& path, const std::string& text, std::string& error);

}  // namespace kdm::tools
