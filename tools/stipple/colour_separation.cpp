#include "colour_separation.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <numeric>
#include <stdexcept>
#include <unordered_map>

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

using Vec3 = std::array<double, 3>;

/// How a pixel's absorbance is split over inks: the coverages c ≥ 0, Σ c ≤ 1 (dots of several inks side by
/// side, the paper showing between them) whose Σ c_i · ink_i is nearest the pixel's absorbance, plus a
/// small ridge, kRidge · |c|², which makes the split unique and continuous in the colour (a gradient is
/// drawn by coverages that change smoothly, not by one ink per region) and among equal fits prefers the
/// least coverage (a grey by black alone, not by cyan and red side by side).
constexpr double kRidge = 1e-3;

/// Non-negative least squares in Gram form, min cᵀGc − 2hᵀc over c ≥ 0 (Lawson and Hanson's active set;
/// G positive definite, m ≤ 8).
void nnls(const std::vector<double>& G, const std::vector<double>& h, std::size_t m, double* c) {
  std::fill(c, c + m, 0.0);
  std::vector<bool> passive(m, false);
  std::vector<double> z(m);
  const auto solve_passive = [&] {  // z = G_PP⁻¹ h_P by Gaussian elimination, 0 off P
    std::vector<std::size_t> idx;
    for (std::size_t i = 0; i < m; ++i)
      if (passive[i]) idx.push_back(i);
    const std::size_t k = idx.size();
    std::vector<double> a(k * (k + 1));
    for (std::size_t r = 0; r < k; ++r) {
      for (std::size_t q = 0; q < k; ++q) a[r * (k + 1) + q] = G[idx[r] * m + idx[q]];
      a[r * (k + 1) + k] = h[idx[r]];
    }
    for (std::size_t col = 0; col < k; ++col) {
      std::size_t pivot = col;
      for (std::size_t r = col + 1; r < k; ++r)
        if (std::abs(a[r * (k + 1) + col]) > std::abs(a[pivot * (k + 1) + col])) pivot = r;
      for (std::size_t q = 0; q <= k; ++q) std::swap(a[col * (k + 1) + q], a[pivot * (k + 1) + q]);
      for (std::size_t r = col + 1; r < k; ++r) {
        const double f = a[r * (k + 1) + col] / a[col * (k + 1) + col];
        for (std::size_t q = col; q <= k; ++q) a[r * (k + 1) + q] -= f * a[col * (k + 1) + q];
      }
    }
    std::fill(z.begin(), z.end(), 0.0);
    for (std::size_t r = k; r-- > 0;) {
      double v = a[r * (k + 1) + k];
      for (std::size_t q = r + 1; q < k; ++q) v -= a[r * (k + 1) + q] * z[idx[q]];
      z[idx[r]] = v / a[r * (k + 1) + r];
    }
  };
  for (std::size_t outer = 0; outer < 4 * m; ++outer) {
    std::size_t best = m;
    double best_w = 1e-12;
    for (std::size_t j = 0; j < m; ++j) {
      if (passive[j]) continue;
      double w = h[j];
      for (std::size_t q = 0; q < m; ++q) w -= G[j * m + q] * c[q];
      if (w > best_w) best = j, best_w = w;
    }
    if (best == m) break;
    passive[best] = true;
    for (std::size_t inner = 0; inner < 4 * m; ++inner) {
      solve_passive();
      double alpha = 1;
      bool feasible = true;
      for (std::size_t i = 0; i < m; ++i)
        if (passive[i] && z[i] <= 0) {
          feasible = false;
          alpha = std::min(alpha, c[i] / (c[i] - z[i]));
        }
      if (feasible) {
        std::copy(z.begin(), z.end(), c);
        break;
      }
      for (std::size_t i = 0; i < m; ++i) {
        c[i] += alpha * (z[i] - c[i]);
        if (passive[i] && c[i] <= 1e-12) passive[i] = false, c[i] = 0;
      }
    }
  }
}

/// Coverages under this are dropped and the rest split again: a trace of an ink the ridge spreads over
/// inks of near the same colour (black in pure cyan) would be a stray dot of another pen now and then.
constexpr double kTraceCoverage = 0.01;

/// The coverages of the inks in `use` (absorbances; the others 0) that draw absorbance `a` (see kRidge).
void solve_split(const std::vector<Vec3>& inks, const std::vector<bool>& use, const Vec3& a, double* c) {
  std::vector<std::size_t> idx;
  for (std::size_t i = 0; i < inks.size(); ++i)
    if (use[i]) idx.push_back(i);
  const std::size_t m = idx.size();
  std::fill(c, c + inks.size(), 0.0);
  if (m == 0) return;
  std::vector<double> G(m * m), h(m), x(m);
  for (std::size_t i = 0; i < m; ++i) {
    h[i] = dot(inks[idx[i]], a);
    for (std::size_t j = 0; j < m; ++j)
      G[i * m + j] = dot(inks[idx[i]], inks[idx[j]]) + (i == j ? kRidge : 0.0);
  }
  nnls(G, h, m, x.data());
  double sum = 0;
  for (double v : x) sum += v;
  if (sum > 1) {  // darker than the inks side by side can draw: the best split that covers the paper once
    constexpr double kWhole = 1e4;  // Σ c = 1 as a stiff penalty
    for (std::size_t i = 0; i < m; ++i) {
      h[i] += kWhole;
      for (std::size_t j = 0; j < m; ++j) G[i * m + j] += kWhole;
    }
    nnls(G, h, m, x.data());
    sum = 0;
    for (double v : x) sum += v;
    if (sum > 1)
      for (double& v : x) v /= sum;
  }
  for (std::size_t i = 0; i < m; ++i) c[idx[i]] = x[i];
}

/// The coverages of `inks` that draw absorbance `a` (kRidge, kTraceCoverage); returns the squared error.
double split(const std::vector<Vec3>& inks, const Vec3& a, double* c) {
  const std::size_t m = inks.size();
  if (m == 0) return dot(a, a);
  std::vector<bool> use(m, true);
  for (std::size_t round = 0; round < m; ++round) {  // until no trace is left (a dropped ink's share can
    solve_split(inks, use, a, c);                    // pass a trace to another)
    bool traces = false;
    for (std::size_t i = 0; i < m; ++i)
      if (c[i] > 0 && c[i] < kTraceCoverage) use[i] = false, traces = true;
    if (!traces) break;
  }
  Vec3 drawn = {0, 0, 0};
  for (std::size_t i = 0; i < m; ++i)
    for (int k = 0; k < 3; ++k) drawn[k] += c[i] * inks[i][k];
  const Vec3 e = {a[0] - drawn[0], a[1] - drawn[1], a[2] - drawn[2]};
  return dot(e, e);
}

/// An absorbance at full strength: scaled so that its strongest channel is 1 (an ink's dots then draw
/// every tone of its colour, the paper between them), a near-grey one black.
Vec3 full_strength(const Vec3& a) {
  const double strongest = std::max({a[0], a[1], a[2]});
  Vec3 u = {a[0] / strongest, a[1] / strongest, a[2] / strongest};
  if (std::max({a[0], a[1], a[2]}) - std::min({a[0], a[1], a[2]}) < kGreyChroma) u = {1, 1, 1};
  return u;
}

/// Up to N inks for the image, as absorbances at full strength (fewer where fewer draw it about as well;
/// none for a blank image). The image's colours are counted in bins (a subsample, bins of 1/16 of each
/// channel); the inks are chosen among the colours of its own pixels at full strength (farthest-point
/// candidates, so the extremes, black and the most saturated colours, are among them) to draw the counted
/// colours best as splits (least summed squared absorbance error): greedily one ink at a time, then each
/// ink swapped for a better candidate while one is found. An ink that draws under kLeastInk of all the
/// coverage is dropped (it would spend a pen on a few dots).
std::vector<Vec3> choose_inks(const ColourImage& image, int n) {
  const std::size_t pixels = std::size_t(image.width) * image.height;
  const std::size_t step = std::max<std::size_t>(1, pixels / 65536);
  struct Bin {
    Vec3 sum = {0, 0, 0};
    double count = 0;
  };
  std::vector<Bin> bins(16 * 16 * 16);
  for (std::size_t i = 0; i < pixels; i += step) {
    const Vec3 a = absorbance(&image.pixels[3 * i]);
    if (std::sqrt(dot(a, a)) <= kPaperAbsorbance) continue;
    int key = 0;
    for (double v : a) key = key * 16 + std::clamp(int(v * 16), 0, 15);
    for (int k = 0; k < 3; ++k) bins[key].sum[k] += a[k];
    bins[key].count += 1;
  }
  std::vector<Vec3> colours;
  std::vector<double> weights;
  double counted = 0;
  for (const Bin& b : bins)
    if (b.count > 0) {
      colours.push_back({b.sum[0] / b.count, b.sum[1] / b.count, b.sum[2] / b.count});
      weights.push_back(b.count), counted += b.count;
    }
  std::vector<Vec3> inks;
  if (colours.empty()) return inks;
  // Candidates: the full-strength colours of bins holding at least 1 pixel in 2,000 and absorbing at least
  // a tenth (a paler pixel's hue is mostly noise), farthest-point from the most covering.
  std::vector<Vec3> pool;
  std::vector<double> pool_mass;
  for (std::size_t b = 0; b < colours.size(); ++b)
    if (weights[b] >= 5e-4 * counted && std::max({colours[b][0], colours[b][1], colours[b][2]}) >= 0.1) {
      const Vec3& a = colours[b];
      pool.push_back(full_strength(a));
      pool_mass.push_back(weights[b] * std::max({a[0], a[1], a[2]}));
    }
  if (pool.empty()) return inks;
  constexpr std::size_t kCandidates = 32;
  std::vector<Vec3> candidates;
  {
    std::size_t first = std::size_t(std::max_element(pool_mass.begin(), pool_mass.end()) - pool_mass.begin());
    candidates.push_back(pool[first]);
    std::vector<double> far(pool.size(), HUGE_VAL);
    while (candidates.size() < kCandidates) {
      std::size_t best = 0;
      double best_d = 0;
      for (std::size_t i = 0; i < pool.size(); ++i) {
        const Vec3& c = candidates.back();
        const Vec3 d = {pool[i][0] - c[0], pool[i][1] - c[1], pool[i][2] - c[2]};
        far[i] = std::min(far[i], dot(d, d));
        if (far[i] > best_d) best = i, best_d = far[i];
      }
      if (best_d < 0.02 * 0.02) break;  // every colour left is within 0.02 of a candidate
      candidates.push_back(pool[best]);
    }
  }
  std::vector<double> c(8);
  const auto error = [&](const std::vector<Vec3>& palette) {
    double e = 0;
    for (std::size_t b = 0; b < colours.size(); ++b) e += weights[b] * split(palette, colours[b], c.data());
    return e;
  };
  const double blank = error({});
  double current = blank;
  // Greedy: the ink that lowers the error most, while one lowers it by 5% and by 0.2% of the blank
  // paper's. Against the blank paper's alone, which dark pixels dominate, a bright hue covering a sixth
  // of the picture would never count; against the error left alone, a photograph would take every shade
  // of its one hue.
  while (int(inks.size()) < n) {
    std::size_t best = candidates.size();
    double best_e = std::min(current * 0.95, current - 0.002 * blank);
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      if (std::find(inks.begin(), inks.end(), candidates[k]) != inks.end()) continue;
      std::vector<Vec3> trial = inks;
      trial.push_back(candidates[k]);
      const double e = error(trial);
      if (e < best_e) best = k, best_e = e;
    }
    if (best == candidates.size()) break;
    inks.push_back(candidates[best]);
    current = best_e;
  }
  // Swaps: each ink replaced by the candidate that lowers the error most, while one does.
  for (int round = 0; round < 3; ++round) {
    bool changed = false;
    for (std::size_t slot = 0; slot < inks.size(); ++slot)
      for (const Vec3& candidate : candidates) {
        if (std::find(inks.begin(), inks.end(), candidate) != inks.end()) continue;
        std::vector<Vec3> trial = inks;
        trial[slot] = candidate;
        const double e = error(trial);
        if (e < current * (1 - 1e-9)) inks = trial, current = e, changed = true;
      }
    if (!changed) break;
  }
  // Drop inks that draw under kLeastInk of all the coverage, least first, one at a time.
  constexpr double kLeastInk = 0.01;
  while (inks.size() > 1) {
    std::vector<double> mass(inks.size(), 0.0);
    for (std::size_t b = 0; b < colours.size(); ++b) {
      split(inks, colours[b], c.data());
      for (std::size_t k = 0; k < inks.size(); ++k) mass[k] += weights[b] * c[k];
    }
    const double total = std::accumulate(mass.begin(), mass.end(), 0.0);
    const std::size_t least = std::size_t(std::min_element(mass.begin(), mass.end()) - mass.begin());
    if (mass[least] >= kLeastInk * total) break;
    inks.erase(inks.begin() + std::ptrdiff_t(least));
  }
  return inks;
}

/// A word for an ink's colour (sRGB bytes), for the layer a plotter's pen draws: black, grey, red, orange,
/// brown, yellow, green, cyan, blue, purple, magenta or pink.
std::string colour_word(const std::uint8_t rgb[3]) {
  const double r = rgb[0] / 255.0, g = rgb[1] / 255.0, b = rgb[2] / 255.0;
  const double hi = std::max({r, g, b}), lo = std::min({r, g, b}), chroma = hi - lo;
  if (chroma < 0.15) return hi < 0.25 ? "black" : hi > 0.9 ? "white" : "grey";
  double hue = hi == r   ? std::fmod((g - b) / chroma + 6, 6.0)
               : hi == g ? (b - r) / chroma + 2
                         : (r - g) / chroma + 4;
  hue *= 60;
  if (hue < 15 || hue >= 335) return lo > 0.45 ? "pink" : hi < 0.6 ? "brown" : "red";
  if (hue < 45) return hi < 0.7 ? "brown" : "orange";
  if (hue < 70) return hi < 0.6 ? "olive" : "yellow";
  if (hue < 160) return "green";
  if (hue < 200) return "cyan";
  if (hue < 255) return "blue";
  if (hue < 290) return "purple";
  return lo > 0.45 ? "pink" : "magenta";
}

/// An ink list "#e00000,#0000aa,#000000" (each #rrggbb or rrggbb, 1 to 8 of them, spaces around each
/// allowed) as absorbances; throws
/// std::invalid_argument naming the bad part.
std::vector<Vec3> parse_palette(const std::string& scheme) {
  std::vector<Vec3> inks;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = scheme.find(',', start);
    std::string item = scheme.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    // Spaces around an ink are allowed, as a list typed "#e00000, #0000aa" has them.
    const auto space = [](char ch) { return std::isspace(static_cast<unsigned char>(ch)) != 0; };
    item.erase(item.begin(), std::find_if_not(item.begin(), item.end(), space));
    item.erase(std::find_if_not(item.rbegin(), item.rend(), space).base(), item.end());
    if (!item.empty() && item[0] == '#') item.erase(0, 1);
    const bool hex = item.size() == 6 && std::all_of(item.begin(), item.end(), [](char ch) {
                       return std::isxdigit(static_cast<unsigned char>(ch)) != 0;
                     });
    if (!hex)
      throw std::invalid_argument(
          "colours as inks must be #rrggbb, separated by commas (#e00000,#0000aa), got '" + scheme + "'");
    const long v = std::strtol(item.c_str(), nullptr, 16);
    inks.push_back({1 - ((v >> 16) & 255) / 255.0, 1 - ((v >> 8) & 255) / 255.0, 1 - (v & 255) / 255.0});
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (inks.size() > 8)
    throw std::invalid_argument("colours as inks take at most 8 inks, got " + std::to_string(inks.size()));
  for (std::size_t i = 0; i < inks.size(); ++i) {
    if (!(std::max({inks[i][0], inks[i][1], inks[i][2]}) > 0))
      throw std::invalid_argument("an ink of white (#ffffff) draws nothing on white paper: '" + scheme + "'");
    for (std::size_t j = 0; j < i; ++j)
      if (inks[i] == inks[j]) throw std::invalid_argument("an ink is given twice in '" + scheme + "'");
  }
  return inks;
}

/// Inks named by one numbering, their class's (the unused after the used), and their colour, "ink-0-red":
/// the SVG layer, the printed list and a .csv's class number say the same. Layers in class order, but
/// pens (`listed`) keep the order given, so that a plotter's pens stay put whatever the image.
void name_by_class(ColourSeparation& s, bool listed) {
  int k = 0;
  for (auto* list : {&s.inks, &s.unused})
    for (Ink& i : *list) {
      i.name = "ink-" + std::to_string(k) + "-" + colour_word(i.rgb);
      if (!listed) i.layer = k;
      ++k;
    }
}

}  // namespace

ColourSeparation separate_colours(const ColourImage& image, const std::string& scheme, double gamma) {
  if (!(gamma > 0) || !std::isfinite(gamma)) throw std::invalid_argument("gamma must be a finite number > 0");
  ColourSeparation s;
  bool numbered = false;  // inks named by their class number and colour, once the classes are ordered
  bool listed = false;    // the user's pens, their layers in the order given
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
      // Light on black paper: each channel's tone as an inverted picture's (transparent is black).
      s.channels.push_back(channel(image, gamma, names[c], [c, &image](const float* p) {
        const std::size_t i = std::size_t(p - image.pixels.data()) / 3;
        return picture_tone(p[c], image.alpha.empty() ? 1.0 : image.alpha[i], true);
      }));
    }
    s.inks = {ink(255, 0, 0, "red", 0), ink(0, 255, 0, "green", 1), ink(0, 0, 255, "blue", 2)};
    std::fill(s.background, s.background + 3, 0);
    s.blend = Blend::kAdd;
  } else {
    // N inks chosen for the image, or the user's own (a list of colours).
    listed = scheme.find('#') != std::string::npos || scheme.find(',') != std::string::npos;
    std::vector<Vec3> inks;
    if (listed) {
      inks = parse_palette(scheme);
    } else {
      char* end = nullptr;
      const long n = std::strtol(scheme.c_str(), &end, 10);
      if (scheme.empty() || *end != '\0' || n < 2 || n > 8)
        throw std::invalid_argument(
            "colours must be cmyk, rgb, a number of inks from 2 to 8 or inks as #rrggbb,#rrggbb,..., got '" +
            scheme + "'");
      inks = choose_inks(image, int(n));
    }
    // Each distinct colour split once (pixels of one colour share it; keyed at 10 bits a channel, finer
    // than 8-bit images), near-greys as greys (a photograph's colour noise is not a colour to draw).
    const std::size_t pixels = std::size_t(image.width) * image.height;
    std::vector<std::uint32_t> which(pixels);
    std::vector<float> coverage;  // per distinct colour, one value per ink
    {
      std::unordered_map<std::uint32_t, std::uint32_t> seen;
      std::vector<double> c(std::max<std::size_t>(1, inks.size()));
      for (std::size_t i = 0; i < pixels && !inks.empty(); ++i) {
        std::uint32_t key = 0;
        for (int k = 0; k < 3; ++k)
          key =
              key * 1024 + std::uint32_t(std::lround(std::clamp(image.pixels[3 * i + k], 0.0f, 1.0f) * 1023));
        const auto [at, added] = seen.emplace(key, std::uint32_t(seen.size()));
        which[i] = at->second;
        if (!added) continue;
        const float rgb[3] = {float((key >> 20) / 1023.0), float(((key >> 10) & 1023) / 1023.0),
                              float((key & 1023) / 1023.0)};
        split(inks, hue_absorbance(rgb), c.data());
        coverage.insert(coverage.end(), c.begin(), c.begin() + std::ptrdiff_t(inks.size()));
      }
    }
    for (std::size_t c = 0; c < inks.size(); ++c) {
      s.channels.push_back(channel(image, gamma, "ink", [&, c](const float* p) {
        const std::size_t i = std::size_t(p - image.pixels.data()) / 3;
        return double(coverage[which[i] * inks.size() + c]);
      }));
      const auto byte = [](double v) {
        return static_cast<std::uint8_t>(std::lround(std::clamp(1 - v, 0.0, 1.0) * 255));
      };
      s.inks.push_back(ink(byte(inks[c][0]), byte(inks[c][1]), byte(inks[c][2]), "ink", int(c)));
    }
    numbered = true;
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
    if (numbered) name_by_class(s, listed);
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
  if (numbered) name_by_class(sorted, listed);
  return sorted;
}

std::string stipple_summary(std::size_t dots, const std::string& how, const std::string& scheme,
                            const ColourSeparation& inks) {
  std::string inked;
  if (scheme == "cmyk" || scheme == "rgb") {
    inked = ", inks " + scheme;
  } else if (!scheme.empty()) {
    const bool listed = scheme.find_first_of("#,") != std::string::npos;  // the user's pens
    inked = ", inks " + std::to_string(inks.inks.size()) + " of " +
            (listed ? std::to_string(inks.inks.size() + inks.unused.size()) + " given" : scheme);
  }
  return "kdm stipple: " + std::to_string(dots) + " dot" + (dots == 1 ? "" : "s") + " (" + how + inked + ")";
}

}  // namespace kdm::tools
