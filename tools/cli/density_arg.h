// --density on the command line: the neutral description of tools/common/density_spec.h, with its
// errors as CommandError. The full sampler's commands convert it with generator_density.h, the runtime's
// with runtime_args.h.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "density_spec.h"

namespace kdm::cli {

/// How messages name the input "-".
inline constexpr const char* kStandardInputName = "standard input";

/// Standard input read whole, for an input given as "-" (tools::read_standard_input). Throws CommandError
/// when it is a terminal, empty or cannot be read.
std::vector<std::uint8_t> standard_input_bytes();

/// Throws CommandError when more than one of `inputs` (an option's name, its value) is "-": standard input
/// is read once.
void check_one_standard_input(const std::vector<std::pair<std::string, std::string>>& inputs);

/// Parses --density (see tools::parse_density_spec; "-": standard input, an image or a .npy array told
/// apart by its first bytes). Throws CommandError naming the problem.
/// Images: refused over `max_pixels`, averaged down to what `kept` keeps (tools::KeptPixels); a Radiance
/// picture's luminance `white` is white (0: its brightest pixel's).
tools::DensitySpec parse_density(const std::string& text, double gamma, bool invert,
                                 std::uint64_t max_pixels = tools::kMaxImagePixels,
                                 const tools::KeptPixels& kept = {}, double white = 0);

/// --gamma as every command takes it: a finite number > 0, else a CommandError naming the option.
void check_gamma(double gamma);

/// The --class densities share one domain, each image stretched over all of it: images of different shapes
/// would each be stretched differently (tools::images_of_different_shapes; resolutions may differ). Throws
/// CommandError naming two that differ.
void check_class_images(const std::vector<const tools::DensitySpec*>& classes);

/// --gamma and --invert reshape image files' tones only: given (gamma ≠ 1 or invert) with no image among
/// `densities`, they would be silently ignored. Throws CommandError saying so.
void check_image_options(const std::vector<const tools::DensitySpec*>& densities, double gamma, bool invert);

}  // namespace kdm::cli
