// Rendering of the analysis pictures (points, periodogram, RAPS) into RGB images; text via stb_easy_font,
// whose quads are filled as axis-aligned rectangles.
#include "kdm/analysis/plots.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "kdm/analysis/common.h"

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#endif
#include <stb_easy_font.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace kdm::analysis {
namespace {

void fill_rect(tools::RgbImage& im, int x0, int y0, int x1, int y1, const std::uint8_t rgb[3]) {
  x0 = std::max(0, x0), y0 = std::max(0, y0), x1 = std::min(im.width, x1), y1 = std::min(im.height, y1);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      std::uint8_t* p = &im.pixels[(static_cast<std::size_t>(y) * im.width + x) * 3];
      p[0] = rgb[0], p[1] = rgb[1], p[2] = rgb[2];
    }
}

// A line of discs (antialiased by draw_disc) from (x0,y0) to (x1,y1).
void draw_line(tools::RgbImage& im, double x0, double y0, double x1, double y1, double r,
               const std::uint8_t rgb[3]) {
  const double len = std::hypot(x1 - x0, y1 - y0);
  const int steps = std::max(1, static_cast<int>(std::ceil(len / (0.5 * r + 0.25))));
  for (int s = 0; s <= steps; ++s) {
    const double t = static_cast<double>(s) / steps;
    tools::draw_disc(im, x0 + t * (x1 - x0), y0 + t * (y1 - y0), r, rgb);
  }
}

int text_width(const char* text, int scale) {
  return stb_easy_font_width(const_cast<char*>(text)) * scale;
}

}  // namespace

void draw_text(tools::RgbImage& image, int x, int y, const char* text, int scale, const std::uint8_t rgb[3]) {
  std::vector<char> buffer(64 * 1024);
  std::string copy(text);
  const int quads =
      stb_easy_font_print(0, 0, copy.data(), nullptr, buffer.data(), static_cast<int>(buffer.size()));
  for (int q = 0; q < quads; ++q) {
    const float* v = reinterpret_cast<const float*>(buffer.data() + q * 64);  // 4 vertices × 16 bytes
    const float qx0 = v[0], qy0 = v[1], qx1 = v[8], qy1 = v[9];               // vertices 0 and 2: corners
    fill_rect(image, x + static_cast<int>(std::lround(std::min(qx0, qx1) * scale)),
              y + static_cast<int>(std::lround(std::min(qy0, qy1) * scale)),
              x + static_cast<int>(std::lround(std::max(qx0, qx1) * scale)),
              y + static_cast<int>(std::lround(std::max(qy0, qy1) * scale)), rgb);
  }
}

tools::RgbImage plot_points(const tools::PointSet& set, int size_px, const Sides& sides) {
  const bool square = sides[0] == sides[1];
  const double longer = std::max(sides[0], sides[1]);
  const int w = square ? size_px : std::max(1, static_cast<int>(std::lround(size_px * sides[0] / longer)));
  const int h = square ? size_px : std::max(1, static_cast<int>(std::lround(size_px * sides[1] / longer)));
  tools::RgbImage im(w, h, 255);
  const std::uint8_t black[3] = {0, 0, 0};
  const std::size_t n = set.size();
  // Dots scale with the spacing: size_px over the unit square's side, the longer side's pixels over its.
  const double unit_px = square ? size_px : size_px / longer;
  const double r = std::max(0.6, 0.22 * unit_px / std::sqrt(std::max<std::size_t>(1, n)));
  for (std::size_t i = 0; i < n; ++i)
    tools::draw_disc(im, set.coords[i * set.dim] * w, (1.0 - set.coords[i * set.dim + 1]) * h, r, black);
  return im;
}

tools::RgbImage plot_spectrum(const Periodogram& p, int min_size_px) {
  // A rectangle's grid is as wide as its lattice: one square pixel block per frequency.
  const int side = std::max(p.width(), p.height());
  const int s = std::max(1, (min_size_px + side - 1) / side);
  tools::RgbImage im(p.width() * s, p.height() * s, 0);
  for (int ky = -p.ky_max; ky <= p.ky_max; ++ky)
    for (int kx = -p.kx_max; kx <= p.kx_max; ++kx) {
      const double v = std::log10(std::max(1e-12, p.at(kx, ky)));
      const double t = std::clamp((v + 1.5) / 2.5, 0.0, 1.0);
      const std::uint8_t g = static_cast<std::uint8_t>(std::lround(255 * t));
      const std::uint8_t rgb[3] = {g, g, g};
      const int px = (kx + p.kx_max) * s, py = (p.ky_max - ky) * s;
      fill_rect(im, px, py, px + s, py + s, rgb);
    }
  return im;
}

tools::RgbImage plot_raps(const SpectrumStats& st, double fmax, int width_px, int height_px) {
  tools::RgbImage im(width_px, height_px, 255);
  const std::uint8_t black[3] = {0, 0, 0}, grey[3] = {150, 150, 150}, blue[3] = {20, 60, 200};
  const int left = 80, right = 20, top = 56, bottom = 70;
  const int pw = width_px - left - right, ph = height_px - top - bottom;
  double ymax = 2.0;
  for (double v : st.raps) ymax = std::max(ymax, v * 1.1);
  ymax = std::ceil(ymax);
  auto X = [&](double f) { return left + f / fmax * pw; };
  auto Y = [&](double v) { return top + (1.0 - v / ymax) * ph; };
  // Axes, ticks and tick labels.
  fill_rect(im, left, top, left + 2, top + ph, black);
  fill_rect(im, left, top + ph - 1, left + pw, top + ph + 1, black);
  char buf[64];
  const double fstep = fmax > 2 ? 0.5 : (fmax > 1 ? 0.25 : 0.1);
  for (double f = 0; f <= fmax + 1e-9; f += fstep) {
    const int x = static_cast<int>(std::lround(X(f)));
    fill_rect(im, x, top + ph, x + 1, top + ph + 6, black);
    std::snprintf(buf, sizeof buf, "%g", f);
    draw_text(im, x - text_width(buf, 2) / 2, top + ph + 10, buf, 2, black);
  }
  // At most 8 steps of 1, 2 or 5 × 10^k on any range: a fixed step of 2 drew the labels of a peak of 100
  // (a lattice, clumps) on top of each other.
  double ystep = 0.5;
  for (double decade = 1; std::isfinite(ymax) && ymax / ystep > 8; decade *= 10)
    for (double m : {1.0, 2.0, 5.0})
      if (ymax / ystep > 8) ystep = m * decade;
  for (double v = 0; v <= ymax + 1e-9; v += ystep) {
    const int y = static_cast<int>(std::lround(Y(v)));
    fill_rect(im, left - 6, y, left, y + 1, black);
    std::snprintf(buf, sizeof buf, "%g", v);
    draw_text(im, left - 10 - text_width(buf, 2), y - 7, buf, 2, black);
  }
  const char* xlabel = "frequency f = |k| / sqrt(n)";
  draw_text(im, left + pw / 2 - text_width(xlabel, 2) / 2, height_px - 28, xlabel, 2, black);
  draw_text(im, 8, 6, "radially averaged power spectrum; dashed: white noise = 1", 2, black);
  draw_text(im, left - 30, top - 26, "RAPS", 2, black);
  // Dashed white-noise level.
  const double y1 = Y(1.0);
  for (int x = left; x < left + pw; x += 14)
    fill_rect(im, x, static_cast<int>(y1), std::min(x + 8, left + pw), static_cast<int>(y1) + 2, grey);
  // The curve.
  for (std::size_t i = 1; i < st.raps.size(); ++i)
    draw_line(im, X(st.ring_f[i - 1]), Y(std::min(st.raps[i - 1], ymax)), X(st.ring_f[i]),
              Y(std::min(st.raps[i], ymax)), 1.2, blue);
  return im;
}

}  // namespace kdm::analysis
