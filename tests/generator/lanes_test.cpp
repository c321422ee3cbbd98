// The update passes' lane-vector forms (lanes.h, lanes_wide.h): the sixteen-lane AVX-512 passes must give the
// four-lane per-lane passes' bits exactly, so a point set does not depend on the machine; and per-lane sums
// must measure what the four-lane sums do, to rounding.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

#include "sampler/lanes.h"
#include "sampler/lanes_wide.h"
#include "sampler/rng.h"

namespace kdm::gen {
namespace {

std::uint32_t bits(float x) {
  std::uint32_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}
std::uint64_t bits(double x) {
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}

// Calls f(std::integral_constant<int, N>) with N = width / 4 for the widths the wide passes take.
template <class F>
decltype(auto) per_lane_width(int width, F&& f) {
  if (width == 8) return f(std::integral_constant<int, 2>{});
  if (width == 12) return f(std::integral_constant<int, 3>{});
  return f(std::integral_constant<int, 4>{});
}

template <int D>
Grid<D> test_grid() {
  Grid<D> g;
  g.dims.fill(D == 2 ? 48 : 24);
  return g;
}

// A residual like the chain's: mostly small, both signs, some exact zeros (where the sign flips).
std::vector<float> random_residual(std::size_t size, Rng& rng) {
  std::vector<float> r(size);
  for (float& v : r) v = rng.below(16) == 0 ? 0.0f : static_cast<float>(rng.uniform() - 0.6);
  return r;
}

template <int D>
std::vector<Footprint<D>> wide_footprints(const Grid<D>& grid, Rng& rng, KernelTable& table) {
  std::vector<Footprint<D>> out;
  for (const double sigma : {0.95, 1.52, 2.2})  // windows of 8, 12 and 16 nodes
    for (int trial = 0; trial < 24; ++trial) {
      Vec<D> x;
      for (int k = 0; k < D; ++k) x[k] = rng.uniform() * grid.dims[k];
      Footprint<D> fp;
      fp.build(grid, x, sigma, 0.43, true, trial % 2 ? &table : nullptr);
      if (wide::fits(fp)) out.push_back(fp);
    }
  return out;
}

void expect_same_bits(const std::vector<float>& a, const std::vector<float>& b, const char* what) {
  ASSERT_EQ(a.size(), b.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < a.size(); ++i) differ += bits(a[i]) != bits(b[i]);
  EXPECT_EQ(differ, 0u) << what;
}

// The instruction sets of the wide passes this CPU runs (AVX-512 CPUs run the AVX2 passes too).
std::vector<wide::Isa> wide_isas() {
  std::vector<wide::Isa> isas;
  if (wide::widest(8) == wide::Isa::kAvx2) isas.push_back(wide::Isa::kAvx2);
  if (wide::widest(16) == wide::Isa::kAvx512) isas.push_back(wide::Isa::kAvx512);
  return isas;
}
constexpr const char* kNoWidePasses = "this CPU has neither AVX2 nor AVX-512: the wide passes never run here";

template <int D>
void check_wide_passes(wide::Isa isa) {
  SCOPED_TRACE(isa == wide::Isa::kAvx512 ? "AVX-512" : "AVX2");
  const Grid<D> grid = test_grid<D>();
  Rng rng(7, 1, 2, 3, D);
  KernelTable table;
  const std::vector<Footprint<D>> fps = wide_footprints(grid, rng, table);
  int widths[17] = {};
  for (const Footprint<D>& fp : fps) {
    ++widths[fp.width];
    const std::vector<float> start = random_residual(grid.size(), rng);
    std::vector<float> wide_r = start, lane_r = start;
    std::vector<float> wide_saved(16 * 64 * 64), lane_saved(wide_saved.size());
    Vec<D> wide_g, lane_g;

    const double wide_e = wide::remove<D>(isa, wide_r.data(), grid, fp, wide_g, wide_saved.data());
    const double lane_e = per_lane_width(fp.width, [&](auto n) {
      return lanes::measure_per_lane<n(), true>(lane_r.data(), grid, fp, lane_g, lane_saved.data());
    });
    EXPECT_EQ(bits(wide_e), bits(lane_e)) << "remove, width " << fp.width;
    for (int k = 0; k < D; ++k) EXPECT_EQ(bits(wide_g[k]), bits(lane_g[k])) << "remove gradient " << k;
    expect_same_bits(wide_r, lane_r, "R after remove");
    expect_same_bits(wide_saved, lane_saved, "saved nodes");

    const double wide_a = wide::added<D>(isa, wide_r.data(), grid, fp, wide_g);
    const double lane_a = per_lane_width(fp.width, [&](auto n) {
      return lanes::measure_per_lane<n(), false>(lane_r.data(), grid, fp, lane_g, nullptr);
    });
    EXPECT_EQ(bits(wide_a), bits(lane_a)) << "added, width " << fp.width;
    for (int k = 0; k < D; ++k) EXPECT_EQ(bits(wide_g[k]), bits(lane_g[k])) << "added gradient " << k;

    wide::add<D>(isa, wide_r.data(), grid, fp, -0.5f);
    per_lane_width(fp.width, [&](auto n) { lanes::add<n()>(lane_r.data(), grid, fp, -0.5f); });
    expect_same_bits(wide_r, lane_r, "R after add");

    wide::restore<D>(isa, wide_r.data(), grid, fp, wide_saved.data());
    per_lane_width(fp.width,
                   [&](auto n) { lanes::restore<n()>(lane_r.data(), grid, fp, lane_saved.data()); });
    expect_same_bits(wide_r, lane_r, "R after restore");
    if (::testing::Test::HasFailure()) return;
  }
  for (const int w : {8, 12, 16}) EXPECT_GT(widths[w], 2) << "too few footprints " << w << " nodes wide";
}

TEST(LanesTest, WidePassesGiveThePerLaneBits2D) {
  if (wide_isas().empty()) GTEST_SKIP() << kNoWidePasses;
  for (const wide::Isa isa : wide_isas()) check_wide_passes<2>(isa);
}
TEST(LanesTest, WidePassesGiveThePerLaneBits3D) {
  if (wide_isas().empty()) GTEST_SKIP() << kNoWidePasses;
  for (const wide::Isa isa : wide_isas()) check_wide_passes<3>(isa);
}

// The kernel evaluated on wide vectors gives the four-lane evaluation's factors exactly: from the table
// (uniform models) or computed with exp (every other model; `tabulated` false).
void check_wide_kernel_factors(wide::Isa isa, bool tabulated) {
  SCOPED_TRACE(isa == wide::Isa::kAvx512 ? "AVX-512" : "AVX2");
  const Grid<2> grid = test_grid<2>();
  Rng rng(9, 1, 2, 3, 4);
  KernelTable four, sixteen;
  sixteen.isa = isa;
  int wide_rows = 0;
  for (const double sigma : {0.95, 1.52, 2.2, 4.0})
    for (const bool with_derivative : {false, true})
      for (int trial = 0; trial < 24; ++trial) {
        const Vec<2> x{rng.uniform() * grid.dims[0], rng.uniform() * grid.dims[1]};
        Footprint<2> a, b;
        if (tabulated) {
          a.build(grid, x, sigma, 0.43, with_derivative, &four);
          b.build(grid, x, sigma, 0.43, with_derivative, &sixteen);
        } else {
          a.build(grid, x, sigma, 0.43, with_derivative, nullptr);
          b.build(grid, x, sigma, 0.43, with_derivative, nullptr, isa);
        }
        ASSERT_EQ(a.contiguous, b.contiguous);
        wide_rows += b.contiguous && wide::fits_width(b.width);
        for (int k = 0; k < kMaxWindow; ++k) {
          EXPECT_EQ(bits(a.row_value[k]), bits(b.row_value[k])) << "sigma " << sigma << " lane " << k;
          EXPECT_EQ(bits(a.row_deriv[k]), bits(b.row_deriv[k])) << "sigma " << sigma << " lane " << k;
        }
        ASSERT_EQ(a.axes[1].count, b.axes[1].count);
        for (int k = 0; k < a.axes[1].count; ++k) {
          EXPECT_EQ(bits(a.axes[1].value[k]), bits(b.axes[1].value[k]));
          EXPECT_EQ(bits(a.axes[1].deriv[k]), bits(b.axes[1].deriv[k]));
        }
        if (::testing::Test::HasFailure()) return;
      }
  EXPECT_GT(wide_rows, 50);
}

TEST(LanesTest, WideKernelTableGivesTheSameFactors) {
  if (wide_isas().empty()) GTEST_SKIP() << kNoWidePasses;
  for (const wide::Isa isa : wide_isas()) check_wide_kernel_factors(isa, true);
}
TEST(LanesTest, WideComputedKernelGivesTheSameFactors) {
  if (wide_isas().empty()) GTEST_SKIP() << kNoWidePasses;
  for (const wide::Isa isa : wide_isas()) check_wide_kernel_factors(isa, false);
}

// Per-lane and four-lane sums add the same terms in another order, so they agree to float rounding. Over
// these footprints (up to 16·11·11 terms of magnitude up to about 1) the largest difference measured
// was 1.9e-5 (energy, 3D) and 4.3e-6 from the exact Σ|R| difference; the tolerance is ten times the former.
template <int D>
void check_per_lane_sums() {
  const Grid<D> grid = test_grid<D>();
  Rng rng(8, 1, 2, 3, D);
  KernelTable table;
  for (const Footprint<D>& fp : wide_footprints(grid, rng, table)) {
    const std::vector<float> start = random_residual(grid.size(), rng);
    std::vector<float> a = start, b = start, saved(16 * 64 * 64);
    Vec<D> ga, gb;
    const double ea = per_lane_width(fp.width, [&](auto n) {
      return lanes::measure_per_lane<n(), true>(a.data(), grid, fp, ga, saved.data());
    });
    const double eb = per_lane_width(
        fp.width, [&](auto n) { return lanes::measure<n(), true>(b.data(), grid, fp, gb, saved.data()); });
    const double tolerance = 2e-4;
    EXPECT_NEAR(ea, eb, tolerance);
    for (int k = 0; k < D; ++k) EXPECT_NEAR(ga[k], gb[k], tolerance);
    expect_same_bits(a, b, "R after remove (no sums involved)");
    // Both must be the real energy change, which the removal shows as a difference of Σ|R| over the grid.
    double before = 0, after = 0;
    for (std::size_t i = 0; i < start.size(); ++i) before += std::fabs(start[i]), after += std::fabs(a[i]);
    EXPECT_NEAR(ea, before - after, tolerance);
  }
}

TEST(LanesTest, PerLaneSumsMeasureTheSameChange2D) {
  check_per_lane_sums<2>();
}
TEST(LanesTest, PerLaneSumsMeasureTheSameChange3D) {
  check_per_lane_sums<3>();
}

}  // namespace
}  // namespace kdm::gen
