// Parsing densities as users name them (density_spec.h).
#include "density_spec.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "image_io.h"

namespace kdm::tools {

double DensitySpec::map_at(double u, double v) const {
  const double a = std::log(range);
  if (kind == Kind::kRamp) return std::exp(-a * u);
  if (kind == Kind::kRadial) {
    const double dx = u - 0.5, dy = v - 0.5;
    return std::exp(-a * std::min(1.0, 2 * std::sqrt(dx * dx + dy * dy)));
  }
  return 1;
}

double DensitySpec::max_value() const {
  if (kind == Kind::kConstant) return constant;
  if (kind == Kind::kImage)
    return values.empty() ? 0.0 : double(*std::max_element(values.begin(), values.end()));
  return 1;
}

double DensitySpec::mean_value() const {
  switch (kind) {
    case Kind::kConstant:
      return constant;
    case Kind::kImage: {
      double sum = 0;
      for (float v : values) sum += v;
      return values.empty() ? 0.0 : sum / double(values.size());
    }
    case Kind::kRamp:  // ∫₀¹ R^-u du
      return range > 1 ? (1 - 1 / range) / std::log(range) : 1.0;
    case Kind::kRadial: {  // the disc r < 1/2 by the radial integral, 1/R outside it
      const double a = std::log(range);
      if (!(a > 0)) return 1.0;
      // ∫₀^½ e^(−2ar) 2πr dr = (π / (2a²)) (1 − e^(−a)(1 + a))
      const double disc = std::acos(-1.0) / (2 * a * a) * (1 - std::exp(-a) * (1 + a));
      return disc + (1 - std::acos(-1.0) / 4) / range;
    }
  }
  return 1;
}

namespace {

/// A finite number that fills `text` exactly, or NaN.
double parse_number(const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  return !text.empty() && *end == '\0' && std::isfinite(v) ? v : std::nan("");
}

}  // namespace

DensitySpec parse_density_spec(const std::string& text, double gamma, bool invert, std::uint64_t max_pixels,
                               const KeptPixels& kept) {
  DensitySpec spec;
  spec.text = text;
  if (!(std::isfinite(gamma) && gamma > 0)) throw std::invalid_argument("gamma must be a finite number > 0");
  if (text.rfind("const:", 0) == 0) {
    const double v = parse_number(text.substr(6));
    if (!(v >= 0))
      throw std::invalid_argument("density const:V needs a finite V >= 0, got '" + text.substr(6) + "'");
    spec.constant = v;
    return spec;
  }
  for (const char* kind : {"ramp:", "radial:"}) {
    const std::size_t len = std::char_traits<char>::length(kind);
    if (text.compare(0, len, kind) != 0) continue;
    const double range = parse_number(text.substr(len));
    if (!(range >= 1 && range <= 1e9))
      throw std::invalid_argument("density " + std::string(kind) +
                                  "R needs a dynamic range R in [1, 1e9], got '" + text.substr(len) + "'");
    spec.kind = len == 5 ? DensitySpec::Kind::kRamp : DensitySpec::Kind::kRadial;
    spec.range = range;
    return spec;
  }
  std::error_code missing;
  if (!std::filesystem::exists(text, missing))  // a misspelt map more often than a missing picture
    throw std::runtime_error("density '" + text +
                             "': no such file (a density is a picture, const:V, ramp:R or radial:R)");
  GreyImage image;
  std::string error;
  if (!load_grey_image(text, image, error, max_pixels, kept)) throw std::runtime_error(error);
  // Densities keep row 0 at the bottom (y up); the picture's row 0 is its top: flipped here, once.
  spec.kind = DensitySpec::Kind::kImage;
  spec.width = image.width, spec.height = image.height, spec.inverted = invert;
  spec.values.resize(image.pixels.size());
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      // Transparent is paper: white for dark dots, black for --invert's bright ones (its luminance on
      // black is that on white less 1 − alpha).
      const int row = image.height - 1 - y;
      const double grey = image.at(x, row),
                   paper = image.alpha.empty() ? 0.0 : 1.0 - image.alpha[std::size_t(row) * image.width + x],
                   tone = invert ? grey - paper : 1.0 - grey;
      spec.values[static_cast<std::size_t>(y) * image.width + x] =
          static_cast<float>(std::pow(std::max(0.0, tone), gamma));
    }
  return spec;
}

std::pair<int, int> images_of_different_shapes(const std::vector<const DensitySpec*>& specs) {
  int first = -1;
  for (int k = 0; k < static_cast<int>(specs.size()); ++k) {
    const DensitySpec& s = *specs[k];
    if (s.kind != DensitySpec::Kind::kImage) continue;
    if (first < 0) {
      first = k;
      continue;
    }
    const DensitySpec& f = *specs[first];
    const double a = double(s.width) * f.height, b = double(f.width) * s.height;  // ratios times heights
    if (std::fabs(a - b) > 0.01 * b) return {first, k};
  }
  return {-1, -1};
}

}  // namespace kdm::tools
