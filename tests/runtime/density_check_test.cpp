// DensityCheck: a wrapped callback density gives the same points as the bare one, and the first value a
// query reads that is NaN, infinite, negative or above callback_max is recorded with where it was read.
#include "kdm/runtime/density_check.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "kdm/runtime/class_query.h"
#include "kdm/runtime/parallel_query.h"
#include "run_query.h"

namespace kdm {
namespace {

using testing::run_query;
using testing::same_bits;

// 0.25 + x/8, with a flaw right of x = `bad_from` where it returns `bad` instead; bounded by 1.25 up to
// x = 8, past the region's right side by more than smooth mode's reads reach (they reach 6.27 there).
struct Ramp {
  double bad_from = std::numeric_limits<double>::infinity();
  double bad = 0;
  int bounds_calls = 0;
  double value(double x) const { return x >= bad_from ? bad : 0.25 + x / 8; }
  static double at(void* self, double x, double) { return static_cast<Ramp*>(self)->value(x); }
  static void batch(void* self, std::size_t n, const double* x, const double*, double* out) {
    for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<Ramp*>(self)->value(x[i]);
  }
  static void bounds(void* self, double x0, double, double x1, double, double* lo, double* hi) {
    ++static_cast<Ramp*>(self)->bounds_calls;  // only one thread queries where this is counted
    *lo = 0.25 + x0 / 8, *hi = 0.25 + x1 / 8;
  }
};

QueryParams ramp_query(Ramp& ramp, QueryMode mode) {
  QueryParams q;
  q.x0 = 0, q.y0 = 0, q.x1 = 6, q.y1 = 4, q.scale = 2048, q.mode = mode;
  q.density.kind = QueryDensity::Kind::kCallback;
  q.density.callback = &Ramp::at, q.density.user = &ramp, q.density.callback_max = 1.25;
  return q;
}

TEST(DensityCheckTest, AWrappedDensityThatFitsGivesTheSamePointsAndNoFinding) {
  for (const QueryMode mode : {QueryMode::kStable, QueryMode::kSmooth}) {
    Ramp ramp;
    QueryParams q = ramp_query(ramp, mode);
    const std::vector<QueryPoint> bare = run_query(q);
    DensityCheck check;
    ASSERT_EQ(check.wrap(&q.density), Status::kOk);
    const std::vector<QueryPoint> checked = run_query(q);
    EXPECT_GT(bare.size(), 10000u);
    EXPECT_TRUE(same_bits(bare, checked));
    EXPECT_FALSE(check.failed());
    char line[64];
    check.describe(line, sizeof line);
    EXPECT_STREQ(line, "no bad density value");
  }
}

TEST(DensityCheckTest, TheFirstBadValueIsRecordedWithItsPosition) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const double bad : {nan, inf, -0.5, 1.5}) {
    for (const bool batch : {false, true}) {
      Ramp ramp;
      ramp.bad_from = 5, ramp.bad = bad;
      QueryParams q = ramp_query(ramp, QueryMode::kStable);
      if (batch) q.density.callback = nullptr, q.density.batch_callback = &Ramp::batch;
      DensityCheck check;
      ASSERT_EQ(check.wrap(&q.density), Status::kOk);
      run_query(q);
      DensityFinding f;
      ASSERT_TRUE(check.failed(&f)) << bad << (batch ? " batch" : "");
      EXPECT_TRUE(std::isnan(bad) ? std::isnan(f.value) : f.value == bad);
      EXPECT_GE(f.x, 5);  // read where the flaw is, inside the region
      EXPECT_LT(f.x, 6);
      EXPECT_GE(f.y, 0);
      EXPECT_LT(f.y, 4);
      EXPECT_EQ(f.limit, 1.25);
      char line[160];
      const std::size_t length = check.describe(line, sizeof line);
      EXPECT_EQ(length, std::string(line).size());
      EXPECT_EQ(std::string(line).rfind("density callback returned ", 0), 0u) << line;
      EXPECT_EQ(std::string(line).find("above its bound callback_max 1.25") != std::string::npos, bad == 1.5)
          << line;
      check.reset();
      EXPECT_FALSE(check.failed());
    }
  }
}

// A bound far above every value costs speed, not points: the check says what the values reach.
TEST(DensityCheckTest, TheLargestValueReadShowsALooseBound) {
  Ramp ramp;
  QueryParams q = ramp_query(ramp, QueryMode::kStable);
  q.density.callback_max = 50, q.scale = 500;  // within the set's density limit at the bound
  DensityCheck check;
  EXPECT_EQ(check.largest(), -1);
  ASSERT_EQ(check.wrap(&q.density), Status::kOk);
  run_query(q);
  EXPECT_FALSE(check.failed());
  EXPECT_GT(check.largest(), 0.95);  // the ramp reaches 0.25 + 6/8 = 1 at the region's right side
  EXPECT_LE(check.largest(), 1.0);
  char line[240];
  check.describe(line, sizeof line);
  EXPECT_EQ(std::string(line).rfind("no bad density value; the largest value read, 0.9", 0), 0u) << line;
  EXPECT_NE(std::string(line).find("is under half of callback_max 50: a tighter bound"), std::string::npos)
      << line;
  check.reset();
  EXPECT_EQ(check.largest(), -1);
}

TEST(DensityCheckTest, AValueWithinRoundingOfTheBoundFits) {
  EXPECT_TRUE(density_value_fits(1 + 1e-12, 1));
  EXPECT_FALSE(density_value_fits(1 + 1e-6, 1));
  EXPECT_TRUE(density_value_fits(0, 1));
  EXPECT_FALSE(density_value_fits(-0.0001, 1));
  EXPECT_FALSE(density_value_fits(std::numeric_limits<double>::quiet_NaN(), 1));
}

TEST(DensityCheckTest, BoundsReachTheWrappedDensityWithItsOwnUser) {
  Ramp ramp;
  QueryParams q = ramp_query(ramp, QueryMode::kStable);
  q.density.bounds = &Ramp::bounds;
  const std::vector<QueryPoint> bare = run_query(q);
  const int bare_calls = ramp.bounds_calls;
  DensityCheck check;
  ASSERT_EQ(check.wrap(&q.density), Status::kOk);
  EXPECT_TRUE(same_bits(bare, run_query(q)));
  EXPECT_GT(bare_calls, 0);
  EXPECT_EQ(ramp.bounds_calls, 2 * bare_calls);
  EXPECT_FALSE(check.failed());  // true bounds
}

// Bounds that claim more than the density has (lo too high where it drops) make extra points appear; the
// check compares them with the density at 9 points of each rectangle asked.
TEST(DensityCheckTest, BoundsTheDensityBreaksAreFound) {
  Ramp ramp;
  ramp.bad_from = 4, ramp.bad = 0.05;  // drops from 0.75 to 0.05 at x = 4, which the bounds ignore
  QueryParams q = ramp_query(ramp, QueryMode::kStable);
  q.density.bounds = &Ramp::bounds;
  DensityCheck check;
  ASSERT_EQ(check.wrap(&q.density), Status::kOk);
  run_query(q);
  DensityFinding f;
  ASSERT_TRUE(check.failed(&f));
  EXPECT_EQ(f.kind, DensityFinding::Kind::kBounds);
  EXPECT_EQ(f.value, 0.05);
  EXPECT_GE(f.x, 4);
  EXPECT_GE(f.x, f.rect[0]);
  EXPECT_LE(f.x, f.rect[2]);
  EXPECT_GT(f.lo, f.value);
  char line[200];
  check.describe(line, sizeof line);
  EXPECT_EQ(std::string(line).rfind("density bounds gave [", 0), 0u) << line;
  EXPECT_NE(std::string(line).find("but the density is 0.05 at ("), std::string::npos) << line;
}

// One check per density: another density is refused, where routing two through one check would have the
// first read the second's function; the same density again (a new QueryParams per chunk, or the wrapped
// one) is taken, with its bound; reset() frees the check for another.
TEST(DensityCheckTest, OneCheckWrapsOneDensity) {
  Ramp a, b;
  QueryParams qa = ramp_query(a, QueryMode::kStable), qb = ramp_query(b, QueryMode::kStable);
  const QueryDensity bare_a = qa.density;
  DensityCheck check;
  ASSERT_EQ(check.wrap(&qa.density), Status::kOk);
  const QueryDensity before = qb.density;
  EXPECT_EQ(check.wrap(&qb.density), Status::kInvalidArgument);
  EXPECT_EQ(qb.density.user, before.user);  // refused: left as it was
  EXPECT_EQ(qb.density.callback, before.callback);
  EXPECT_EQ(check.wrap(nullptr), Status::kInvalidArgument);

  QueryDensity again = qa.density;  // the wrapped one itself: no second layer (it would call itself)
  again.callback_max = 0.5;
  ASSERT_EQ(check.wrap(&again), Status::kOk);
  EXPECT_EQ(again.user, qa.density.user);
  EXPECT_EQ(again.callback, qa.density.callback);
  QueryDensity chunk = bare_a;  // a fresh copy of the same density, with a lower bound
  chunk.callback_max = 0.5;
  ASSERT_EQ(check.wrap(&chunk), Status::kOk);
  QueryParams q = qa;
  q.density = chunk;
  run_query(q);
  DensityFinding f;
  ASSERT_TRUE(check.failed(&f));  // the ramp passes 0.5 at x = 2
  EXPECT_EQ(f.limit, 0.5);
  EXPECT_GT(f.value, 0.5);

  check.reset();
  EXPECT_FALSE(check.failed());
  ASSERT_EQ(check.wrap(&qb.density), Status::kOk);
  EXPECT_TRUE(same_bits(run_query(ramp_query(b, QueryMode::kStable)), run_query(qb)));
  EXPECT_FALSE(check.failed());
}

TEST(DensityCheckTest, AConstantOrImageDensityIsLeftAsItIs) {
  DensityCheck check;
  QueryDensity constant;
  constant.constant = 0.5;
  ASSERT_EQ(check.wrap(&constant), Status::kOk);
  EXPECT_EQ(constant.kind, QueryDensity::Kind::kConstant);
  EXPECT_EQ(constant.constant, 0.5);
  EXPECT_EQ(constant.user, nullptr);
}

/// A class query of `c` run to its end: each point with its class.
std::vector<std::pair<QueryPoint, std::uint8_t>> run_classes(const ClassQueryParams& c) {
  std::vector<QueryPoint> out(1 << 16);
  std::vector<std::uint8_t> classes(out.size());
  std::size_t written = 0;
  QueryCursor cursor;
  EXPECT_EQ(query_classes(Tileset::builtin(), c, out.data(), classes.data(), out.size(), &written, &cursor),
            Status::kOk);
  std::vector<std::pair<QueryPoint, std::uint8_t>> points;
  for (std::size_t i = 0; i < written; ++i) points.emplace_back(out[i], classes[i]);
  return points;
}

bool same_classed(const std::vector<std::pair<QueryPoint, std::uint8_t>>& a,
                  const std::vector<std::pair<QueryPoint, std::uint8_t>>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!same_bits({a[i].first}, {b[i].first}) || a[i].second != b[i].second) return false;
  return true;
}

TEST(DensityCheckTest, ClassesAndParallelQueriesAreChecked) {
  Ramp good, flawed;
  flawed.bad_from = 3, flawed.bad = -1;
  DensityCheck good_check, flawed_check;
  ClassQueryParams c;
  c.query = ramp_query(good, QueryMode::kStable);
  c.class_count = 2;
  c.classes[0] = c.query.density;
  c.classes[1] = ramp_query(flawed, QueryMode::kStable).density;
  ASSERT_EQ(good_check.wrap(&c.classes[0]), Status::kOk);
  ASSERT_EQ(flawed_check.wrap(&c.classes[1]), Status::kOk);
  EXPECT_FALSE(run_classes(c).empty());
  EXPECT_FALSE(good_check.failed());
  DensityFinding f;
  ASSERT_TRUE(flawed_check.failed(&f));
  EXPECT_EQ(f.value, -1);
  EXPECT_GE(f.x, 3);

  // Two workers read the flawed density at once: one finding, whole.
  ParallelQuery parallel;
  ASSERT_EQ(parallel.init(2), Status::kOk);
  DensityCheck check;
  QueryParams q = ramp_query(flawed, QueryMode::kSmooth);
  ASSERT_EQ(check.wrap(&q.density), Status::kOk);
  std::vector<QueryPoint> out(1 << 16);
  std::size_t written = 0;
  ASSERT_EQ(parallel.run(Tileset::builtin(), q, out.data(), out.size(), &written, std_thread_runner()),
            Status::kOk);
  ASSERT_TRUE(check.failed(&f));
  EXPECT_EQ(f.value, -1);
  EXPECT_GE(f.x, 3);
  EXPECT_EQ(f.limit, 1.25);
}

// A joint class density (three ramps from one call), with a flaw in one class right of x = `bad_from`
// and bounds that may understate class 0 by `bounds_short`.
struct JointRamps {
  double bad_from = std::numeric_limits<double>::infinity(), bad = 0, bounds_short = 0;
  static void at(void* self, double x, double y, double* v) {
    const auto& j = *static_cast<JointRamps*>(self);
    Ramp r;
    v[0] = r.value(x) * 0.25, v[1] = x >= j.bad_from ? j.bad : r.value(x) * 0.5, v[2] = r.value(y) * 0.25;
  }
  static void batch(void* self, std::size_t n, const double* x, const double* y, double* v) {
    for (std::size_t i = 0; i < n; ++i) {
      double one[3];
      at(self, x[i], y[i], one);
      for (std::size_t k = 0; k < 3; ++k) v[k * n + i] = one[k];
    }
  }
  static void bounds(void* self, double x0, double y0, double x1, double y1, double* lo, double* hi) {
    const auto& j = *static_cast<JointRamps*>(self);
    lo[0] = (0.25 + x0 / 8) * 0.25, hi[0] = (0.25 + x1 / 8) * 0.25 - j.bounds_short;
    lo[1] = (0.25 + x0 / 8) * 0.5, hi[1] = (0.25 + x1 / 8) * 0.5;
    lo[2] = (0.25 + y0 / 8) * 0.25, hi[2] = (0.25 + y1 / 8) * 0.25;
  }
};

ClassQueryParams joint_query(JointRamps& ramps, QueryMode mode, bool batch) {
  ClassQueryParams c;
  Ramp unused;
  c.query = ramp_query(unused, mode);
  c.class_count = 3;
  if (batch)
    c.joint.batch_densities = &JointRamps::batch;
  else
    c.joint.densities = &JointRamps::at;
  c.joint.bounds = &JointRamps::bounds;
  c.joint.user = &ramps;
  c.joint.max[0] = 1.25 * 0.25, c.joint.max[1] = 1.25 * 0.5, c.joint.max[2] = 1.25 * 0.25;
  return c;
}

TEST(DensityCheckTest, AJointClassDensityIsCheckedClassByClass) {
  for (const bool batch : {false, true})
    for (const QueryMode mode : {QueryMode::kStable, QueryMode::kSmooth}) {
      SCOPED_TRACE(batch ? "batch" : "one position a call");
      JointRamps fine;
      ClassQueryParams c = joint_query(fine, mode, batch);
      const auto bare = run_classes(c);
      DensityCheck check;
      ASSERT_EQ(check.wrap(&c.joint, c.class_count), Status::kOk);
      EXPECT_GT(bare.size(), 10000u);
      EXPECT_TRUE(same_classed(bare, run_classes(c)));  // the same points and classes, nothing found
      EXPECT_FALSE(check.failed());
      EXPECT_GT(check.largest(), 0.4);

      // Class 1 NaN right of x = 3, then class 0's upper bound a little short: each found, its class named.
      struct Flaw {
        JointRamps ramps;
        DensityFinding::Kind kind;
        int cls;
        const char* line;
      } flaws[] = {{JointRamps{3, std::nan(""), 0}, DensityFinding::Kind::kValue, 1,
                    "joint density's class 1 was nan at ("},
                   {JointRamps{HUGE_VAL, 0, 0.01}, DensityFinding::Kind::kBounds, 0,
                    "joint density's class 0 bounds gave ["}};
      for (Flaw& flaw : flaws) {
        ClassQueryParams flawed = joint_query(flaw.ramps, mode, batch);
        DensityCheck flawed_check;
        ASSERT_EQ(flawed_check.wrap(&flawed.joint, flawed.class_count), Status::kOk);
        run_classes(flawed);
        DensityFinding finding;
        ASSERT_TRUE(flawed_check.failed(&finding)) << flaw.line;
        EXPECT_EQ(finding.kind, flaw.kind);
        EXPECT_EQ(finding.cls, flaw.cls);
        if (flaw.kind == DensityFinding::Kind::kValue) {
          EXPECT_GE(finding.x, 3);
        }
        char line[200];
        flawed_check.describe(line, sizeof line);
        EXPECT_EQ(std::string(line).rfind(flaw.line, 0), 0u) << line;
        if (flaw.kind == DensityFinding::Kind::kBounds) {
          EXPECT_NE(std::string(line).find(", but it is "), std::string::npos) << line;
        }
      }
    }
}

TEST(DensityCheckTest, OneCheckWrapsOneJointDensity) {
  JointRamps a, b;
  ClassQueryParams ca = joint_query(a, QueryMode::kStable, false),
                   cb = joint_query(b, QueryMode::kStable, false);
  DensityCheck check;
  EXPECT_EQ(check.wrap(&ca.joint, 0), Status::kInvalidArgument);
  EXPECT_EQ(check.wrap(&ca.joint, kMaxQueryClasses + 1), Status::kInvalidArgument);
  EXPECT_EQ(check.wrap(static_cast<JointClassDensity*>(nullptr), 3), Status::kInvalidArgument);
  const JointClassDensity bare = ca.joint;
  ASSERT_EQ(check.wrap(&ca.joint, 3), Status::kOk);
  JointClassDensity again = ca.joint;  // the wrapped one itself, with a lower bound: no second layer
  again.max[1] = 0.01;
  ASSERT_EQ(check.wrap(&again, 3), Status::kOk);
  EXPECT_EQ(again.user, ca.joint.user);
  JointClassDensity chunk = bare;  // a fresh copy of the same density, with the same lower bound
  chunk.max[1] = 0.01;
  ASSERT_EQ(check.wrap(&chunk, 3), Status::kOk);
  EXPECT_EQ(check.wrap(&cb.joint, 3), Status::kInvalidArgument);  // another density
  EXPECT_EQ(cb.joint.user, &b);                                   // refused: left as it was
  Ramp ramp;
  QueryParams q = ramp_query(ramp, QueryMode::kStable);
  EXPECT_EQ(check.wrap(&q.density), Status::kInvalidArgument);  // one check, one density of either kind
  ClassQueryParams lowered = ca;
  lowered.joint = again;
  run_classes(lowered);
  DensityFinding f;
  ASSERT_TRUE(check.failed(&f));  // class 1 passes 0.01 everywhere
  EXPECT_EQ(f.cls, 1);
  EXPECT_EQ(f.limit, 0.01);
  check.reset();
  DensityCheck single;
  ASSERT_EQ(single.wrap(&q.density), Status::kOk);
  EXPECT_EQ(single.wrap(&cb.joint, 3), Status::kInvalidArgument);
}

TEST(DensityCheckTest, DescribeCutsToTheBufferAndCountsTheWholeLine) {
  Ramp ramp;
  ramp.bad_from = 1, ramp.bad = 2;
  QueryParams q = ramp_query(ramp, QueryMode::kStable);
  DensityCheck check;
  ASSERT_EQ(check.wrap(&q.density), Status::kOk);
  run_query(q);
  char whole[160], cut[12] = "untouched";
  const std::size_t length = check.describe(whole, sizeof whole);
  EXPECT_EQ(check.describe(nullptr, 0), length);
  EXPECT_EQ(check.describe(cut, sizeof cut), length);
  EXPECT_EQ(std::string(cut), std::string(whole, sizeof cut - 1));
}

}  // namespace
}  // namespace kdm
