#include "sampler/setup.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <memory>
#include <sstream>

#include "kdm/runtime/check.h"
#include "platform/huge_pages.h"
#include "platform/parallel.h"
#include "platform/thread_count.h"
#include "sampler/kernel.h"

namespace kdm::gen {
namespace {

template <int D>
std::string format_position(const double* u) {
  std::ostringstream s;
  s << "(";
  for (int k = 0; k < D; ++k) s << (k ? ", " : "") << u[k];
  s << ")";
  return s.str();
}

/// Where normalised coordinate u falls between an image's pixel centres, which sit at (i + 1/2) / pixels,
/// clamped at the edges (columns from the left, rows from the bottom).
struct PixelLerp {
  int lo, hi;
  double t;
  PixelLerp(double u, int pixels) {
    const double f = std::clamp(u * pixels - 0.5, 0.0, pixels - 1.0);
    lo = static_cast<int>(f);
    hi = std::min(lo + 1, pixels - 1);
    t = f - lo;
  }
};

/// An image density between four pixels: the one formula of Density::from_values()'s function and of
/// sample_image(), so both give the same bits.
inline double image_value(const DensityImage& image, const PixelLerp& x, const PixelLerp& y) {
  auto at = [&](int col, int row) { return double(image.values[std::size_t(row) * image.width + col]); };
  return (1 - y.t) * ((1 - x.t) * at(x.lo, y.lo) + x.t * at(x.hi, y.lo)) +
         y.t * ((1 - x.t) * at(x.lo, y.hi) + x.t * at(x.hi, y.hi));
}

/// A volume density between eight voxels: Density::from_volume()'s function, the bilinear image_value()
/// of the two slices around u_z blended along z.
inline double volume_value(const DensityVolume& v, const PixelLerp& x, const PixelLerp& y,
                           const PixelLerp& z) {
  auto at = [&](int col, int row, int slice) {
    return double(v.values[(std::size_t(slice) * v.height + row) * v.width + col]);
  };
  auto slice = [&](int k) {
    return (1 - y.t) * ((1 - x.t) * at(x.lo, y.lo, k) + x.t * at(x.hi, y.lo, k)) +
           y.t * ((1 - x.t) * at(x.lo, y.hi, k) + x.t * at(x.hi, y.hi, k));
  };
  return (1 - z.t) * slice(z.lo) + z.t * slice(z.hi);
}

/// Samples the density at every node of `grid` (averaging supersamples where the source is finer), on up
/// to `threads` threads when the density may be called concurrently, or through Density::batch (one
/// thread). Throws InvalidArgument naming the first node (in storage order) where the density is not
/// finite or negative, whatever the thread count.
template <int D>
std::vector<float> sample_function(const Grid<D>& grid, const Density& density, int threads) {
  std::vector<float> rho = vector_on_huge_pages<float>(static_cast<std::size_t>(grid.size()), 0.0f);
  std::array<int, D> sub{};
  int subsamples = 1;
  for (int k = 0; k < D; ++k) {
    sub[k] = std::clamp((density.native_resolution[k] + grid.dims[k] - 1) / std::max(1, grid.dims[k]), 1, 8);
    subsamples *= sub[k];
  }
  // Subsample s of `node`: the one formula of both paths below, so they read the same positions.
  const auto position = [&](const std::array<int, D>& node, int s, double* u) {
    int rest = s;
    for (int k = 0; k < D; ++k) {
      const int j = rest % sub[k];
      rest /= sub[k];
      u[k] = (node[k] + (j + 0.5) / sub[k]) / grid.dims[k];
    }
  };
  // The node of `row` (all axes but the first) and column x.
  const auto node_at = [&](std::int64_t row, int x) {
    std::array<int, D> node{};
    node[0] = x;
    for (int k = 1; k < D; ++k) {
      node[k] = static_cast<int>(row % grid.dims[k]);
      row /= grid.dims[k];
    }
    return node;
  };
  const auto refusal = [](double v, const double* u) {
    return std::string(std::isfinite(v) ? "density is negative at " : "density is not finite at ") +
           format_position<D>(u);
  };
  double peak = 0;
  if (density.batch) {
    // Runs of whole nodes, kDensityBatch positions at most (a node has at most 8^3 subsamples).
    const std::int64_t run = std::int64_t(kDensityBatch) / subsamples;
    std::vector<double> u(static_cast<std::size_t>(run * subsamples * D));
    std::vector<double> values(static_cast<std::size_t>(run * subsamples));
    for (std::int64_t first = 0; first < grid.size(); first += run) {
      const std::int64_t nodes = std::min(run, grid.size() - first);
      for (std::int64_t i = 0; i < nodes; ++i) {
        const std::array<int, D> node =
            node_at((first + i) / grid.dims[0], static_cast<int>((first + i) % grid.dims[0]));
        for (int s = 0; s < subsamples; ++s)
          position(node, s, &u[static_cast<std::size_t>((i * subsamples + s) * D)]);
      }
      density.batch(u.data(), static_cast<std::size_t>(nodes * subsamples), values.data());
      for (std::int64_t i = 0; i < nodes; ++i) {
        double sum = 0;
        for (int s = 0; s < subsamples; ++s) {
          const std::size_t at = static_cast<std::size_t>(i * subsamples + s);
          const double v = values[at];
          if (!std::isfinite(v) || v < 0) throw InvalidArgument(refusal(v, &u[at * D]));
          sum += v;
        }
        peak = std::max(peak, sum / subsamples);
        rho[static_cast<std::size_t>(first + i)] = static_cast<float>(sum / subsamples);
      }
    }
  } else {
    // Rows along the first axis, cut into one stretch per part; each part stops at its first bad node.
    const std::int64_t rows = grid.size() / grid.dims[0];
    const int parts = density.thread_safe && grid.size() >= (1 << 16) ? std::max(1, threads) : 1;
    std::vector<std::int64_t> bad_node(static_cast<std::size_t>(parts), grid.size());
    std::vector<std::string> bad_message(static_cast<std::size_t>(parts));
    std::vector<double> part_peak(static_cast<std::size_t>(parts), 0.0);
    for_each_part(parts, parts > 1, [&](int part, int) {
      for (std::int64_t row = rows * part / parts; row < rows * (part + 1) / parts; ++row) {
        for (int x = 0; x < grid.dims[0]; ++x) {
          const std::array<int, D> node = node_at(row, x);
          double sum = 0;
          for (int s = 0; s < subsamples; ++s) {
            double u[3] = {0, 0, 0};
            position(node, s, u);
            const double v = density.function(u);
            if (!std::isfinite(v) || v < 0) {
              bad_node[part] = row * grid.dims[0] + x;
              bad_message[part] = refusal(v, u);
              return;
            }
            sum += v;
          }
          part_peak[part] = std::max(part_peak[part], sum / subsamples);
          rho[static_cast<std::size_t>(row * grid.dims[0] + x)] = static_cast<float>(sum / subsamples);
        }
      }
    });
    const auto first_bad = std::min_element(bad_node.begin(), bad_node.end());
    if (*first_bad < grid.size()) throw InvalidArgument(bad_message[first_bad - bad_node.begin()]);
    peak = *std::max_element(part_peak.begin(), part_peak.end());
  }
  // Nodes keep floats: a density far outside their range would become infinite or zero.
  if (peak > kMaxDensityValue || (peak > 0 && peak < kMinDensityPeak)) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "density peaks at %.3g, outside %g ... %g (kept as floats); only its shape matters, so %s "
                  "it by a constant",
                  peak, kMinDensityPeak, kMaxDensityValue, peak > 1 ? "divide" : "multiply");
    throw InvalidArgument(text);
  }
  return rho;
}

/// sample_function() for an image density, without a call per node: each column's and row's PixelLerp
/// worked out once, and the same image_value() as the function, so every node gets the same bits.
/// At 65,536 points on examples/sphere.png (two 2368² grids) the calls took 0.2 s; this takes 0.04 s.
std::vector<float> sample_image(const Grid<2>& grid, const Density& density, int threads) {
  const DensityImage& image = *density.image;
  if (image.width <= 0 || image.height <= 0 ||
      image.values.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height))
    throw InvalidArgument("density image: its size does not match its values");
  // Each subsample's place between pixels along each axis, worked out once per column and per row.
  auto lerps = [](int nodes, int sub, int pixels) {
    std::vector<PixelLerp> out;
    out.reserve(static_cast<std::size_t>(nodes) * sub);
    for (int i = 0; i < nodes; ++i)
      for (int j = 0; j < sub; ++j) out.emplace_back((i + (j + 0.5) / sub) / nodes, pixels);
    return out;
  };
  const int* native = density.native_resolution;  // as sample_function() takes it
  const int sub_x = std::clamp((native[0] + grid.dims[0] - 1) / std::max(1, grid.dims[0]), 1, 8);
  const int sub_y = std::clamp((native[1] + grid.dims[1] - 1) / std::max(1, grid.dims[1]), 1, 8);
  const std::vector<PixelLerp> xs = lerps(grid.dims[0], sub_x, image.width);
  const std::vector<PixelLerp> ys = lerps(grid.dims[1], sub_y, image.height);
  std::vector<float> rho = vector_on_huge_pages<float>(static_cast<std::size_t>(grid.size()), 0.0f);
  const int parts = grid.size() >= (1 << 16) ? std::max(1, threads) : 1;
  for_each_part(parts, parts > 1, [&](int part, int) {
    for (std::int64_t row = grid.dims[1] * std::int64_t(part) / parts;
         row < grid.dims[1] * std::int64_t(part + 1) / parts; ++row)
      for (int x = 0; x < grid.dims[0]; ++x) {
        double sum = 0;
        for (int sy = 0; sy < sub_y; ++sy)  // the subsamples in sample_function()'s order
          for (int sx = 0; sx < sub_x; ++sx)
            sum += image_value(image, xs[std::size_t(x) * sub_x + sx], ys[std::size_t(row) * sub_y + sy]);
        rho[static_cast<std::size_t>(row * grid.dims[0] + x)] = static_cast<float>(sum / (sub_x * sub_y));
      }
  });
  for (float v : rho)
    if (!(std::isfinite(v) && v >= 0))
      throw InvalidArgument("density image holds a non-finite or negative value");
  return rho;
}

/// The density at every node of `grid`: constant (1), an image's, or a function's.
template <int D>
std::vector<float> sample_density(const Grid<D>& grid, const Density& density, int threads) {
  if constexpr (D == 2)
    if (density.image) return sample_image(grid, density, threads);
  if (!density.function) return vector_on_huge_pages<float>(static_cast<std::size_t>(grid.size()), 1.0f);
  return sample_function<D>(grid, density, threads);
}

/// The refusal of a domain whose finest grid is one node wide across its short side. That leaves the chain
/// no room across it: measured with a uniform density, the points then bunch up (300 at aspect ratio
/// 5000: all in the left half), while two nodes sample it evenly.
InvalidArgument too_narrow(const SamplerOptions& o) {
  double min_extent = o.extent[0], max_extent = o.extent[0];
  for (int k = 1; k < o.dim; ++k)
    min_extent = std::min(min_extent, o.extent[k]), max_extent = std::max(max_extent, o.extent[k]);
  std::ostringstream s;
  s << "the domain is too narrow for " << o.n << (o.n == 1 ? " point" : " points") << ": its long side is "
    << max_extent / min_extent
    << " times its short side, which would be one grid node wide, and the sampler needs two ("
    << (o.dim == 2 ? "sides at most about 10 times the point count apart"
                   : "a short side of at least about 0.35 of a point spacing")
    << "); ask for more points or a squarer domain";
  return InvalidArgument(s.str());
}

/// The thinnest 3D tube sampled, its short sides in point spacings (the sampler stalls from about 0.55).
constexpr double kThinnestTube = 0.6;

/// The refusal of a 3D domain whose two short sides are `sides` point spacings across (their mean).
InvalidArgument too_thin(const SamplerOptions& o, double sides) {
  double min_extent = o.extent[0], max_extent = o.extent[0];
  for (int k = 1; k < o.dim; ++k)
    min_extent = std::min(min_extent, o.extent[k]), max_extent = std::max(max_extent, o.extent[k]);
  std::ostringstream s;
  s << "the domain is too narrow for " << o.n << (o.n == 1 ? " point" : " points") << ": its long side is "
    << max_extent / min_extent << " times its short sides, which would be " << std::setprecision(2) << sides
    << " of a point spacing across, and in 3D the "
    << "sampler needs " << kThinnestTube
    << " (a tube at most about 4.6 times the point count longer than "
       "wide); ask for more points or a squarer domain";
  return InvalidArgument(s.str());
}

/// The dims (in double: an extreme aspect ratio overflows an int) and pyramid levels of the finest grid
/// with about `shortest` nodes along the domain's shortest side; returns their product.
template <int D>
double grid_dims(const SamplerOptions& o, double shortest, int& levels, double (&dims)[D]) {
  double min_extent = o.extent[0];
  for (int k = 1; k < D; ++k) min_extent = std::min(min_extent, o.extent[k]);
  levels = 1;
  while (shortest / std::ldexp(1.0, levels) >= o.coarsest_grid) ++levels;
  const double unit = std::ldexp(1.0, levels - 1);
  double nodes = 1;
  for (int k = 0; k < D; ++k) {
    dims[k] = unit * std::max(1.0, std::round(shortest * o.extent[k] / min_extent / unit));
    nodes *= dims[k];
  }
  return nodes;
}

/// The finest grid for `shortest` (grid_dims). Past max_grid_nodes it is refused, saying how many points
/// fit: `most_points()`, or where that is NaN (nothing known of the density's peak) the count scaled by
/// the nodes, which a density whose peak the grid resolves better as it grows overestimates.
template <int D, class MostPoints>
Grid<D> make_grid(const SamplerOptions& o, double shortest, int& levels, MostPoints most_points) {
  double dims[D];
  const double nodes = grid_dims<D>(o, shortest, levels, dims);
  double fewest = dims[0];
  for (int k = 1; k < D; ++k) fewest = std::min(fewest, dims[k]);
  if (!(nodes <= double(o.max_grid_nodes))) {
    if (fewest < 2) throw too_narrow(o);  // refining the grid only makes it larger: say what is wrong
    double most = most_points();
    if (std::isnan(most)) most = double(o.n) * double(o.max_grid_nodes) / nodes;
    std::ostringstream s;
    s << "the density needs a computational grid of " << nodes << " nodes, more than the limit of "
      << o.max_grid_nodes << ": about " << std::setprecision(3) << most
      << " points at most with this density and domain (ask for fewer points, a smaller dynamic range or "
         "a squarer domain)";
    throw InvalidArgument(s.str());
  }
  Grid<D> g;
  g.torus = o.domain == Domain::kTorus;
  for (int k = 0; k < D; ++k) g.dims[k] = static_cast<int>(dims[k]);
  return g;
}

}  // namespace

void validate_options(const SamplerOptions& o) {
  if (o.dim != 2 && o.dim != 3) throw InvalidArgument("dimension must be 2 or 3");
  if (o.n < 0) throw InvalidArgument("point count must be > 0 (or 0 with a grid resolution > 0)");
  check_thread_count(o.threads);
  if (o.domain != Domain::kTorus && o.domain != Domain::kBox)
    throw InvalidArgument("domain must be Domain::kTorus or Domain::kBox, got " +
                          std::to_string(static_cast<int>(o.domain)));
  if (o.numerics != Numerics::kFast && o.numerics != Numerics::kOriginal)
    throw InvalidArgument("numerics must be Numerics::kFast or Numerics::kOriginal, got " +
                          std::to_string(static_cast<int>(o.numerics)));
  if (o.vector_lanes != 16 && o.vector_lanes != 8 && o.vector_lanes != 4)
    throw InvalidArgument("vector_lanes must be 16, 8 or 4, got " + std::to_string(o.vector_lanes));
  if (o.n == 0 && o.resolution <= 0)
    throw InvalidArgument("give a point count n > 0 or a grid resolution > 0");
  if (!(std::isfinite(o.temperature) && o.temperature >= 0))
    throw InvalidArgument("temperature must be a finite number >= 0");
  if (o.temperature > kMaxTemperature)
    throw InvalidArgument(
        "temperature must be at most 1000: past it nearly every move is refused and the "
        "points keep their starting places (100 and up already give near white noise)");
  if (!(std::isfinite(o.step) && o.step >= 0)) throw InvalidArgument("step must be a finite number >= 0");
  if (!(o.peak_density > 0 && o.peak_density <= 1)) throw InvalidArgument("peak density must be in (0, 1]");
  if (!(o.sigma_max == 0 || o.sigma_max >= 1))
    throw InvalidArgument("sigma_max must be 0 (automatic) or >= 1");
  if (o.sweeps < 0 || o.coarse_sweeps < 0 || o.coarsest_sweeps < 0 || o.burn_in_sweeps < 0)
    throw InvalidArgument("sweep counts must be >= 0");
  if (o.coarsest_grid < 4) throw InvalidArgument("coarsest grid must have at least 4 nodes per axis");
  for (int k = 0; k < o.dim; ++k)
    if (!(std::isfinite(o.extent[k]) && o.extent[k] > 0))
      throw InvalidArgument("domain extents must be finite and > 0");
  if (o.n > (std::int64_t(1) << 31)) throw InvalidArgument("point count is too large (limit 2^31)");
  if (o.fixed_points.size() % o.dim != 0)
    throw InvalidArgument("fixed points: coordinate count is not a multiple of the dimension");
  for (double u : o.fixed_points)
    if (!(u >= 0 && u < 1)) throw InvalidArgument("fixed points must lie in [0, 1) on every axis");
  if (!o.fixed_points.empty() && o.n == 0)
    throw InvalidArgument("constrained sampling needs a point count n > 0");
}

template <int D>
ModelSetup<D> build_model(const SamplerOptions& o, const Density& density) {
  validate_options(o);
  if (D == 3 && density.image)  // its values hold no z: 3D wants a function of (x, y, z)
    throw InvalidArgument("an image density (from_values) is 2D: sample it with dim 2, or give a function");
  if (D == 2 && density.volume)  // a volume's third axis would be read at u_z = 0 only
    throw InvalidArgument("a volume density (from_volume) is 3D: sample it with dim 3");
  if (density.volume && !density.function)
    throw InvalidArgument("a volume density needs its function (from_volume sets it)");
  if (density.batch && !density.function)
    throw InvalidArgument(
        "a density's batch function needs its function too (the same density point by point)");
  for (int k = 0; k < 3; ++k)
    if (density.native_resolution[k] < 0)
      throw InvalidArgument("density native_resolution must be >= 0 (0: unknown), got " +
                            std::to_string(density.native_resolution[k]));
  const int threads = thread_count(o.threads);
  ModelSetup<D> setup;
  setup.mass_per_point = std::pow(truncated_factor_integral(), D);
  double extent_product = 1, min_extent = o.extent[0];
  for (int k = 0; k < D; ++k) extent_product *= o.extent[k], min_extent = std::min(min_extent, o.extent[k]);
  const double aspect_product = extent_product / std::pow(min_extent, D);

  Grid<D> grid;
  std::vector<float> rho;
  int levels = 1;
  if (o.n > 0) {
    // Start from a probe of the density's mean and peak, then refine until max ρ <= peak_density.
    double peak_over_mean = 1;
    if (density.function) {
      Grid<D> probe;
      probe.torus = true;
      for (int k = 0; k < D; ++k) probe.dims[k] = D == 2 ? 64 : 24;
      const std::vector<float> p = sample_density<D>(probe, density, 1);
      double sum = 0, mx = 0;
      for (float v : p) sum += v, mx = std::max<double>(mx, v);
      if (!(mx > 0)) throw InvalidArgument("density is zero everywhere");
      peak_over_mean = mx / (sum / p.size());
    }
    const double fixed = double(o.fixed_points.size() / D), total = double(o.n) + fixed;
    const auto shortest_for = [&](double points, double peak_ratio) {
      return std::pow(points * setup.mass_per_point * peak_ratio / (o.peak_density * aspect_product),
                      1.0 / D);
    };
    double shortest = shortest_for(total, peak_over_mean);
    // An image's or a volume's peak over its mean is known from its values, whatever the grid resolves
    // of it, and a constant's is 1: the largest count whose grid (at that full peak) fits, with the
    // refinement's margin. (A volume's was a count scaled by the nodes: 373, then 14.7, for one voxel.)
    const auto most_points = [&] {
      const std::vector<float>* values = density.image    ? &density.image->values
                                         : density.volume ? &density.volume->values
                                                          : nullptr;
      if (!values && density.function) return std::nan("");
      double sum = 0, mx = 0;
      if (values)
        for (float v : *values) sum += v, mx = std::max<double>(mx, v);
      const double ratio = values ? mx / (sum / double(values->size())) : 1.0;
      const auto fits = [&](double points) {
        double dims[D];
        int grid_levels = 0;
        return grid_dims<D>(o, std::max(1.0, shortest_for(points, ratio) * 1.03), grid_levels, dims) <=
               double(o.max_grid_nodes);
      };
      double lo = std::floor(total), hi = lo + 1;  // lo: the largest count known to fit (0 if none)
      while (lo >= 1 && !fits(lo)) hi = lo, lo = std::floor(lo * 0.9);
      while (hi - lo > 1) {  // the same figure whatever count was asked
        const double mid = std::floor((lo + hi) / 2);
        (fits(mid) ? lo : hi) = mid;
      }
      return std::max(0.0, lo - fixed);
    };
    for (int attempt = 0;; ++attempt) {
      grid = make_grid<D>(o, std::max(1.0, shortest), levels, most_points);
      rho = sample_density<D>(grid, density, threads);
      double sum = 0, mx = 0;
      if (!density.function)
        sum = static_cast<double>(rho.size()), mx = 1;  // every node 1: what the loop would add up exactly
      else
        for (float v : rho) sum += v, mx = std::max<double>(mx, v);
      if (!(sum > 0)) throw InvalidArgument("density is zero everywhere");
      const double scale = total * setup.mass_per_point / sum;
      const double peak = mx * scale;
      if (peak <= o.peak_density * 1.02 || attempt == 6) {
        for (float& v : rho) v = static_cast<float>(v * scale);
        break;
      }
      shortest *= std::pow(peak / o.peak_density, 1.0 / D) * 1.01;
    }
    if (*std::min_element(grid.dims.begin(), grid.dims.end()) < 2) throw too_narrow(o);
    if (D == 3) {
      // A tube whose short sides are under about 0.55 point spacings is a line of points: every kernel
      // spans its cross-section many times over, so the first ones all raise E, and the exact count then
      // places each kernel by scanning every node (43 s for 1,000 points at 7,000 : 1; minutes beyond).
      double side[3];
      for (int k = 0; k < 3; ++k) side[k] = o.extent[k] / std::cbrt(extent_product) * std::cbrt(total);
      std::sort(side, side + 3);
      if (std::sqrt(side[0] * side[1]) < kThinnestTube) throw too_thin(o, std::sqrt(side[0] * side[1]));
    }
  } else {
    if (o.resolution < 2) throw InvalidArgument("grid resolution must be at least 2 nodes");
    const auto fits = [&](double resolution) {
      double dims[D];
      int grid_levels = 0;
      return grid_dims<D>(o, resolution, grid_levels, dims) <= double(o.max_grid_nodes);
    };
    if (!fits(o.resolution)) {  // make_grid's refusal speaks of a count of points, which none asked for
      double lo = 1, hi = o.resolution;  // lo: the largest resolution known to fit (1 if none does)
      while (hi - lo > 1) {
        const double mid = std::floor((lo + hi) / 2);
        (fits(mid) ? lo : hi) = mid;
      }
      double dims[D];
      int grid_levels = 0;
      std::ostringstream s;
      s << "grid resolution " << o.resolution << " needs a computational grid of "
        << grid_dims<D>(o, o.resolution, grid_levels, dims) << " nodes, more than the limit of "
        << o.max_grid_nodes << ": ";
      if (lo >= 2)
        s << "a resolution of at most " << lo << " fits this domain (ask for a smaller one)";
      else
        s << "no resolution fits this domain (ask for a squarer one)";
      throw InvalidArgument(s.str());
    }
    grid = make_grid<D>(o, o.resolution, levels, [] { return std::nan(""); });
    rho = sample_density<D>(grid, density, threads);
    const double mx = *std::max_element(rho.begin(), rho.end());
    if (!(mx > 0)) throw InvalidArgument("density is zero everywhere");
    for (float& v : rho) v = static_cast<float>(v * (o.peak_density / mx));
  }

  const auto [lo, hi] = std::minmax_element(rho.begin(), rho.end());
  setup.uniform = *lo == *hi;
  setup.levels.push_back({grid, std::move(rho)});
  for (int l = 1; l < levels; ++l) {
    const DensityGrid<D>& fine = setup.levels.back();
    DensityGrid<D> coarse;
    coarse.grid = fine.grid;
    for (int k = 0; k < D; ++k) coarse.grid.dims[k] /= 2;
    coarse.rho = box_sum_half<D>(fine.grid, fine.rho, threads);
    setup.levels.push_back(std::move(coarse));
  }
  return setup;
}

template <int D>
std::vector<float> box_sum_half(const Grid<D>& fine, const std::vector<float>& values, int threads) {
  std::array<int, D> coarse_dims{};
  std::int64_t size = 1;
  for (int k = 0; k < D; ++k) {
    KDM_CHECK(fine.dims[k] % 2 == 0);
    coarse_dims[k] = fine.dims[k] / 2, size *= coarse_dims[k];
  }
  std::vector<float> coarse = vector_on_huge_pages<float>(static_cast<std::size_t>(size), 0.0f);
  // Each coarse node adds its children in storage order, starting from 0: the same bits as adding every
  // fine value into its parent in one pass over the fine grid, for any number of threads.
  std::array<std::int64_t, (1 << D)> child{};
  for (int c = 0; c < (1 << D); ++c)
    for (int k = 0; k < D; ++k) child[c] += ((c >> k) & 1) * fine.stride(k);
  const std::int64_t rows = size / coarse_dims[0];
  const int parts = size >= (1 << 16) ? std::max(1, threads) : 1;
  for_each_part(parts, parts > 1, [&](int part, int) {
    for (std::int64_t row = rows * part / parts; row < rows * (part + 1) / parts; ++row) {
      std::int64_t first = 0, rest = row;  // the fine index of the row's first child
      for (int k = 1; k < D; ++k) {
        first += 2 * (rest % coarse_dims[k]) * fine.stride(k);
        rest /= coarse_dims[k];
      }
      float* out = coarse.data() + row * coarse_dims[0];
      for (int x = 0; x < coarse_dims[0]; ++x, first += 2) {
        float sum = 0;
        for (int c = 0; c < (1 << D); ++c) sum += values[static_cast<std::size_t>(first + child[c])];
        out[x] = sum;
      }
    }
  });
  return coarse;
}

template std::vector<float> box_sum_half<2>(const Grid<2>&, const std::vector<float>&, int);
template std::vector<float> box_sum_half<3>(const Grid<3>&, const std::vector<float>&, int);
template ModelSetup<2> build_model<2>(const SamplerOptions&, const Density&);
template ModelSetup<3> build_model<3>(const SamplerOptions&, const Density&);

Density Density::constant(double value) {
  if (!(std::isfinite(value) && value >= 0))
    throw InvalidArgument("a constant density must be a finite number >= 0, got " + std::to_string(value));
  Density d;
  d.function = [value](const double*) { return value; };
  d.thread_safe = true;
  return d;
}

namespace {

// A density's values: finite, >= 0 and not all zero, else InvalidArgument naming `what`.
void check_density_values(const std::vector<float>& values, const std::string& what) {
  bool any = false;
  for (float v : values) {
    if (!std::isfinite(v))
      throw InvalidArgument(what + " holds a value that is not finite or exceeds a float (3.4e38)");
    if (v < 0) throw InvalidArgument(what + " holds a negative value");
    any |= v > 0;
  }
  if (!any) throw InvalidArgument(what + " is zero everywhere");
}

}  // namespace

Density Density::from_values(int width, int height, std::vector<float> values) {
  if (width <= 0 || height <= 0)
    throw InvalidArgument("density image must be at least 1 x 1 values, got " + std::to_string(width) +
                          " x " + std::to_string(height));
  if (values.size() != static_cast<std::size_t>(width) * height)
    throw InvalidArgument("density image has the wrong number of values");
  check_density_values(values, "density image");
  Density d;
  d.thread_safe = true;  // the function below only reads its shared, immutable values
  d.native_resolution[0] = width;
  d.native_resolution[1] = height;
  auto image = std::make_shared<DensityImage>();
  image->width = width;
  image->height = height;
  image->values = std::move(values);
  d.image = image;
  d.function = [image](const double* u) {
    return image_value(*image, PixelLerp(u[0], image->width), PixelLerp(u[1], image->height));
  };
  return d;
}

Density Density::from_volume(int width, int height, int depth, std::vector<float> values) {
  if (width <= 0 || height <= 0 || depth <= 0)
    throw InvalidArgument("density volume must be at least 1 x 1 x 1 values, got " + std::to_string(width) +
                          " x " + std::to_string(height) + " x " + std::to_string(depth));
  // Three ints multiply past 2^64: no vector holds that many, so such sizes are wrong, not merely large.
  const std::size_t slice = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (slice > values.max_size() / static_cast<std::size_t>(depth))
    throw InvalidArgument("density volume of " + std::to_string(width) + " x " + std::to_string(height) +
                          " x " + std::to_string(depth) + " values is too large to index");
  if (values.size() != slice * static_cast<std::size_t>(depth))
    throw InvalidArgument("density volume has the wrong number of values: " + std::to_string(values.size()) +
                          " for " + std::to_string(width) + " x " + std::to_string(height) + " x " +
                          std::to_string(depth));
  check_density_values(values, "density volume");
  Density d;
  d.thread_safe = true;  // the function below only reads its shared, immutable values
  d.native_resolution[0] = width;
  d.native_resolution[1] = height;
  d.native_resolution[2] = depth;
  auto volume = std::make_shared<DensityVolume>();
  volume->width = width;
  volume->height = height;
  volume->depth = depth;
  volume->values = std::move(values);
  d.volume = volume;
  d.function = [volume](const double* u) {
    return volume_value(*volume, PixelLerp(u[0], volume->width), PixelLerp(u[1], volume->height),
                        PixelLerp(u[2], volume->depth));
  };
  return d;
}

}  // namespace kdm::gen
