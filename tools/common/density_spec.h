// A density as a user names it ("const:V", the test maps "ramp:R" and "radial:R", an image whose
// darkness is the density, or a 3-D NumPy array of densities for 3D samples), parsed once into a neutral
// description: the full sampler's commands convert it for the generator, the runtime's commands for a query,
// and neither needs the other's headers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "image_io.h"

namespace kdm::tools {

struct DensitySpec {
  enum class Kind { kConstant, kRamp, kRadial, kImage, kVolume };
  Kind kind = Kind::kConstant;
  double constant = 1;        ///< kConstant: the value (>= 0)
  double range = 1;           ///< kRamp, kRadial: the dynamic range R (in [1, 1e9])
  int width = 0, height = 0;  ///< kImage, kVolume: its size in pixels (voxels)
  int depth = 0;              ///< kVolume: its slices along z
  /// kImage: density per pixel (finite, >= 0), row 0 at the bottom. kVolume: per voxel, as
  /// gen::DensityVolume lays them out (x fastest, row 0 at the bottom, slice 0 at z near 0).
  std::vector<float> values;
  bool inverted = false;  ///< kImage: luminance is the density (else darkness)
  bool array = false;     ///< kImage, kVolume: read from a NumPy .npy array of densities (not a picture)
  /// An array's divisor: values whose largest lies outside 1e-30 … 1e30 are kept divided by it (only
  /// their shape matters to the sampler); a query, which counts their size, multiplies it back.
  double divided_by = 1;
  std::string text;  ///< what it was parsed from (for messages)

  /// Whether the density is a function of position (the test maps), not a constant, image or volume.
  bool analytic() const { return kind == Kind::kRamp || kind == Kind::kRadial; }
  /// The test maps at unit position (u, v) in [0, 1]²: ramp R^-u (1 at the left edge, 1/R at the right),
  /// radial R^-(r/0.5) with r the distance from the centre, 1/R beyond r = 0.5 (continuous across a
  /// torus's edges). 1 for other kinds. A 3D sample reads them at (x, y): a ramp along x, a cylinder.
  double map_at(double u, double v) const;
  /// The largest value anywhere (1 for the test maps), and the mean over the unit square.
  double max_value() const;
  double mean_value() const;
};

/// A density that does not parse: a malformed or out-of-range value (std::invalid_argument), or an image
/// that cannot be read (std::runtime_error, naming the file). Messages are one line.
/// `text` is "const:V" (V finite, >= 0), "ramp:R" or "radial:R" (R in [1, 1e9]), or a path to an image:
/// darkness (1 − luminance) raised to `gamma` (finite, > 0) is the density; `invert` uses luminance (on
/// black paper: picture_tone). A NumPy .npy file (known by its first bytes) holds real densities of either
/// byte order (float16, 32 or 64, integers of 8 to 64 bits as their values, bool as 0 and 1; finite, >= 0,
/// at any scale: when the largest is outside 1e-30 ... 1e30 all are divided by it, as kdm.sample does),
/// in C or Fortran order, at most kMaxImagePixels values: a 2-D array (rows, columns) is a kImage, row 0 at
/// the top (y near 1), as 2-D density arrays in Python; a 3-D one (depth, height, width) a kVolume, array[k]
/// slice k along z (k = 0 at z near 0), each slice as a 2-D array. Other shapes and types are refused,
/// naming the file. An image of more than `max_pixels` pixels is refused; `kept`, if given, averages a larger
/// picture down as it is read (KeptPixels; the average is of luminance, before `gamma`). `white` > 0 is the
/// luminance of a Radiance .hdr picture that is white (load_grey_image; 0: its brightest pixel's).
DensitySpec parse_density_spec(const std::string& text, double gamma = 1, bool invert = false,
                               std::uint64_t max_pixels = kMaxImagePixels, const KeptPixels& kept = {},
                               double white = 0);

/// parse_density_spec of an image or .npy file's bytes in memory (standard input read whole, say), told apart
/// by their first bytes as a file's are; `name` stands for the file in messages.
DensitySpec parse_density_bytes(const void* data, std::size_t size, const std::string& name, double gamma = 1,
                                bool invert = false, std::uint64_t max_pixels = kMaxImagePixels,
                                const KeptPixels& kept = {}, double white = 0);

/// A picture's tone at a pixel, before gamma: its darkness 1 − grey, or with `invert` its luminance on black
/// paper, grey − (1 − alpha). `grey` is composited on white (GreyImage) and `alpha` its coverage (1 where
/// opaque): transparent is paper, white for dark dots and black for inverted ones. Every reader of a
/// picture's tone (a file, a colour's channel, a Python array) takes it from here, so that they agree bit
/// for bit. Never negative; a tone under 2^-20, float rounding rather than ink, is 0.
double picture_tone(double grey, double alpha, bool invert);

/// Densities that share one domain (the classes of a query or a sample) stretch each image over all of it:
/// images whose sides differ in ratio (by more than 1%) would be stretched differently, while images of one
/// shape at any resolutions line up. Returns the indices {i, j} (i < j) of the first image `specs[j]`
/// whose shape differs from the first image's `specs[i]`, or {-1, -1} where every image has one shape.
std::pair<int, int> images_of_different_shapes(const std::vector<const DensitySpec*>& specs);

}  // namespace kdm::tools
