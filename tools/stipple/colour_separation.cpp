#include "colour_separation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <numeric>
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

/// An ink or pixel on white paper as its absorbance, 1 − rgb per channel: a dot of ink a covering a
/// fraction c of the paper leaves c · a, so a pixel a_p is drawn in ink a by coverage (a_p · a) / |a|².
std::array<double, 3> absorbance(const float* rgb) {
  return {1.0 - rgb[0], 1.0 - rgb[1], 1.0 - rgb[2]};
}

double dot(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/// Pixels fainter than this (|absorbance|) are paper: their hue is noise, and they need next to no ink.
constexpr double kPaperAbsorbance = 0.02;

/// Channels closer than this (15 of 255) are grey: a photograph's greys carry a few levels of colour noise,
/// which clustered as hues gave a grey image six tinted near-black inks.
constexpr double kGreyChroma = 0.06;

/// The absorbance whose hue a pixel is clustered and inked by: its own, or grey of the same mean where its
/// channels lie within kGreyChroma of each other.
std::array<double, 3> hue_absorbance(const float* rgb) {
  const std::array<double, 3> a = {1.0 - rgb[0], 1.0 - rgb[1], 1.0 - rgb[2]};
  if (std::max({a[0], a[1], a[2]}) - std::min({a[0], a[1], a[2]}) >= kGreyChroma) return a;
  const double mean = (a[0] + a[1] + a[2]) / 3;
  return {mean, mean, mean};
}

/// The ink (a unit direction among `hues`) whose hue is nearest the absorbance `a`: the largest cosine.
std::size_t nearest_hue(const std::array<double, 3>& a, const std::vector<std::array<double, 3>>& hues) {
  std::size_t best = 0;
  for (std::size_t c = 1; c < hues.size(); ++c)
    if (dot(a, hues[c]) > dot(a, hues[best])) best = c;
  return best;
}

/// Up to N ink hues of the image: spherical k-means on the pixels' absorbance directions, each pixel
/// weighing its absorbance (Lloyd's iterations from a farthest-point start on a subsample, so the result
/// depends on the image alone). Fewer where the image holds fewer hues (a grey image: one). Unit vectors.
std::vector<std::array<double, 3>> cluster_hues(const ColourImage& image, int n) {
  const std::size_t pixels = std::size_t(image.width) * image.height;
  const std::size_t step = std::max<std::size_t>(1, pixels / 65536);
  std::vector<std::array<double, 3>> samples;
  for (std::size_t i = 0; i < pixels; i += step) {
    const std::array<double, 3> a = hue_absorbance(&image.pixels[3 * i]);
    if (std::sqrt(dot(a, a)) > kPaperAbsorbance) samples.push_back(a);
  }
  std::vector<std::array<double, 3>> hues;
  if (samples.empty()) return hues;
  auto unit = [](std::array<double, 3> a) {
    const double length = std::sqrt(dot(a, a));
    for (double& v : a) v /= length;
    return a;
  };
  // The darkest sample first, then each time the sample whose hue lies farthest from those chosen (1 −
  // cosine), weighed by its absorbance so that a faint pixel's noisy hue does not count as a colour.
  std::size_t first = 0;
  for (std::size_t i = 0; i < samples.size(); ++i)
    if (dot(samples[i], samples[i]) > dot(samples[first], samples[first])) first = i;
  hues.push_back(unit(samples[first]));
  std::vector<double> far(samples.size(), HUGE_VAL);
  while (int(hues.size()) < n) {
    std::size_t best = 0;
    double best_score = 0;
    for (std::size_t i = 0; i < samples.size(); ++i) {
      const double length = std::sqrt(dot(samples[i], samples[i]));
      far[i] = std::min(far[i], length - dot(samples[i], hues.back()));  // |a| (1 − cos)
      if (far[i] > best_score) best = i, best_score = far[i];
    }
    if (best_score < 0.01) break;  // every hue left is within about 8° of one chosen
    hues.push_back(unit(samples[best]));
  }
  // Lloyd's iterations; then a hue holding under kLeastInk of all the ink (a highlight of a few pixels,
  // colour noise) is dropped and its pixels go to the others: it would spend a pen on a few dots (a cyan
  // ink of 5 dots in 40,000 for the coffee picture's spoon).
  constexpr double kLeastInk = 0.01;
  for (int round = 0; round < 2; ++round) {
    std::vector<double> mass(hues.size());
    for (int iteration = 0; iteration < 20; ++iteration) {
      std::vector<std::array<double, 3>> sums(hues.size(), {0, 0, 0});
      std::fill(mass.begin(), mass.end(), 0.0);
      for (const auto& a : samples) {
        const std::size_t c = nearest_hue(a, hues);
        for (int k = 0; k < 3; ++k) sums[c][k] += a[k];
        mass[c] += std::sqrt(dot(a, a));
      }
      for (std::size_t c = 0; c < hues.size(); ++c)
        if (dot(sums[c], sums[c]) > 0) hues[c] = unit(sums[c]);
    }
    const double total = std::accumulate(mass.begin(), mass.end(), 0.0);
    std::vector<std::array<double, 3>> kept;
    for (std::size_t c = 0; c < hues.size(); ++c)
      if (mass[c] >= kLeastInk * total) kept.push_back(hues[c]);
    if (kept.size() == hues.size() || kept.empty()) break;
    hues = kept;
  }
  return hues;
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
    // Each ink is its hue at full strength (its strongest channel absorbs everything), so that its dots,
    // covering part of the paper, can draw every tone of that hue: an ink of a pixel's own colour would
    // need to cover all of it (a flat 50% grey drawn in a #808080 ink came out 25% grey).
    const auto hues = cluster_hues(image, int(n));
    std::vector<std::array<double, 3>> inks;
    for (const auto& h : hues) {
      const double strongest = std::max({h[0], h[1], h[2]});
      inks.push_back({h[0] / strongest, h[1] / strongest, h[2] / strongest});
    }
    // Each pixel's ink, once for all channels.
    std::vector<std::uint8_t> owner(std::size_t(image.width) * image.height);
    for (std::size_t i = 0; i < owner.size() && !hues.empty(); ++i)
      owner[i] = static_cast<std::uint8_t>(nearest_hue(hue_absorbance(&image.pixels[3 * i]), hues));
    for (std::size_t c = 0; c < inks.size(); ++c) {
      s.channels.push_back(channel(image, gamma, "ink-" + std::to_string(c), [&, c](const float* p) {
        const std::size_t i = std::size_t(p - image.pixels.data()) / 3;
        return owner[i] == c ? dot(absorbance(p), inks[c]) / dot(inks[c], inks[c]) : 0.0;
      }));
      const auto byte = [](double v) {
        return static_cast<std::uint8_t>(std::lround(std::clamp(1 - v, 0.0, 1.0) * 255));
      };
      s.inks.push_back(
          ink(byte(inks[c][0]), byte(inks[c][1]), byte(inks[c][2]), "ink-" + std::to_string(c), int(c)));
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
