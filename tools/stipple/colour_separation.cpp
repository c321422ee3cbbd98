#include "colour_separation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace kdm::tools {
namespace {

/// An image-sized density with row 0 at the bottom (DensitySpec's order), filled by `value(pixel)`.
template <class Value>
DensitySpec channel(const ColourImage& image, double gamma, const std::string& name, Value&& value) {
  DensitySpec spec;
  spec.kind = DensitySpec::Kind::kImage;
  spec.width = image.width, spec.height = image.height;
  spec.text = name;
  spec.values.resize(std::size_t(image.width) * image.height);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const float* rgb = &image.pixels[(std::size_t(y) * image.width + x) * 3];
      // Below 1e-6 is rounding (the chromatic parts of a grey pixel), not ink.
      const double raw = value(rgb), v = raw < 1e-6 ? 0.0 : std::min(raw, 1.0);
      spec.values[std::size_t(image.height - 1 - y) * image.width + x] =
          static_cast<float>(gamma == 1 ? v : std::pow(v, gamma));
    }
  return spec;
}

Ink ink(std::uint8_t r, std::uint8_t g, std::uint8_t b, const std::string& name, int layer) {
  Ink i;
  i.rgb[0] = r, i.rgb[1] = g, i.rgb[2] = b;
  i.name = name, i.layer = layer;
  return i;
}

double luminance(const float* rgb) {
  return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
}

/// The paper's colour: a fixed centre among the inks' clusters, so that the image's white takes no ink.
constexpr std::array<double, 3> kPaper = {1, 1, 1};

double distance(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
}

/// The index of the centre nearest `p`, or centres.size() where the paper is nearer than every centre.
std::size_t nearest_centre(const std::array<double, 3>& p,
                           const std::vector<std::array<double, 3>>& centres) {
  std::size_t best = centres.size();
  double best_distance = distance(p, kPaper);
  for (std::size_t c = 0; c < centres.size(); ++c)
    if (const double d = distance(p, centres[c]); d < best_distance) best = c, best_distance = d;
  return best;
}

/// N ink colours of the image by k-means beside the fixed paper (Lloyd's iterations from a farthest-point
/// start on a subsample, so the result depends on the image alone).
std::vector<std::array<double, 3>> cluster_colours(const ColourImage& image, int n) {
  const std::size_t pixels = std::size_t(image.width) * image.height;
  const std::size_t step = std::max<std::size_t>(1, pixels / 65536);
  std::vector<std::array<double, 3>> samples;
  for (std::size_t i = 0; i < pixels; i += step)
    samples.push_back({image.pixels[3 * i], image.pixels[3 * i + 1], image.pixels[3 * i + 2]});
  // Each centre the sample farthest from the paper and the centres chosen before it.
  std::vector<std::array<double, 3>> centres;
  std::vector<double> nearest(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) nearest[i] = distance(samples[i], kPaper);
  while (int(centres.size()) < n) {
    std::size_t far = 0;
    for (std::size_t i = 0; i < samples.size(); ++i) {
      if (!centres.empty()) nearest[i] = std::min(nearest[i], distance(samples[i], centres.back()));
      if (nearest[i] > nearest[far]) far = i;
    }
    centres.push_back(samples[far]);
  }
  for (int iteration = 0; iteration < 20; ++iteration) {
    std::vector<std::array<double, 4>> sums(centres.size(), {0, 0, 0, 0});
    for (const auto& s : samples) {
      const std::size_t best = nearest_centre(s, centres);
      if (best == centres.size()) continue;  // the paper's
      for (int k = 0; k < 3; ++k) sums[best][k] += s[k];
      sums[best][3] += 1;
    }
    for (std::size_t c = 0; c < centres.size(); ++c)
      if (sums[c][3] > 0)
        for (int k = 0; k < 3; ++k) centres[c][k] = sums[c][k] / sums[c][3];
  }
  // Darkest first: the inks that show most get the best-spread dots.
  std::sort(centres.begin(), centres.end(),
            [](const auto& a, const auto& b) { return a[0] + a[1] + a[2] < b[0] + b[1] + b[2]; });
  return centres;
}

}  // namespace

ColourSeparation separate_colours(const ColourImage& image, const std::string& scheme, double gamma) {
  if (!(gamma > 0) || !std::isfinite(gamma)) throw std::invalid_argument("gamma must be a finite number > 0");
  ColourSeparation s;
  if (scheme == "cmyk") {
    auto black = [](const float* p) { return 1.0 - std::max({double(p[0]), double(p[1]), double(p[2])}); };
    auto part = [&](int c) {
      return [c, black](const float* p) {
        const double k = black(p);
        return k >= 1 ? 0.0 : (1 - p[c] - k) / (1 - k);
      };
    };
    s.channels.push_back(channel(image, gamma, "black", black));  // one at a time: no copies of channels
    s.channels.push_back(channel(image, gamma, "cyan", part(0)));
    s.channels.push_back(channel(image, gamma, "magenta", part(1)));
    s.channels.push_back(channel(image, gamma, "yellow", part(2)));
    // Layers in the printing order, black last, whichever inks the image uses most.
    s.inks = {ink(0, 0, 0, "black", 3), ink(0, 174, 239, "cyan", 0), ink(236, 0, 140, "magenta", 1),
              ink(255, 242, 0, "yellow", 2)};
  } else if (scheme == "rgb") {
    for (int c = 0; c < 3; ++c) {
      const char* names[3] = {"red", "green", "blue"};
      // Light on black paper: transparent is black (the colour on white less 1 − alpha).
      s.channels.push_back(channel(image, gamma, names[c], [c, &image](const float* p) {
        const std::size_t i = std::size_t(p - image.pixels.data()) / 3;
        return double(p[c]) - (image.alpha.empty() ? 0.0 : 1.0 - image.alpha[i]);
      }));
    }
    s.inks = {ink(255, 0, 0, "red", 0), ink(0, 255, 0, "green", 1), ink(0, 0, 255, "blue", 2)};
    std::fill(s.background, s.background + 3, 0);
    s.blend = Blend::kAdd;
  } else {
    char* end = nullptr;
    const long n = std::strtol(scheme.c_str(), &end, 10);
    if (scheme.empty() || *end != '\0' || n < 2 || n > 8)
      throw std::invalid_argument("colours must be cmyk, rgb or a number of inks from 2 to 8, got '" +
                                  scheme + "'");
    const auto centres = cluster_colours(image, int(n));
    // Each pixel's ink, once for all channels (centres.size(): the paper's, no ink).
    std::vector<std::uint8_t> owner(std::size_t(image.width) * image.height);
    for (std::size_t i = 0; i < owner.size(); ++i) {
      const float* p = &image.pixels[3 * i];
      owner[i] = static_cast<std::uint8_t>(nearest_centre({p[0], p[1], p[2]}, centres));
    }
    for (std::size_t c = 0; c < centres.size(); ++c) {
      s.channels.push_back(channel(image, gamma, "ink-" + std::to_string(c), [&, c](const float* p) {
        return owner[std::size_t(p - image.pixels.data()) / 3] == c ? 1 - luminance(p) : 0.0;
      }));
      const auto byte = [](double v) {
        return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255));
      };
      s.inks.push_back(ink(byte(centres[c][0]), byte(centres[c][1]), byte(centres[c][2]),
                           "ink-" + std::to_string(c), int(c)));
    }
  }
  // Inks that no pixel uses would only waste a class: keep those with some coverage.
  std::vector<Ink> unused;
  for (std::size_t c = s.channels.size(); c-- > 0;)
    if (!(s.channels[c].max_value() > 0)) {
      unused.insert(unused.begin(), s.inks[c]);
      s.channels.erase(s.channels.begin() + c), s.inks.erase(s.inks.begin() + c);
    }
  if (s.channels.empty()) {  // a blank image: no dots, every ink an empty layer
    s.unused = std::move(unused);
    return s;
  }
  // A later class's dots are those its cumulative density adds to the earlier classes', so its tone carries
  // their count errors too, the more the smaller its share: inks of least coverage first. But an ink of
  // very little coverage first takes the union's lowest thresholds, which repeat a motif along tile edges:
  // inks under a tenth of the total coverage go last, most covering first (docs/design.md, "Several
  // classes in colour").
  std::vector<double> mean(s.channels.size());  // each a pass over every pixel: once
  double total = 0;
  for (std::size_t c = 0; c < mean.size(); ++c) total += mean[c] = s.channels[c].mean_value();
  auto minor = [&](std::size_t c) { return mean[c] < 0.1 * total; };
  std::vector<std::size_t> order(s.channels.size());
  for (std::size_t c = 0; c < order.size(); ++c) order[c] = c;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    if (minor(a) != minor(b)) return minor(b);
    const double ca = mean[a], cb = mean[b];
    return minor(a) ? ca > cb : ca < cb;
  });
  ColourSeparation sorted;
  std::copy(s.background, s.background + 3, sorted.background);
  sorted.blend = s.blend;
  sorted.unused = std::move(unused);
  for (std::size_t c : order)
    sorted.channels.push_back(std::move(s.channels[c])), sorted.inks.push_back(s.inks[c]);
  return sorted;
}

}  // namespace kdm::tools
