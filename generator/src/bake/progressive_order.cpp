// Progressive ranking by void-and-cluster: R. Ulichney, "The void-and-cluster method for dither array
// generation", SPIE 1913, 1993 — its "void" phase: each next point is the candidate in the deepest void of
// a Gaussian-filtered density of everything already present. See progressive_order.h.
#include <algorithm>
#include <cmath>
#include <numeric>

#include "bake/progressive_order.h"

namespace kdm::gen {
namespace {

/// Min-heap of candidate indices ordered by (field, index), with positions so that a candidate whose
/// field grew can sink to its place (fields only ever grow).
class VoidHeap {
 public:
  explicit VoidHeap(const std::vector<double>& field)
      : field_(field), heap_(field.size()), pos_(field.size()) {
    std::iota(heap_.begin(), heap_.end(), 0u);
    for (std::size_t i = 0; i < heap_.size(); ++i) pos_[i] = i;
    for (std::size_t i = heap_.size() / 2; i-- > 0;) sink(i);
  }
  bool contains(std::uint32_t c) const { return pos_[c] != kGone; }
  std::uint32_t pop() {
    const std::uint32_t top = heap_.front();
    move(heap_.size() - 1, 0);
    heap_.pop_back();
    pos_[top] = kGone;
    if (!heap_.empty()) sink(0);
    return top;
  }
  void grew(std::uint32_t c) { sink(pos_[c]); }
  /// Restores the order after fields changed arbitrarily.
  void rebuild() {
    for (std::size_t i = heap_.size() / 2; i-- > 0;) sink(i);
  }

 private:
  static constexpr std::size_t kGone = ~std::size_t(0);
  bool less(std::uint32_t a, std::uint32_t b) const {
    return field_[a] < field_[b] || (field_[a] == field_[b] && a < b);
  }
  void move(std::size_t from, std::size_t to) {
    heap_[to] = heap_[from];
    pos_[heap_[to]] = to;
  }
  void sink(std::size_t i) {
    const std::uint32_t c = heap_[i];
    for (;;) {
      std::size_t child = 2 * i + 1;
      if (child >= heap_.size()) break;
      if (child + 1 < heap_.size() && less(heap_[child + 1], heap_[child])) ++child;
      if (!less(heap_[child], c)) break;
      move(child, i);
      i = child;
    }
    heap_[i] = c;
    pos_[c] = i;
  }
  const std::vector<double>& field_;
  std::vector<std::uint32_t> heap_;
  std::vector<std::size_t> pos_;
};

}  // namespace

std::uint16_t rank_key(std::size_t s, std::size_t n) {
  return static_cast<std::uint16_t>(std::floor((double(s) + 0.5) / double(n) * 65536.0));
}

std::vector<std::uint32_t> progressive_order(const RankingInput& in) {
  const std::size_t n = in.candidates.size() / 2;
  if (n == 0) return {};
  const double w = in.width, h = in.height;
  // The filter narrows with the density of what is present (σ ∝ 1/sqrt(density)), so each pick looks for
  // the deepest void at the current spacing: wide early (low frequencies), narrow late (no close pairs).
  const double sigma0 = in.filter_width, sigma1 = in.filter_width_end > 0 ? in.filter_width_end : sigma0;
  auto sigma_at = [&](std::size_t s) {
    const double t = (double(s) + 0.5) / double(n);
    return 1 / std::sqrt(1 / (sigma0 * sigma0) + t * (1 / (sigma1 * sigma1) - 1 / (sigma0 * sigma0)));
  };
  double sigma = sigma_at(0);
  const double reach = 3 * std::max(sigma0, sigma1);  // cells fit the widest filter
  double reach2 = 9 * sigma * sigma, inv2s2 = 1.0 / (2 * sigma * sigma);
  // Candidates bucketed in cells at least `reach` wide, so a splat visits the 3×3 cells around it.
  const int cx = std::max(1, std::min(4096, static_cast<int>(w / reach)));
  const int cy = std::max(1, std::min(4096, static_cast<int>(h / reach)));
  auto cell_x = [&](double x) { return std::min(cx - 1, std::max(0, static_cast<int>(x / w * cx))); };
  auto cell_y = [&](double y) { return std::min(cy - 1, std::max(0, static_cast<int>(y / h * cy))); };
  std::vector<std::vector<std::uint32_t>> cells(static_cast<std::size_t>(cx) * cy);
  for (std::uint32_t i = 0; i < n; ++i)
    cells[static_cast<std::size_t>(cell_y(in.candidates[2 * i + 1])) * cx + cell_x(in.candidates[2 * i])]
        .push_back(i);
  // field: what is present; spread: the pending points at full weight; depth (what the heap orders):
  // field + fraction · spread, the fraction stepping in kSteps so that the heap is rebuilt only that often.
  std::vector<double> field(n, 0.0), spread(n, 0.0), depth(n, 0.0);
  constexpr std::size_t kSteps = 64;
  double fraction = 0;
  VoidHeap* heap = nullptr;
  std::vector<double>* into = &field;
  auto splat = [&](const double* p) {
    const int px = cell_x(p[0]), py = cell_y(p[1]);
    // Three columns (rows) around the point, or every one once when the grid is narrower than that.
    const int nx = cx >= 3 ? 3 : cx, ny = cy >= 3 ? 3 : cy;
    for (int oy = 0; oy < ny; ++oy)
      for (int ox = 0; ox < nx; ++ox) {
        const int gx = cx >= 3 ? (px + ox - 1 + cx) % cx : ox, gy = cy >= 3 ? (py + oy - 1 + cy) % cy : oy;
        for (std::uint32_t i : cells[static_cast<std::size_t>(gy) * cx + gx]) {
          if (heap && !heap->contains(i)) continue;
          double ddx = std::fabs(p[0] - in.candidates[2 * i]),
                 ddy = std::fabs(p[1] - in.candidates[2 * i + 1]);
          ddx = std::min(ddx, w - ddx), ddy = std::min(ddy, h - ddy);
          const double d2 = ddx * ddx + ddy * ddy;
          if (d2 >= reach2) continue;
          const double g = std::exp(-d2 * inv2s2);
          (*into)[i] += g;
          if (heap) depth[i] += g, heap->grew(i);
        }
      }
  };
  std::vector<const double*> present;
  for (std::size_t j = 0; j + 1 < in.fixed.size(); j += 2) present.push_back(&in.fixed[j]);
  auto refilter = [&]() {  // field and spread at the current width, depth from them; the heap is off
    std::fill(field.begin(), field.end(), 0.0);
    std::fill(spread.begin(), spread.end(), 0.0);
    heap = nullptr;
    into = &field;
    for (const double* p : present) splat(p);
    into = &spread;
    for (std::size_t j = 0; j + 1 < in.pending.size(); j += 2) splat(&in.pending[j]);
    into = &field;
    for (std::size_t i = 0; i < n; ++i) depth[i] = field[i] + fraction * spread[i];
  };
  refilter();
  std::vector<std::size_t> timed(in.timed_keys.size());
  std::iota(timed.begin(), timed.end(), std::size_t(0));
  std::stable_sort(timed.begin(), timed.end(),
                   [&](std::size_t a, std::size_t b) { return in.timed_keys[a] < in.timed_keys[b]; });
  VoidHeap voids(depth);
  heap = &voids;
  std::vector<std::uint32_t> order;
  order.reserve(n);
  std::size_t next_timed = 0;
  for (std::size_t s = 0; s < n; ++s) {
    const std::uint16_t key = rank_key(s, n);
    const double step_fraction =
        in.pending.empty() ? 0.0 : double(s * kSteps / n) / double(kSteps);  // floor(s / n, 1 / kSteps)
    if (sigma_at(s) < 0.95 * sigma) {  // re-filter everything present at the new width
      sigma = sigma_at(s);
      reach2 = 9 * sigma * sigma, inv2s2 = 1.0 / (2 * sigma * sigma);
      fraction = step_fraction;
      refilter();
      heap = &voids;
      voids.rebuild();
    } else if (step_fraction != fraction) {
      fraction = step_fraction;
      for (std::size_t i = 0; i < n; ++i) depth[i] = field[i] + fraction * spread[i];
      voids.rebuild();
    }
    for (; next_timed < timed.size() && in.timed_keys[timed[next_timed]] < key; ++next_timed) {
      present.push_back(&in.timed[2 * timed[next_timed]]);
      splat(present.back());
    }
    const std::uint32_t next = voids.pop();
    order.push_back(next);
    present.push_back(&in.candidates[2 * next]);
    splat(present.back());
  }
  return order;
}

}  // namespace kdm::gen
