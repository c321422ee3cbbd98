#include "sampler/support_pieces.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace kdm::gen {
namespace {

/// Moves whose weight no longer brings two pieces nearer their shares end the balance; passes are few (a
/// piece is within a kernel of its share from the level before), and this bounds them whatever happens.
constexpr int kMaxPasses = 256;

/// The node holding position x (grid units), clamped into the grid.
template <int D>
std::int64_t node_of(const Grid<D>& g, const Vec<D>& x) {
  std::int64_t node = 0;
  for (int k = 0; k < D; ++k) {
    const double c = std::clamp(std::floor(x[k]), 0.0, double(g.dims[k] - 1));
    node += static_cast<std::int64_t>(c) * g.stride(k);
  }
  return node;
}

template <int D>
Vec<D> centre_of(const Grid<D>& g, std::int64_t node) {
  Vec<D> x{};
  for (int k = 0; k < D; ++k) x[k] = double((node / g.stride(k)) % g.dims[k]) + 0.5;
  return x;
}

template <int D>
double squared_distance(const Grid<D>& g, const Vec<D>& a, const Vec<D>& b) {
  double d2 = 0;
  for (int k = 0; k < D; ++k) {
    double d = std::fabs(a[k] - b[k]);
    if (g.torus) d = std::min(d, g.dims[k] - d);
    d2 += d * d;
  }
  return d2;
}

}  // namespace

template <int D>
SupportPieces support_pieces(const DensityGrid<D>& level) {
  const Grid<D>& g = level.grid;
  const std::size_t nodes = static_cast<std::size_t>(g.size());
  if (std::all_of(level.rho.begin(), level.rho.end(), [](float v) { return v > 0; })) return {};
  SupportPieces s;
  s.piece.assign(nodes, -1);
  std::vector<std::int64_t> stack;
  for (std::size_t start = 0; start < nodes; ++start) {
    if (s.piece[start] >= 0 || !(level.rho[start] > 0)) continue;
    const auto id = static_cast<std::int32_t>(s.mass.size());
    double mass = 0;
    s.piece[start] = id;
    stack.assign(1, static_cast<std::int64_t>(start));
    while (!stack.empty()) {  // a flood fill across faces
      const std::int64_t i = stack.back();
      stack.pop_back();
      mass += level.rho[static_cast<std::size_t>(i)];
      for (int k = 0; k < D; ++k) {
        const std::int64_t stride = g.stride(k), m = g.dims[k], c = (i / stride) % m;
        for (int dir = -1; dir <= 1; dir += 2) {
          std::int64_t n = c + dir;
          if (n < 0 || n >= m) {
            if (!g.torus) continue;
            n = n < 0 ? m - 1 : 0;
          }
          const std::size_t j = static_cast<std::size_t>(i + (n - c) * stride);
          if (s.piece[j] >= 0 || !(level.rho[j] > 0)) continue;
          s.piece[j] = id;
          stack.push_back(static_cast<std::int64_t>(j));
        }
      }
    }
    s.mass.push_back(mass);
  }
  if (s.mass.size() < 2) return {};
  return s;
}

template <int D>
std::int64_t balance_pieces(Chain<D>& chain, std::vector<Particle<D>>& particles,
                            const SupportPieces& pieces) {
  const std::size_t count = pieces.mass.size();
  if (count < 2) return 0;
  const Grid<D>& g = chain.grid();
  const std::vector<float>& R = chain.residual();
  const double total_mass = std::accumulate(pieces.mass.begin(), pieces.mass.end(), 0.0);
  typename Chain<D>::Scratch scratch;
  std::int64_t moved = 0;
  std::vector<double> weight(count);
  std::vector<std::vector<std::size_t>> members(count);
  std::vector<std::int64_t> highest(count), lowest(count);
  std::vector<std::size_t> order(count);
  for (int pass = 0; pass < kMaxPasses; ++pass) {
    std::fill(weight.begin(), weight.end(), 0.0);
    for (auto& m : members) m.clear();
    double total_weight = 0;
    for (std::size_t j = 0; j < particles.size(); ++j) {
      total_weight += particles[j].weight();
      const std::int32_t p = pieces.piece[static_cast<std::size_t>(node_of<D>(g, particles[j].x))];
      if (p < 0) continue;  // on the fringe where interpolation fades to zero: counted nowhere
      weight[static_cast<std::size_t>(p)] += particles[j].weight();
      members[static_cast<std::size_t>(p)].push_back(j);
    }
    std::vector<double> off(count);  // weight held minus share
    for (std::size_t p = 0; p < count; ++p) off[p] = weight[p] - total_weight * pieces.mass[p] / total_mass;
    std::fill(highest.begin(), highest.end(), -1);
    std::fill(lowest.begin(), lowest.end(), -1);
    for (std::int64_t i = 0; i < g.size(); ++i) {
      const std::int32_t p = pieces.piece[static_cast<std::size_t>(i)];
      if (p < 0) continue;
      std::int64_t& hi = highest[static_cast<std::size_t>(p)];
      std::int64_t& lo = lowest[static_cast<std::size_t>(p)];
      if (hi < 0 || R[static_cast<std::size_t>(i)] > R[static_cast<std::size_t>(hi)]) hi = i;
      if (lo < 0 || R[static_cast<std::size_t>(i)] < R[static_cast<std::size_t>(lo)]) lo = i;
    }
    // The largest surpluses with the largest deficits, one move each per pass: a piece's nodes of highest
    // and lowest R change with each move.
    std::iota(order.begin(), order.end(), std::size_t(0));
    std::sort(order.begin(), order.end(),
              [&](std::size_t a, std::size_t b) { return off[a] > off[b] || (off[a] == off[b] && a < b); });
    std::int64_t moved_in_pass = 0;
    for (std::size_t s = 0, d = count; s < d;) {
      const std::size_t from = order[s], to = order[d - 1];
      if (!(off[from] > 0 && off[to] < 0)) break;
      const double most = 2 * std::min(off[from], -off[to]);  // a lighter move brings both nearer
      std::size_t best = particles.size();
      double best_weight = 0, best_d2 = std::numeric_limits<double>::infinity();
      const Vec<D> source = centre_of<D>(g, highest[from]);
      for (std::size_t j : members[from]) {
        const double w = particles[j].weight();
        if (!(w < most)) continue;
        const double d2 = squared_distance<D>(g, particles[j].x, source);
        if (w > best_weight || (w == best_weight && d2 < best_d2)) best = j, best_weight = w, best_d2 = d2;
      }
      if (best == particles.size()) {  // nothing light enough here: the next surplus may have one
        ++s;
        continue;
      }
      Particle<D>& p = particles[best];
      chain.splat(p, -1.0f, scratch);
      p.x = centre_of<D>(g, lowest[to]);
      p.fresh = true;
      chain.splat(p, 1.0f, scratch);
      off[from] -= best_weight, off[to] += best_weight;
      ++moved, ++moved_in_pass;
      ++s, --d;
    }
    if (moved_in_pass == 0) break;
  }
  return moved;
}

template SupportPieces support_pieces<2>(const DensityGrid<2>&);
template SupportPieces support_pieces<3>(const DensityGrid<3>&);
template std::int64_t balance_pieces<2>(Chain<2>&, std::vector<Particle<2>>&, const SupportPieces&);
template std::int64_t balance_pieces<3>(Chain<3>&, std::vector<Particle<3>>&, const SupportPieces&);

}  // namespace kdm::gen
