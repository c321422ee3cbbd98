// Pictures drawn by kdm (stipples, plots): antialiased discs that keep a stipple's tone, and PNG writing.
#include "picture.h"

#include <algorithm>
#include <cmath>
#include <string>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>

#include "atomic_file.h"

namespace kdm::tools {

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

}  // namespace kdm::tools
