// Several classes by constrained KDM sampling, one class at a time; see kdm/generator/multiclass.h.
#include "kdm/generator/multiclass.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

namespace kdm::gen {
namespace {

/// The mean of `density` over the unit domain: an image's mean value, a function's mean over a grid of
/// 256² (2D) or 64³ (3D) midpoints (through its batch function when it has one), 1 for a constant.
double mean_of(const Density& density, int dim) {
  if (density.image) {
    double sum = 0;
    for (float v : density.image->values) sum += v;
    return sum / double(density.image->values.size());
  }
  if (!density.function) return 1;
  const int side = dim == 2 ? 256 : 64;
  const std::size_t count = std::size_t(side) * side * (dim == 3 ? side : 1);
  std::vector<double> u, values(count);
  if (density.batch) u.reserve(count * std::size_t(dim));
  double at[3] = {0, 0, 0};
  std::size_t i = 0;
  for (int z = 0; z < (dim == 3 ? side : 1); ++z)
    for (int y = 0; y < side; ++y)
      for (int x = 0; x < side; ++x, ++i) {
        at[0] = (x + 0.5) / side, at[1] = (y + 0.5) / side, at[2] = (z + 0.5) / side;
        if (density.batch)
          u.insert(u.end(), at, at + dim);
        else
          values[i] = density.function(at);
      }
  for (std::size_t first = 0; density.batch && first < count; first += kDensityBatch)
    density.batch(&u[first * std::size_t(dim)], std::min(kDensityBatch, count - first), &values[first]);
  double sum = 0;
  for (double v : values) {
    if (!std::isfinite(v) || v < 0) throw InvalidArgument("a class's density is negative or not finite");
    sum += v;
  }
  return sum / double(count);
}

std::uint64_t class_seed(std::uint64_t seed, std::size_t k) {
  // SplitMix64 of the pair: the class runs' random streams are unrelated, and class 0 keeps `seed`.
  if (k == 0) return seed;
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull * (k + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/// For each stray (a point relabelled from class from[j] to its present class c because from[j]'s density
/// is zero there), relabels the nearest point of class c where from[j]'s density is positive as from[j]:
/// every class ends with the count it was sampled with. A class with no such point left keeps the loss
/// (`counts` follow the labels). Distances are plain (a torus's nearest point across its seam may be
/// passed over, which changes which point swaps, not the counts). Points are bucketed on a grid of about
/// four a cell and searched shell by shell outwards.
template <class Value>
void give_back_counts(ClassSample& s, const std::vector<std::size_t>& strays,
                      const std::vector<std::uint8_t>& from, const Value& value) {
  if (strays.empty()) return;
  const int dim = s.dim;
  const std::size_t n = s.classes.size();
  double lo[3] = {0, 0, 0}, cell[3] = {1, 1, 1};
  int side = std::max(1, static_cast<int>(std::pow(double(n) / 4, 1.0 / dim)));
  for (int a = 0; a < dim; ++a) {
    double low = HUGE_VAL, high = -HUGE_VAL;
    for (std::size_t i = 0; i < n; ++i)
      low = std::min(low, s.points[i * dim + a]), high = std::max(high, s.points[i * dim + a]);
    lo[a] = low, cell[a] = std::max((high - low) / side, 1e-300);
  }
  const auto coordinate = [&](std::size_t i, int a) {
    return std::clamp(static_cast<int>((s.points[i * dim + a] - lo[a]) / cell[a]), 0, side - 1);
  };
  std::size_t cells = 1;
  for (int a = 0; a < dim; ++a) cells *= std::size_t(side);
  std::vector<std::size_t> first(cells + 1, 0), members(n);
  const auto cell_of = [&](std::size_t i) {
    std::size_t c = 0;
    for (int a = dim - 1; a >= 0; --a) c = c * std::size_t(side) + std::size_t(coordinate(i, a));
    return c;
  };
  for (std::size_t i = 0; i < n; ++i) ++first[cell_of(i) + 1];
  for (std::size_t c = 0; c < cells; ++c) first[c + 1] += first[c];
  std::vector<std::size_t> next(first.begin(), first.end() - 1);
  for (std::size_t i = 0; i < n; ++i) members[next[cell_of(i)]++] = i;

  std::vector<char> taken(n, 0);
  for (std::size_t i : strays) taken[i] = 1;  // its class is the density's there already
  const double finest = *std::min_element(cell, cell + dim);
  for (std::size_t j = 0; j < strays.size(); ++j) {
    const std::size_t p = strays[j], c = s.classes[p], lost = from[j];
    int centre[3] = {0, 0, 0};
    for (int a = 0; a < dim; ++a) centre[a] = coordinate(p, a);
    std::size_t best = n;
    double best_d2 = HUGE_VAL;
    for (int r = 0; r <= side; ++r) {
      // The cells at Chebyshev distance r from the centre: none nearer than (r - 1) cells.
      const int span = 2 * r + 1;
      std::size_t count = 1;
      for (int a = 0; a < dim; ++a) count *= std::size_t(span);
      for (std::size_t k = 0; k < count; ++k) {
        int at[3] = {0, 0, 0};
        bool shell = false, inside = true;
        std::size_t rest = k, index = 0;
        for (int a = 0; a < dim; ++a) {
          const int offset = static_cast<int>(rest % std::size_t(span)) - r;
          rest /= std::size_t(span);
          shell = shell || std::abs(offset) == r;
          at[a] = centre[a] + offset;
          inside = inside && at[a] >= 0 && at[a] < side;
        }
        if (!shell || !inside) continue;
        for (int a = dim - 1; a >= 0; --a) index = index * std::size_t(side) + std::size_t(at[a]);
        for (std::size_t m = first[index]; m < first[index + 1]; ++m) {
          const std::size_t i = members[m];
          if (s.classes[i] != c || taken[i]) continue;
          double d2 = 0;
          for (int a = 0; a < dim; ++a)
            d2 += (s.points[p * dim + a] - s.points[i * dim + a]) *
                  (s.points[p * dim + a] - s.points[i * dim + a]);
          if (d2 < best_d2 && value(lost, &s.points[i * dim]) > 0) best_d2 = d2, best = i;
        }
      }
      if (best < n && std::sqrt(best_d2) <= r * finest) break;  // the next shell lies further
    }
    --s.counts[lost], ++s.counts[c];
    if (best == n) continue;
    s.classes[best] = static_cast<std::uint8_t>(lost), taken[best] = 1;
    --s.counts[c], ++s.counts[lost];
  }
}

}  // namespace

std::vector<std::int64_t> class_counts(const SamplerOptions& options, const std::vector<Density>& densities,
                                       std::int64_t n) {
  if (n < 0) throw InvalidArgument("point count must be >= 0, got " + std::to_string(n));
  std::vector<double> cumulative;
  double total = 0;
  for (const Density& d : densities) cumulative.push_back(total += mean_of(d, options.dim));
  if (!(total > 0)) throw InvalidArgument("every class's density is zero: nothing to sample");
  std::vector<std::int64_t> counts;
  std::int64_t before = 0;
  for (double c : cumulative) {
    const auto upto = static_cast<std::int64_t>(std::llround(double(n) * c / total));
    counts.push_back(upto - before);
    before = upto;
  }
  return counts;
}

Density sum_of_densities(const std::vector<Density>& densities, int dim) {
  bool all_constant = true, images = true;
  int width = 0, height = 0;
  for (const Density& d : densities) {
    if (!d.function) continue;
    all_constant = false;
    if (!d.image || (width && (d.image->width != width || d.image->height != height))) images = false;
    if (d.image) width = d.image->width, height = d.image->height;
  }
  if (all_constant) return Density::constant();
  if (images) {  // one image: the sampler reads its values itself
    std::vector<float> sum(std::size_t(width) * height, 0.0f);
    for (const Density& d : densities)
      for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += d.function ? d.image->values[i] : 1.0f;
    return Density::from_values(width, height, std::move(sum));
  }
  Density sum;
  sum.thread_safe = true;
  for (const Density& d : densities) {
    sum.thread_safe = sum.thread_safe && (d.thread_safe || !d.function);
    for (int a = 0; a < 3; ++a)
      sum.native_resolution[a] = std::max(sum.native_resolution[a], d.native_resolution[a]);
  }
  auto parts = std::make_shared<std::vector<Density>>(densities);
  sum.function = [parts](const double* u) {
    double s = 0;
    for (const Density& d : *parts) s += d.function ? d.function(u) : 1.0;
    return s;
  };
  const bool batch =
      std::any_of(densities.begin(), densities.end(), [](const Density& d) { return bool(d.batch); });
  if (!batch) return sum;
  // Each part's batch, or its function at each position: the same sums, added in the same order.
  sum.thread_safe = false;  // read through the batch on one thread anyway
  sum.batch = [parts, dim](const double* u, std::size_t count, double* out) {
    std::fill(out, out + count, 0.0);
    std::vector<double> values(count);
    for (const Density& d : *parts) {
      if (d.batch)
        d.batch(u, count, values.data());
      else
        for (std::size_t i = 0; i < count; ++i)
          values[i] = d.function ? d.function(u + i * std::size_t(dim)) : 1.0;
      for (std::size_t i = 0; i < count; ++i) out[i] += values[i];
    }
  };
  return sum;
}

ClassSample sample_classes(const SamplerOptions& options, const std::vector<Density>& densities,
                           int union_sweeps) {
  if (union_sweeps < 0) throw InvalidArgument("union sweeps must be >= 0");
  if (densities.empty() || densities.size() > 8)
    throw InvalidArgument("a sample takes 1 to 8 classes, got " + std::to_string(densities.size()));
  if (options.n <= 0) throw InvalidArgument("a sample with classes needs a point count n > 0");
  if (!options.fixed_points.empty() || !options.initial_points.empty())
    throw InvalidArgument("a sample with classes takes no fixed or initial points");
  ClassSample result;
  result.dim = options.dim;
  result.counts = class_counts(options, densities, options.n);
  std::vector<Density> prefix;
  for (std::size_t k = 0; k < densities.size(); ++k) {
    prefix.push_back(densities[k]);
    const std::int64_t count = result.counts[k];
    if (count == 0) continue;
    SamplerOptions o = options;
    o.n = count;
    o.seed = class_seed(options.seed, k);
    o.fixed_points = result.points;  // the earlier classes, which this one fills in around
    if (options.progress)
      o.progress = [&options, k, total = densities.size()](double f) {
        options.progress((double(k) + f) / double(total));
      };
    SampleResult r = sample(o, prefix.size() == 1 ? prefix.front() : sum_of_densities(prefix, options.dim));
    result.points.insert(result.points.end(), r.points.begin(), r.points.end());
    result.classes.insert(result.classes.end(), r.size(), static_cast<std::uint8_t>(k));
    result.reports.push_back(std::move(r.report));
  }
  if (union_sweeps > 0 && densities.size() > 1) {  // all classes together, in their order
    SamplerOptions o = options;
    o.n = 0;
    o.seed = class_seed(options.seed, densities.size());
    o.initial_points = result.points;
    o.sweeps = union_sweeps;
    o.burn_in_sweeps = 0;
    o.progress = nullptr;
    SampleResult r = sample(o, sum_of_densities(densities, options.dim));
    result.points = std::move(r.points);
    result.reports.push_back(std::move(r.report));
  }
  // A class's points where its own density is zero go to the class of the largest density there. Class k
  // fills in around the earlier classes at their summed density, so it takes a gap they left where its
  // own density is zero, and the joint sweeps move every point by the sum: cyan dots in a black area.
  // Each such point's new class then gives its original class back the nearest of its own points where
  // that class's density is positive, so that every class keeps its count.
  if (densities.size() > 1) {
    const auto value = [&](std::size_t k, const double* u) {
      return densities[k].function ? densities[k].function(u) : 1.0;
    };
    const std::size_t dim = std::size_t(options.dim);
    std::vector<std::size_t> strays;
    std::vector<std::uint8_t> from;
    for (std::size_t i = 0; i < result.classes.size(); ++i) {
      const double* u = &result.points[i * dim];
      const std::size_t own = result.classes[i];
      if (value(own, u) > 0) continue;
      std::size_t best = own;
      double best_value = 0;
      for (std::size_t k = 0; k < densities.size(); ++k) {
        const double v = value(k, u);
        if (v > best_value) best = k, best_value = v;
      }
      if (best == own) continue;  // no class has density here (the sum's edge): it keeps its class
      result.classes[i] = static_cast<std::uint8_t>(best);
      strays.push_back(i), from.push_back(static_cast<std::uint8_t>(own));
    }
    const bool moved = !strays.empty();
    give_back_counts(result, strays, from, value);
    if (moved) {  // class 0's points first again, each class's in their order
      std::vector<std::size_t> order(result.classes.size());
      for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
      std::stable_sort(order.begin(), order.end(),
                       [&](std::size_t a, std::size_t b) { return result.classes[a] < result.classes[b]; });
      std::vector<double> points(result.points.size());
      std::vector<std::uint8_t> classes(result.classes.size());
      for (std::size_t i = 0; i < order.size(); ++i) {
        classes[i] = result.classes[order[i]];
        std::copy_n(&result.points[order[i] * dim], dim, &points[i * dim]);
      }
      result.points = std::move(points), result.classes = std::move(classes);
    }
  }
  return result;
}

}  // namespace kdm::gen
