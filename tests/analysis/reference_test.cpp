// Cross-check against the reference sets of Fattal's own implementation (tests/data/reference/README.md):
// 10 torus sets of 4044 points with published statistics. The computation is deterministic on fixed data,
// so the tolerance is half a unit of the last published digit (the published values are rounded).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "kdm/analysis/report.h"

namespace kdm::analysis {
namespace {

TEST(Reference, MatchesPublishedStatistics) {
  std::vector<std::string> files;
  for (int i = 1; i <= 10; ++i) {
    char name[64];
    std::snprintf(name, sizeof name, "/reference/ref_T0.5_n4096_%02d.txt", i);
    files.push_back(std::string(KDM_TEST_DATA_DIR) + name);
  }
  const std::vector<tools::PointSet> sets = load_point_sets(files);
  ASSERT_EQ(sets.size(), 10u);
  for (const tools::PointSet& s : sets) ASSERT_EQ(s.size(), 4044u);
  AnalysisOptions o;
  o.torus = true;
  o.fmax = 2.5;
  const AnalysisReport r = analyze(sets, o);
  EXPECT_NEAR(r.nn.davg, 0.872, 0.0005);
  EXPECT_NEAR(r.dmin_mean, 0.612, 0.0005);
  EXPECT_NEAR(r.nn.dmin, 0.533, 0.0005);  // worst set
  const SpectrumStats& st = r.spectrum_stats;
  EXPECT_NEAR(st.low_p, 0.0044, 0.00005);
  // ν_eff moves in ring steps of 1/√4044 = 0.0157, so ±0.0005 pins the ring (48/√4044 = 0.7548).
  EXPECT_NEAR(st.nu_eff, 0.755, 0.0005);
  EXPECT_NEAR(st.peak, 3.50, 0.005);
  EXPECT_NEAR(st.peak_f, 1.04, 0.005);
  EXPECT_NEAR(st.anisotropy_db, -10.0, 0.05);
  std::printf(
      "reference: davg %.5f dmin mean %.5f worst %.5f lowP %.6f nu_eff %.5f peak %.4f at %.4f aniso %.3f "
      "dB\n",
      r.nn.davg, r.dmin_mean, r.nn.dmin, st.low_p, st.nu_eff, st.peak, st.peak_f, st.anisotropy_db);
}

}  // namespace
}  // namespace kdm::analysis
