// Empty circles of a baker's run; see hole_finder.h.
#include "bake/hole_finder.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "kdm/runtime/check.h"

namespace kdm::gen {

HoleFinder::HoleFinder(double width, double height, double step, double reach,
                       const std::vector<double>& points)
    : height_(height), step_(step), reach_(reach) {
  KDM_CHECK(width > 0 && height > 0 && step > 0 && reach > 0);
  nx_ = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(width / step)));
  ny_ = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(height / step)));
  step_ = width / double(nx_);  // whole nodes per side, so the grid wraps
  distance_.assign(nx_ * ny_, static_cast<float>(reach));
  for (std::size_t i = 0; i + 1 < points.size(); i += 2) add(points[i], points[i + 1]);
}

void HoleFinder::add(double x, double y) {
  const double step_y = height_ / double(ny_);
  const auto span_x = static_cast<std::ptrdiff_t>(std::ceil(reach_ / step_));
  const auto span_y = static_cast<std::ptrdiff_t>(std::ceil(reach_ / step_y));
  const auto cx = static_cast<std::ptrdiff_t>(std::floor(x / step_));
  const auto cy = static_cast<std::ptrdiff_t>(std::floor(y / step_y));
  const auto nx = static_cast<std::ptrdiff_t>(nx_), ny = static_cast<std::ptrdiff_t>(ny_);
  // Nodes within reach; a node seen twice on a small grid takes the smaller distance either way.
  for (std::ptrdiff_t j = cy - span_y; j <= cy + span_y + 1; ++j)
    for (std::ptrdiff_t i = cx - span_x; i <= cx + span_x + 1; ++i) {
      const double d = std::hypot(double(i) * step_ - x, double(j) * step_y - y);
      if (d >= reach_) continue;
      float& at = distance_[std::size_t((j % ny + ny) % ny) * nx_ + std::size_t((i % nx + nx) % nx)];
      at = std::min(at, static_cast<float>(d));
    }
}

std::vector<double> HoleFinder::centres_beyond(double radius) const {
  std::vector<std::size_t> nodes;
  for (std::size_t n = 0; n < distance_.size(); ++n)
    if (distance_[n] > radius) nodes.push_back(n);
  std::stable_sort(nodes.begin(), nodes.end(),
                   [&](std::size_t a, std::size_t b) { return distance_[a] > distance_[b]; });
  std::vector<double> out;
  const double step_y = height_ / double(ny_);
  for (std::size_t n : nodes) out.insert(out.end(), {double(n % nx_) * step_, double(n / nx_) * step_y});
  return out;
}

}  // namespace kdm::gen
