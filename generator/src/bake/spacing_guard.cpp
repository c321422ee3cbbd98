// Hard-core test for baked points; see spacing_guard.h.
#include "bake/spacing_guard.h"

#include <algorithm>
#include <cmath>

#include "kdm/runtime/check.h"

namespace kdm::gen {

SpacingGuard::SpacingGuard(double width, double height, double min_distance, std::size_t expected_points)
    : width_(width), height_(height), min_distance_(min_distance) {
  KDM_CHECK(width > 0 && height > 0 && min_distance >= 0);
  // Cells at least min_distance wide (so a test reads 3×3 cells) and about one point each.
  const double spacing = std::sqrt(width * height / double(std::max<std::size_t>(expected_points, 1)));
  cell_ = std::max({min_distance, spacing, 1e-9});
  nx_ = std::max<std::int64_t>(1, static_cast<std::int64_t>(width / cell_));
  ny_ = std::max<std::int64_t>(1, static_cast<std::int64_t>(height / cell_));
  head_.assign(static_cast<std::size_t>(nx_ * ny_), -1);
}

std::int64_t SpacingGuard::cell_of(double x, double y) const {
  const auto wrap = [](double v, double period, std::int64_t cells) {
    const double t = v - std::floor(v / period) * period;  // [0, period]
    return std::min<std::int64_t>(cells - 1, static_cast<std::int64_t>(t / period * double(cells)));
  };
  return wrap(y, height_, ny_) * nx_ + wrap(x, width_, nx_);
}

bool SpacingGuard::clear(double x, double y) const {
  if (min_distance_ <= 0) return true;
  const std::int64_t c = cell_of(x, y), cx = c % nx_, cy = c / nx_;
  const double r2 = min_distance_ * min_distance_;
  // With fewer than 3 cells along an axis the neighbourhood repeats a cell: visit each once.
  const std::int64_t spanx = std::min<std::int64_t>(nx_, 3), spany = std::min<std::int64_t>(ny_, 3);
  for (std::int64_t j = 0; j < spany; ++j)
    for (std::int64_t i = 0; i < spanx; ++i) {
      const std::int64_t gx = ((cx + i - (spanx > 1)) % nx_ + nx_) % nx_;
      const std::int64_t gy = ((cy + j - (spany > 1)) % ny_ + ny_) % ny_;
      for (std::int32_t p = head_[static_cast<std::size_t>(gy * nx_ + gx)]; p >= 0;
           p = next_[std::size_t(p)]) {
        double dx = std::fabs(xy_[2 * std::size_t(p)] - x), dy = std::fabs(xy_[2 * std::size_t(p) + 1] - y);
        dx = std::fmod(dx, width_), dy = std::fmod(dy, height_);
        dx = std::min(dx, width_ - dx), dy = std::min(dy, height_ - dy);
        if (dx * dx + dy * dy < r2) return false;
      }
    }
  return true;
}

void SpacingGuard::add(double x, double y) {
  const std::size_t c = static_cast<std::size_t>(cell_of(x, y));
  xy_.insert(xy_.end(), {x, y});
  next_.push_back(head_[c]);
  head_[c] = static_cast<std::int32_t>(next_.size() - 1);
}

}  // namespace kdm::gen
