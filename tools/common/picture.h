// Pictures kdm draws (stipples, plots): an 8-bit RGB image, antialiased discs and PNG writing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace kdm::tools {

/// An 8-bit RGB image, row-major, row 0 at the top.
struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;  // 3 bytes per pixel
  RgbImage() = default;
  RgbImage(int w, int h, std::uint8_t fill = 255)
      : width(w), height(h), pixels(static_cast<std::size_t>(w) * h * 3, fill) {}
};

/// Writes `image` as PNG atomically (temporary file, then rename). Returns false with `error` set on failure.
bool write_png(const std::string& path, const RgbImage& image, std::string& error);

/// Draws an antialiased filled disc of radius `r` pixels centred at (cx, cy) (pixel units, y down): painted
/// over what is there, or with `mode` 1 multiplied into it (inks on paper), 2 added to it (light). Its
/// pixels' coverages sum to its area π r², a disc under a pixel's size included (it is then a grey pixel
/// or a few).
void draw_disc(RgbImage& image, double cx, double cy, double r, const std::uint8_t rgb[3], int mode = 0);

/// How much of each pixel one ink's dots cover, 0 … 65535 for 0 … 1. Dots add their coverage (saturating):
/// dots side by side fill the pixel they share, and dots under a pixel's size darken it by their area, so
/// that a stipple keeps its tone at any picture size (dots laid over each other would lighten both).
struct CoverageImage {
  int width = 0, height = 0;
  std::vector<std::uint16_t> values;
  CoverageImage(int w, int h) : width(w), height(h), values(static_cast<std::size_t>(w) * h, 0) {}
};

/// Adds a disc as draw_disc draws it (same coverage) to `layer`.
void add_disc(CoverageImage& layer, double cx, double cy, double r);

/// Lays `rgb` over `image` where `layer` covers it, by its coverage (`mode` as draw_disc's).
void composite(RgbImage& image, const CoverageImage& layer, const std::uint8_t rgb[3], int mode = 0);

}  // namespace kdm::tools
