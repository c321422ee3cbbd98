// Diagnostic pictures of an analysis: the point set as dots, the set-averaged periodogram on a log scale
// (centred, ky up), and the RAPS curve with labelled axes and the white-noise level 1 dashed.
// Text is drawn with stb_easy_font (public-domain bitmap-segment font from libstb).
#pragma once

#include "kdm/analysis/common.h"
#include "kdm/analysis/periodogram.h"
#include "picture.h"
#include "point_io.h"

namespace kdm::analysis {

/// Dots of `set` (x right, y up; 3D sets show x, y) on a white `size_px` square, or a rectangle of the
/// domain's shape `sides` (common.h) whose longer side is `size_px`. Thread-safe.
tools::RgbImage plot_points(const tools::PointSet& set, int size_px = 1024, const Sides& sides = kUnitSides);

/// log10 P(k) mapped from [−1.5, 1] to black…white, k = 0 at the centre, ky up, each k an s×s block with
/// s chosen so the picture is about `min_size_px` wide (a rectangle's grid: its longer side). Thread-safe.
tools::RgbImage plot_spectrum(const Periodogram& p, int min_size_px = 640);

/// RAPS against f with axes, ticks, labels and a dashed line at 1. Thread-safe.
tools::RgbImage plot_raps(const SpectrumStats& stats, double fmax, int width_px = 800, int height_px = 500);

/// Draws `text` (ASCII) with its top-left corner at (x, y), `scale` pixels per font unit. Thread-safe.
void draw_text(tools::RgbImage& image, int x, int y, const char* text, int scale, const std::uint8_t rgb[3]);

}  // namespace kdm::analysis
