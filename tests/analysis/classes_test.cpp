// Labelled sets with a density per class (analyze_classes' class_densities): each class against its own
// density, the union's sum, and the classes' counts against their densities' shares.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "kdm/analysis/classes.h"
#include "kdm/analysis/common.h"
#include "kdm/generator/multiclass.h"

namespace kdm::analysis {
namespace {

// Class 1's steep ramp, 1 : 20 across x, scaled to a mean of 2 (class 0's uniform density has mean 1):
// shares of a third and two thirds.
constexpr double kRampRatio = 20;
double ramp(double x) {
  return std::pow(kRampRatio, x) * 2 * std::log(kRampRatio) / (kRampRatio - 1);
}

/// gen::sample_classes of `n` points: class 0 uniform, class 1 the ramp.
tools::PointSet uniform_and_ramp(std::int64_t n, std::uint64_t seed) {
  gen::Density steep;
  steep.function = [](const double* u) { return ramp(u[0]); };
  steep.thread_safe = true;
  gen::SamplerOptions o;
  o.n = n;
  o.seed = seed;
  o.domain = gen::Domain::kBox;  // a ramp has walls: on a torus its two ends would meet
  const gen::ClassSample s = gen::sample_classes(o, {gen::Density::from_values(1, 1, {1.0f}), steep});
  tools::PointSet set;
  set.dim = 2;
  set.coords = s.points;
  set.classes = s.classes;
  return set;
}

const DensityFunction kUniform = [](double, double) { return 1.0; };
const DensityFunction kRamp = [](double x, double) { return ramp(x); };

double worst_band(const AnalysisReport& r) {
  double worst = 0;
  for (const DensityBand& b : r.density.bands)
    if (b.expected >= 50) worst = std::max(worst, std::abs(b.bias()));
  return worst;
}

AnalysisOptions box_options() {
  AnalysisOptions o;
  o.torus = false;
  o.spectrum = false;  // not judged here; the rest of the analysis is what class densities change
  return o;
}

TEST(AnalysisClassesTest, EachClassAgainstItsOwnDensity) {
  // Seeds 1..8 of 3,000 points (box): with each class's own density, window RMS z 0.21–0.33 (class 0)
  // and 0.26–0.42 (class 1), class 1's worst band (of those expecting ≥ 50 points) 2–11%, its largest
  // hole 0.95–1.05 local d_hex. Against the union's summed density (what one --density judged before):
  // RMS z 2.92–2.99 and 1.51–1.72, class 1's worst band 56–61%, largest hole 1.27–1.54 (0.31 to 0.55
  // above the own density's, set by set). The bars lie between, with room on both sides.
  const tools::PointSet set = uniform_and_ramp(3000, 4);
  AnalysisOptions o = box_options();
  const ClassesReport own = analyze_classes({set}, o, {}, {kUniform, kRamp});
  o.density = summed_density({kUniform, kRamp});
  const ClassesReport one = analyze_classes({set}, o);
  ASSERT_EQ(own.classes, (std::vector<std::uint8_t>{0, 1}));
  ASSERT_EQ(one.classes, own.classes);
  for (const ClassesReport* r : {&own, &one})
    for (const AnalysisReport& c : r->reports) ASSERT_TRUE(c.has_density && c.has_empty_circles);
  EXPECT_LT(own.reports[0].density.rms_z, 0.6);
  EXPECT_LT(own.reports[1].density.rms_z, 0.6);
  EXPECT_GT(one.reports[0].density.rms_z, 2.0);
  EXPECT_GT(one.reports[1].density.rms_z, 1.2);
  EXPECT_LT(worst_band(own.reports[1]), 0.25);
  EXPECT_GT(worst_band(one.reports[1]), 0.4);
  EXPECT_LT(own.reports[1].empty_circles.largest, 1.2);
  EXPECT_GT(one.reports[1].empty_circles.largest, own.reports[1].empty_circles.largest + 0.1);
  // The closest pair of different classes: in local spacings of the classes' summed density.
  EXPECT_EQ(own.cross_class_closest, cross_class_closest(set, false, summed_density({kUniform, kRamp})));
  EXPECT_NE(own.cross_class_closest, cross_class_closest(set, false));
  // The ramp varies: its class's spectrum would measure it. The uniform class's does not.
  o = box_options();
  o.spectrum = true;
  const ClassesReport notes = analyze_classes({set}, o, {}, {kUniform, kRamp});
  EXPECT_EQ(notes.reports[0].spectrum_nonuniform, "");
  EXPECT_EQ(notes.reports[1].spectrum_nonuniform, "the target density is not constant");
}

TEST(AnalysisClassesTest, SharesCatchWrongCounts) {
  const tools::PointSet set = uniform_and_ramp(3000, 2);
  const AnalysisOptions o = box_options();
  const ClassesReport right = analyze_classes({set}, o, {}, {kUniform, kRamp});
  ASSERT_EQ(right.shares.size(), 2u);
  // Means 1 and 2: a third and two thirds of the points; binomial sd √(3000 · 2/9) = 25.8.
  EXPECT_NEAR(right.shares[0].share, 1.0 / 3, 1e-4);
  EXPECT_NEAR(right.shares[0].expected, 1000, 0.5);
  EXPECT_NEAR(right.shares[1].sd, std::sqrt(3000 * 2.0 / 9), 0.01);
  EXPECT_EQ(right.shares[0].count + right.shares[1].count, 3000u);
  // The sampler splits its points by the same integrals (to the rounding of a count): z near 0.
  for (const ClassShare& c : right.shares) EXPECT_LT(std::abs(c.z), 0.5) << int(c.cls);

  // Classes swapped: 2,000 points where 1,000 are expected, z about 39.
  tools::PointSet swapped = set;
  for (std::uint8_t& k : swapped.classes) k = 1 - k;
  const ClassesReport wrong = analyze_classes({swapped}, o, {}, {kUniform, kRamp});
  EXPECT_GT(wrong.shares[0].z, 10);
  EXPECT_LT(wrong.shares[1].z, -10);
  // A class's density at half the scale the sampler had: halves expected, z about ±18.
  const DensityFunction half = [](double x, double) { return ramp(x) / 2; };
  const ClassesReport scaled = analyze_classes({set}, o, {}, {kUniform, half});
  EXPECT_LT(scaled.shares[0].z, -10);
  EXPECT_GT(scaled.shares[1].z, 10);
  // Its shape, all each class's own test reads, is the same.
  EXPECT_DOUBLE_EQ(scaled.reports[1].density.rms_z, right.reports[1].density.rms_z);

  // Several sets pool: counts and expectations add up.
  const ClassesReport two = analyze_classes({set, set}, o, {}, {kUniform, kRamp});
  EXPECT_EQ(two.shares[1].count, 2 * right.shares[1].count);
  EXPECT_NEAR(two.shares[1].expected, 2 * right.shares[1].expected, 1e-9);
  EXPECT_NEAR(two.shares[1].sd, std::sqrt(2.0) * right.shares[1].sd, 1e-9);
}

TEST(AnalysisClassesTest, ClassDensitiesInJsonEnergyAndRefusals) {
  const tools::PointSet set = uniform_and_ramp(600, 3);
  const AnalysisOptions o = box_options();
  // Without class densities classes.json is as it was (no shares); with them it holds one per class.
  const std::string plain = classes_json(analyze_classes({set}, o), {"p"});
  EXPECT_EQ(plain.find("shares"), std::string::npos);
  EXPECT_EQ(format_class_shares(analyze_classes({set}, o)), "");
  const ClassesReport own = analyze_classes({set}, o, {}, {kUniform, kRamp});
  const std::string json = classes_json(own, {"p"});
  EXPECT_NE(json.find("\"shares\": [{\"class\": 0, \"share\": "), std::string::npos) << json;
  EXPECT_NE(json.find("{\"class\": 1, \"share\": "), std::string::npos) << json;
  EXPECT_NE(format_class_shares(own).find("class 1"), std::string::npos);

  // The energy callback learns which class it measures.
  std::vector<int> asked;
  const ClassEnergy energy = [&](std::uint8_t k, const std::vector<tools::PointSet>& subsets) {
    asked.push_back(k);
    return double(subsets.front().size());
  };
  const ClassesReport e = analyze_classes({set}, o, energy, {kUniform, kRamp});
  EXPECT_EQ(asked, (std::vector<int>{0, 1}));
  EXPECT_EQ(e.reports[1].energy_per_point, double(e.shares[1].count));

  // A class between without points may have a density (0 too): its share is compared with no points.
  tools::PointSet gap = set;
  for (std::uint8_t& k : gap.classes) k *= 2;  // classes 0 and 2
  const DensityFunction zero = [](double, double) { return 0.0; };
  const ClassesReport skipped = analyze_classes({gap}, o, {}, {kUniform, kRamp, kRamp});
  ASSERT_EQ(skipped.shares.size(), 3u);
  EXPECT_EQ(skipped.shares[1].count, 0u);
  EXPECT_LT(skipped.shares[1].z, -10);  // expected about 2 / 5 of the points
  EXPECT_EQ(analyze_classes({gap}, o, {}, {kUniform, zero, kRamp}).shares[1].z, 0);

  const auto message = [&](const tools::PointSet& s, const std::vector<DensityFunction>& d) -> std::string {
    try {
      analyze_classes({s}, o, {}, d);
    } catch (const InvalidInput& error) {
      return error.what();
    }
    return "no error";
  };
  EXPECT_NE(message(set, {kUniform}).find("1 class densities given, but the points' classes run 0 to 1 (2 "),
            std::string::npos);
  // A class after the last label holds no points (a sampled class of density 0): counted, not refused.
  const ClassesReport trailing = analyze_classes({set}, o, {}, {kUniform, kRamp, zero});
  ASSERT_EQ(trailing.shares.size(), 3u);
  EXPECT_EQ(trailing.shares[2].count, 0u);
  EXPECT_EQ(trailing.shares[2].z, 0);
  EXPECT_EQ(trailing.shares[1].count, own.shares[1].count);
  EXPECT_NE(message(set, {kUniform, zero}).find("class 1's density is zero everywhere, but the class has"),
            std::string::npos);
  EXPECT_NE(message(gap, {zero, zero, zero}).find("every class density is zero"), std::string::npos);
  EXPECT_NE(message(set, {kUniform, DensityFunction{}}).find("class 1's density is empty"),
            std::string::npos);
  const DensityFunction negative = [](double x, double) { return x - 0.5; };
  EXPECT_NE(message(set, {negative, kRamp}).find("class 0's density is negative"), std::string::npos);
}

}  // namespace
}  // namespace kdm::analysis
