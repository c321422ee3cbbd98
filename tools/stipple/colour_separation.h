// Colour stippling: an image separated into inks, each ink's coverage the density of one class of dots
// (kdm/runtime/class_query.h), so that the dots of all inks together are one blue-noise set and each ink's
// dots follow its channel.
#pragma once

#include <string>
#include <vector>

#include "density_spec.h"
#include "image_io.h"
#include "point_output.h"

namespace kdm::tools {

/// An image separated into inks: per ink, its density (a DensitySpec of kind kImage, row 0 at the bottom)
/// and its colour in pictures; `background` is the paper.
struct ColourSeparation {
  std::vector<DensitySpec> channels;
  std::vector<Ink> inks;
  /// The scheme's inks that no pixel uses: no class of dots, but a picture still lists them (an empty SVG
  /// group each), so that a plotter's pen layers are the same whatever the image.
  std::vector<Ink> unused;
  std::uint8_t background[3] = {255, 255, 255};
  Blend blend = Blend::kMultiply;  ///< inks on paper multiply; light on black adds

  /// Every ink of the scheme, for a picture's layers: the used ones in class order, then the unused.
  std::vector<Ink> layers() const {
    std::vector<Ink> all = inks;
    all.insert(all.end(), unused.begin(), unused.end());
    return all;
  }
};

/// Separates `image` by `scheme`:
/// - "cmyk": cyan, magenta, yellow and black on white paper, black by full under-colour removal
///   (K = 1 − max(R, G, B), C = (1 − R − K) / (1 − K), …);
/// - "rgb": red, green and blue dots on black paper, each channel's intensity its density;
/// - "N" (2 … 8): up to N inks on white paper chosen for the image: among its own colours at full
///   strength (strongest channel 0; a near-grey one black), greedily and then by swaps, the inks whose
///   splits (below) draw the image's colours with the least squared error; fewer where another would not
///   lower it by 5% and by 0.2% of the blank paper's, none under 1% of the coverage (one black ink for a
///   grey image);
/// - "#rrggbb,#rrggbb,…" (1 … 8): the user's own inks (pens) as given.
/// With N inks or a list, each pixel's colour is split over the inks: the coverages c_i ≥ 0, Σ c_i ≤ 1 (dots
/// side by side) whose Σ c_i (1 − ink_i) is nearest its absorbance 1 − rgb (least squares with a small
/// ridge, so the split changes smoothly with the colour and a gradient is drawn by dots of several inks;
/// traces under 1% dropped), near-greys as greys. Such inks are named by their class number and colour,
/// "ink-0-red", after the ordering below, the unused after the used; N inks' layers come in that order,
/// pens' in the order given.
/// Each density is the coverage raised to `gamma` (> 0). The inks come in order of increasing mean coverage
/// (a later class's tone carries the earlier classes' count errors, the more the smaller its share), except
/// that inks under a tenth of the total coverage come last, most covering first (a sparse class early in
/// the order shows the tile edges). An image with no ink in any colour gives no channels (every ink
/// unused). Throws std::invalid_argument naming the problem for another scheme.
ColourSeparation separate_colours(const ColourImage& image, const std::string& scheme, double gamma);

/// A stipple's first header line, as kdm stipple and kdm.stipple write it: "kdm stipple: N dots (HOW)",
/// HOW how they were placed; with a colour `scheme` (--colours as given; empty: one ink) ", inks SCHEME"
/// after HOW, cmyk and rgb as named, a count or pens as "K of N" (the K inks the image uses of the N asked
/// for or given).
std::string stipple_summary(std::size_t dots, const std::string& how, const std::string& scheme,
                            const ColourSeparation& inks);

}  // namespace kdm::tools
