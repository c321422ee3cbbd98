#include "spec_density.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

namespace kdm::tools {

SpecDensity::SpecDensity(const DensitySpec& s, const double r[4]) : spec(s) {
  std::copy(r, r + 4, rect);
  using Kind = DensitySpec::Kind;
  switch (spec.kind) {
    case Kind::kConstant:
      density.kind = QueryDensity::Kind::kConstant;
      density.constant = spec.constant;
      return;
    case Kind::kRamp:
    case Kind::kRadial:
      density.kind = QueryDensity::Kind::kCallback;
      density.callback = [](void* user, double x, double y) {
        const SpecDensity& d = *static_cast<const SpecDensity*>(user);
        const double u = std::clamp((x - d.rect[0]) / (d.rect[2] - d.rect[0]), 0.0, 1.0);
        const double v = std::clamp((y - d.rect[1]) / (d.rect[3] - d.rect[1]), 0.0, 1.0);
        return d.spec.map_at(u, v);
      };
      // Their bounds over a rectangle, from where it lies on the map (the ramp falls along u, the disc
      // away from its centre), widened by 1e-12 for exp's rounding: a tile far from the map's peak is then
      // judged without reading it (radial:1e9 over 4,096² tiles at 32,000 points per tile took hours).
      density.bounds = [](void* user, double x0, double y0, double x1, double y1, double* lo, double* hi) {
        const SpecDensity& d = *static_cast<const SpecDensity*>(user);
        const auto unit = [](double v, double from, double to) {
          return std::clamp((v - from) / (to - from), 0.0, 1.0);
        };
        const double u0 = unit(x0, d.rect[0], d.rect[2]), u1 = unit(x1, d.rect[0], d.rect[2]);
        const double v0 = unit(y0, d.rect[1], d.rect[3]), v1 = unit(y1, d.rect[1], d.rect[3]);
        double near = 0, far = 0;  // along u for a ramp; distances from the centre for a disc
        if (d.spec.kind == DensitySpec::Kind::kRamp) {
          near = u0, far = u1;
        } else {
          const double nu = std::max({u0 - 0.5, 0.0, 0.5 - u1}), nv = std::max({v0 - 0.5, 0.0, 0.5 - v1});
          const double fu = std::max(std::abs(u0 - 0.5), std::abs(u1 - 0.5));
          const double fv = std::max(std::abs(v0 - 0.5), std::abs(v1 - 0.5));
          near = std::sqrt(nu * nu + nv * nv), far = std::sqrt(fu * fu + fv * fv);
        }
        const double a = std::log(d.spec.range);
        const double scaled = d.spec.kind == DensitySpec::Kind::kRamp ? 1.0 : 2.0;
        *hi = std::exp(-a * std::min(1.0, scaled * near)) * (1 + 1e-12);
        *lo = std::exp(-a * std::min(1.0, scaled * far)) * (1 - 1e-12);
      };
      density.user = this;
      density.callback_max = 1;
      return;
    case Kind::kVolume:
      throw std::invalid_argument("density '" + spec.text +
                                  "' is a 3-D volume: only the full sampler takes it (kdm sample --dim 3)");
    case Kind::kImage:
      break;
  }
  image.values = spec.values.data();  // row 0 at y0, as DensityImageView has it
  if (spec.divided_by != 1) {         // a query counts the values' size: back to what the array holds
    undivided.resize(spec.values.size());
    for (std::size_t i = 0; i < spec.values.size(); ++i) {
      const double v = double(spec.values[i]) * spec.divided_by;
      if (!(v <= std::numeric_limits<float>::max())) {
        char message[256];
        std::snprintf(message, sizeof message,
                      "density '%s': a value of %g: a query's densities are points per unit area at scale "
                      "1, at most 3.4e38 (kept as floats); scale the array down and --scale up",
                      spec.text.c_str(), v);
        throw std::invalid_argument(message);
      }
      undivided[i] = static_cast<float>(v);
    }
    image.values = undivided.data();
  }
  image.width = spec.width, image.height = spec.height;
  image.x0 = r[0], image.y0 = r[1], image.x1 = r[2], image.y1 = r[3];
  if (make_density_max_mip(image, mip) != Status::kOk) {
    const bool values_ok = std::all_of(spec.values.begin(), spec.values.end(),
                                       [](float v) { return v >= 0 && std::isfinite(v); });
    char message[256];
    if (!values_ok || image.width <= 0 || image.height <= 0)
      std::snprintf(message, sizeof message,
                    "density image of %d x %d values: values must be finite and >= 0", image.width,
                    image.height);
    else
      std::snprintf(message, sizeof message,
                    "density image rectangle (%.17g, %.17g, %.17g, %.17g) must be finite, of positive width "
                    "and height, and wide enough for its texels per unit to be finite",
                    r[0], r[1], r[2], r[3]);
    throw std::invalid_argument(message);
  }
  density.kind = QueryDensity::Kind::kImage;
  density.image = &image;
}

bool read_images_by_sums(ClassQueryParams& params, ClassImageSums& sums, double max_texels) {
  const DensityImageView* images[kMaxQueryClasses];
  if (params.class_count < 2 || params.class_count > kMaxQueryClasses) return false;
  for (std::uint32_t k = 0; k < params.class_count; ++k) {
    if (params.classes[k].kind != QueryDensity::Kind::kImage || !params.classes[k].image) return false;
    images[k] = params.classes[k].image;
  }
  // Building costs about 1.5 ns a texel and saves 1 (stable) to 7 (smooth) ns a point (2-vCPU AMD EPYC):
  // larger images are read one by one, so that small queries of them (chunks) do not pay for it.
  const double texels = double(params.class_count) * images[0]->width * images[0]->height;
  if (!(texels <= max_texels)) return false;
  if (sums.build(images, params.class_count) != Status::kOk) return false;  // not on one grid
  params.image_sums = &sums;
  return true;
}

}  // namespace kdm::tools
