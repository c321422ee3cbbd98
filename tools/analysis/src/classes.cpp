#include "kdm/analysis/classes.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "kdm/analysis/common.h"
#include "kdm/analysis/density.h"
#include "kdm/analysis/json.h"

namespace kdm::analysis {

std::vector<std::uint8_t> classes_present(const tools::PointSet& set) {
  std::vector<std::uint8_t> present(set.classes);
  std::sort(present.begin(), present.end());
  present.erase(std::unique(present.begin(), present.end()), present.end());
  return present;
}

tools::PointSet class_subset(const tools::PointSet& set, std::uint8_t k) {
  tools::PointSet subset;
  subset.dim = set.dim;
  for (std::size_t i = 0; i < set.classes.size(); ++i)
    if (set.classes[i] == k)
      subset.coords.insert(subset.coords.end(), set.coords.begin() + i * set.dim,
                           set.coords.begin() + (i + 1) * set.dim);
  return subset;
}

namespace {

/// The set's points by square cell about two spacings wide (a counting sort): cell (gx, gy) holds
/// order[start[gy · cells + gx] … start[gy · cells + gx + 1]).
struct CellList {
  int cells = 1;
  std::vector<std::size_t> start, order;
  int cell_of(double v) const { return std::min(cells - 1, std::max(0, static_cast<int>(v * cells))); }
  /// The cell at (gx, gy), wrapped on a torus; -1 past a box's side.
  std::ptrdiff_t at(int gx, int gy, bool torus) const {
    if (torus) gx = (gx % cells + cells) % cells, gy = (gy % cells + cells) % cells;
    if (gx < 0 || gy < 0 || gx >= cells || gy >= cells) return -1;
    return std::ptrdiff_t(gy) * cells + gx;
  }
  CellList(const tools::PointSet& set, double spacing)
      : cells(std::clamp(static_cast<int>(1 / (2 * spacing)), 1, 4096)),
        start(std::size_t(cells) * cells + 1, 0),
        order(set.size()) {
    const auto cell = [&](std::size_t i) {
      return std::size_t(cell_of(set.coords[2 * i + 1])) * cells + cell_of(set.coords[2 * i]);
    };
    for (std::size_t i = 0; i < set.size(); ++i) ++start[cell(i) + 1];
    for (std::size_t c = 1; c < start.size(); ++c) start[c] += start[c - 1];
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < set.size(); ++i) order[fill[cell(i)]++] = i;
  }
};

/// The closest pair of different classes in local spacings: each pair's distance over d_hex of the set's
/// count scaled by √(mean ρ / ρ) at its midpoint, every point looking up to two of its own local spacings
/// away (a pair farther apart than that is no close pair where either stands). Work ∝ n, as a sparse
/// region's wider reach meets fewer points.
double local_cross_class_closest(const tools::PointSet& set, bool torus, const DensityFunction& density) {
  const std::size_t n = set.size();
  const double spacing = hex_spacing(n), mean = density_scale(density).first;
  if (!(mean > 0)) throw InvalidInput("the target density is zero everywhere");
  const CellList list(set, spacing);
  const int cells = list.cells;
  const double h = 1.0 / cells;
  const auto cell_of = [&](double v) { return list.cell_of(v); };
  const std::vector<std::size_t>&start = list.start, &order = list.order;
  auto local = [&](double x, double y) {
    const double rho = density(x, y);
    return rho > 0 ? spacing * std::sqrt(mean / rho) : std::numeric_limits<double>::infinity();
  };
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    const double x = set.coords[2 * i], y = set.coords[2 * i + 1];
    const double reach = std::min(2 * local(x, y), torus ? 0.5 : 1.5);
    if (!std::isfinite(reach)) continue;  // a point where ρ = 0: no local spacing
    const int rings = std::min(cells, static_cast<int>(std::ceil(reach / h)));
    const int cx = cell_of(x), cy = cell_of(y);
    for (int dy = -rings; dy <= rings; ++dy)
      for (int dx = -rings; dx <= rings; ++dx) {
        if (torus && (std::abs(dx) > cells / 2 || std::abs(dy) > cells / 2))
          continue;  // reached the other way
        const std::ptrdiff_t c = list.at(cx + dx, cy + dy, torus);
        if (c < 0) continue;
        for (std::size_t k = start[c]; k < start[c + 1]; ++k) {
          const std::size_t j = order[k];
          if (set.classes[j] == set.classes[i]) continue;
          double ddx = set.coords[2 * j] - x, ddy = set.coords[2 * j + 1] - y;
          if (torus) ddx -= std::round(ddx), ddy -= std::round(ddy);
          const double d = std::hypot(ddx, ddy);
          if (d > reach) continue;
          double mx = x + ddx / 2, my = y + ddy / 2;
          if (torus) mx -= std::floor(mx), my -= std::floor(my);
          best = std::min(best, d / local(mx, my));
        }
      }
  }
  return best;
}

}  // namespace

double cross_class_closest(const tools::PointSet& set, bool torus, const DensityFunction& density) {
  if (density) {
    if (set.dim != 2 || set.classes.size() != set.size())
      throw InvalidInput("the cross-class closest pair needs 2D points with a class each");
    if (classes_present(set).size() < 2) return std::numeric_limits<double>::quiet_NaN();
    return local_cross_class_closest(set, torus, density);
  }
  const std::size_t n = set.size();
  if (set.dim != 2 || set.classes.size() != n)
    throw InvalidInput("the cross-class closest pair needs 2D points with a class each");
  if (classes_present(set).size() < 2) return std::numeric_limits<double>::quiet_NaN();
  // Cells about two spacings wide; each point looks through rings of cells around its own until the ring
  // lies farther than the closest pair found so far.
  const double spacing = hex_spacing(n);
  const CellList list(set, spacing);
  const int cells = list.cells;
  const double h = 1.0 / cells;
  const auto cell_of = [&](double v) { return list.cell_of(v); };
  const std::vector<std::size_t>&start = list.start, &order = list.order;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    const double x = set.coords[2 * i], y = set.coords[2 * i + 1];
    const int cx = cell_of(x), cy = cell_of(y);
    for (int ring = 0; ring <= cells && (ring - 1) * h < best; ++ring)
      for (int dy = -ring; dy <= ring; ++dy)
        for (int dx = -ring; dx <= ring; ++dx) {
          if (std::max(std::abs(dx), std::abs(dy)) != ring) continue;
          if (torus && ring > cells / 2) continue;  // every cell is already within reach on the torus
          const std::ptrdiff_t c = list.at(cx + dx, cy + dy, torus);
          if (c < 0) continue;
          for (std::size_t k = start[c]; k < start[c + 1]; ++k) {
            const std::size_t j = order[k];
            if (set.classes[j] == set.classes[i]) continue;
            double ddx = std::fabs(set.coords[2 * j] - x), ddy = std::fabs(set.coords[2 * j + 1] - y);
            if (torus) ddx = std::min(ddx, 1 - ddx), ddy = std::min(ddy, 1 - ddy);
            best = std::min(best, std::hypot(ddx, ddy));
          }
        }
  }
  return best / spacing;
}

DensityFunction summed_density(const std::vector<DensityFunction>& densities) {
  if (densities.empty()) return {};
  return [densities](double x, double y) {
    double sum = 0;
    for (const DensityFunction& d : densities)
      if (d) sum += d(x, y);
    return sum;
  };
}

std::vector<ClassShare> class_shares(const std::vector<tools::PointSet>& sets,
                                     const std::vector<DensityFunction>& densities) {
  std::size_t labels = 0;  // largest label + 1
  for (const tools::PointSet& set : sets)
    for (std::uint8_t k : set.classes) labels = std::max(labels, std::size_t(k) + 1);
  if (labels == 0) throw InvalidInput("class densities given, but the sets hold no points");
  if (densities.size() < labels)  // more: classes after the last label hold no points (a density of 0)
    throw InvalidInput(std::to_string(densities.size()) +
                       " class densities given, but the points' classes run 0 to " +
                       std::to_string(labels - 1) + " (" + std::to_string(labels) +
                       " classes): give one density per class, class 0 first");
  const std::size_t classes = densities.size();
  std::vector<ClassShare> shares(classes);
  double total = 0;
  std::vector<double> mean(classes);
  for (std::size_t k = 0; k < classes; ++k) {
    const std::string name = "class " + std::to_string(k) + "'s density";
    if (!densities[k]) throw InvalidInput(name + " is empty");
    // density_scale clamps what it reads; a density the windows would refuse is named here by class.
    constexpr int kProbe = 64;
    for (int j = 0; j < kProbe; ++j)
      for (int i = 0; i < kProbe; ++i) {
        const double v = densities[k]((i + 0.5) / kProbe, (j + 0.5) / kProbe);
        if (!std::isfinite(v) || v < 0) throw InvalidInput(name + " is negative or not finite");
      }
    mean[k] = density_scale(densities[k]).first;
    total += mean[k];
    shares[k].cls = static_cast<std::uint8_t>(k);
  }
  if (!(total > 0)) throw InvalidInput("every class density is zero everywhere");
  for (const tools::PointSet& set : sets)
    for (std::uint8_t k : set.classes) ++shares[k].count;
  for (std::size_t k = 0; k < classes; ++k) {
    ClassShare& s = shares[k];
    if (!(mean[k] > 0) && s.count > 0)
      throw InvalidInput("class " + std::to_string(k) + "'s density is zero everywhere, but the class has " +
                         std::to_string(s.count) + " points");
    s.share = mean[k] / total;
    double variance = 0;
    for (const tools::PointSet& set : sets) {
      const double n = static_cast<double>(set.size());
      s.expected += n * s.share;
      variance += n * s.share * (1 - s.share);
    }
    s.sd = std::sqrt(variance);
    // sd = 0: a share of 0 (no points, checked above) or 1 (every point, the others having none).
    s.z = s.sd > 0 ? (static_cast<double>(s.count) - s.expected) / s.sd : 0.0;
  }
  return shares;
}

ClassesReport analyze_classes(const std::vector<tools::PointSet>& sets, const AnalysisOptions& options,
                              const ClassEnergy& energy,
                              const std::vector<DensityFunction>& class_densities) {
  ClassesReport out;
  for (const tools::PointSet& set : sets)
    if (set.classes.size() != set.size())
      throw InvalidInput("every set of labelled points needs its classes");
  // The closest pair of different classes is searched in the unit square's cells and lengths.
  if (!sets.empty() && !unit_sides(unit_measure_sides(options.extent, sets.front().dim)))
    throw InvalidInput(
        "labelled points (classes) are analysed in the unit square only: give them the aspect 1 (the "
        "whole set's measures are stretched then)");
  const bool own = !class_densities.empty();
  if (own) out.shares = class_shares(sets, class_densities);
  // The closest pair of different classes: in local spacings of the classes' summed density, if they have
  // their own.
  const DensityFunction pair_density = own ? summed_density(class_densities) : options.density;
  double closest = HUGE_VAL;
  std::vector<std::uint8_t> present;
  for (const tools::PointSet& set : sets) {
    closest = std::min(closest, cross_class_closest(set, options.torus, pair_density));
    for (std::uint8_t k : classes_present(set))
      if (std::find(present.begin(), present.end(), k) == present.end()) present.push_back(k);
  }
  std::sort(present.begin(), present.end());
  // NaN: no set has two classes (with a density: none within two local spacings of each other)
  out.cross_class_closest = closest < HUGE_VAL ? closest : std::nan("");
  AnalysisOptions class_options = options;
  for (std::uint8_t k : present) {
    std::vector<tools::PointSet> subsets;
    for (const tools::PointSet& set : sets) {
      subsets.push_back(class_subset(set, k));
      if (subsets.back().size() < 2) subsets.pop_back();
    }
    if (subsets.empty()) {
      out.too_small.push_back(k);
      continue;
    }
    if (own) class_options.density = class_densities[k];
    AnalysisReport report = analyze(subsets, class_options);
    if (energy) report.energy_per_point = energy(k, subsets), report.has_energy = true;
    out.classes.push_back(k);
    out.reports.push_back(std::move(report));
  }
  return out;
}

std::string format_class_shares(const ClassesReport& report) {
  if (report.shares.empty()) return "";
  std::string s =
      "class counts against their densities' shares (± binomial sd; a sampler that fixes counts: |z| << 1)\n";
  for (const ClassShare& c : report.shares) {
    char line[200];
    std::snprintf(line, sizeof line,
                  "  class %-3u %10zu points  expected %12.1f ± %-8.1f share %.4f  z %+.2f\n",
                  unsigned(c.cls), c.count, c.expected, c.sd, c.share, c.z);
    s += line;
  }
  return s;
}

std::string classes_json(const ClassesReport& report, const std::vector<std::string>& inputs) {
  JsonWriter number;
  number.value(report.cross_class_closest);  // null when no two classes meet
  std::string json = "{\"cross_class_closest\": " + number.str() + ", \"classes\": [";
  for (std::size_t c = 0; c < report.classes.size(); ++c)
    json += std::string(c ? ", " : "") + "{\"class\": " + std::to_string(report.classes[c]) +
            ", \"metrics\": " + metrics_json(report.reports[c], inputs) + "}";
  json += "], \"too_small\": [";  // present, but with fewer than 2 points in every set: not analysed
  for (std::size_t c = 0; c < report.too_small.size(); ++c)
    json += std::string(c ? ", " : "") + std::to_string(report.too_small[c]);
  json += "]";
  if (!report.shares.empty()) {  // only with class densities: the output without them is unchanged
    const auto number = [](double v) {
      JsonWriter w;
      w.value(v);
      return w.str();
    };
    json += ", \"shares\": [";
    for (std::size_t c = 0; c < report.shares.size(); ++c) {
      const ClassShare& s = report.shares[c];
      json += std::string(c ? ", " : "") + "{\"class\": " + std::to_string(s.cls) +
              ", \"share\": " + number(s.share) + ", \"count\": " + std::to_string(s.count) +
              ", \"expected\": " + number(s.expected) + ", \"sd\": " + number(s.sd) +
              ", \"z\": " + number(s.z) + "}";
    }
    json += "]";
  }
  return json + "}\n";
}

}  // namespace kdm::analysis
