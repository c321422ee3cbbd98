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
/// - "N" (2 … 8): up to N inks on white paper, the image's hues clustered (spherical k-means of the
///   pixels' absorbances 1 − rgb, deterministic; fewer inks where the image holds fewer hues, one for a
///   grey image), each ink its hue at full strength (its strongest channel 0), each pixel drawn by the ink
///   of the nearest hue with the coverage that gives its absorbance (least squares, at most 1).
/// Each density is the coverage raised to `gamma` (> 0). The inks come in order of increasing mean coverage
/// (a later class's tone carries the earlier classes' count errors, the more the smaller its share), except
/// that inks under a tenth of the total coverage come last, most covering first (a sparse class early in
/// the order shows the tile edges). An image with no ink in any colour gives no channels (every ink
/// unused). Throws std::invalid_argument naming the problem for another scheme.
ColourSeparation separate_colours(const ColourImage& image, const std::string& scheme, double gamma);

}  // namespace kdm::tools
