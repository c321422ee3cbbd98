// Class queries' points by id, for the tests that compare them: whole queries resumed through a buffer,
// one-class queries, bit-for-bit comparison, no allocation, and three images on one grid to query.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <tuple>
#include <vector>

#include "allocation_counter.h"
#include "kdm/runtime/class_query.h"
#include "random_partition.h"

namespace kdm::testing {

using Id = std::tuple<std::int64_t, std::int64_t, std::uint32_t, std::uint32_t>;
struct Emitted {
  double x, y;
  int cls;
};
using Points = std::map<Id, Emitted>;

inline Id id_of(const QueryPoint& p) {
  return {p.id.tile_x, p.id.tile_y, p.id.rank, p.id.depth};
}

/// query_classes over `q`, resumed through a buffer of `capacity`: each point once, with its class.
inline Points run_classes(const ClassQueryParams& q, std::size_t capacity = 1 << 14) {
  std::vector<QueryPoint> out(capacity);
  std::vector<std::uint8_t> classes(capacity);
  Points points;
  QueryCursor cursor;
  for (;;) {
    std::size_t written = 0;
    const Status s =
        query_classes(Tileset::builtin(), q, out.data(), classes.data(), out.size(), &written, &cursor);
    EXPECT_TRUE(s == Status::kOk || s == Status::kBufferFull) << status_message(s);
    for (std::size_t i = 0; i < written; ++i) {
      EXPECT_LT(classes[i], q.class_count);
      EXPECT_TRUE(points.emplace(id_of(out[i]), Emitted{out[i].x, out[i].y, classes[i]}).second)
          << "a point emitted twice";
    }
    if (s != Status::kBufferFull) break;
  }
  return points;
}

/// query_points over `q`, every point of class 0.
inline Points run_one(const QueryParams& q) {
  std::vector<QueryPoint> out(1 << 14);
  Points points;
  QueryCursor cursor;
  for (;;) {
    std::size_t written = 0;
    const Status s = query_points(Tileset::builtin(), q, out.data(), out.size(), &written, &cursor);
    EXPECT_TRUE(s == Status::kOk || s == Status::kBufferFull) << status_message(s);
    for (std::size_t i = 0; i < written; ++i) points.emplace(id_of(out[i]), Emitted{out[i].x, out[i].y, 0});
    if (s != Status::kBufferFull) break;
  }
  return points;
}

/// The points of `all` whose class is at most `last`.
inline Points up_to_class(const Points& all, int last) {
  Points some;
  for (const auto& [id, p] : all)
    if (p.cls <= last) some.emplace(id, p);
  return some;
}

/// Whether two point sets hold the same ids at the same positions (bit for bit).
inline void expect_same(const Points& a, const Points& b, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  auto j = b.begin();
  for (auto i = a.begin(); i != a.end(); ++i, ++j) {
    ASSERT_TRUE(i->first == j->first) << what;
    ASSERT_EQ(i->second.x, j->second.x) << what;
    ASSERT_EQ(i->second.y, j->second.y) << what;
  }
}

/// Parts of `whole` (a random grid of them) give its points and classes, the whole resumed many times;
/// returns the whole's count per class.
inline std::vector<std::size_t> expect_parts_give_the_whole(const ClassQueryParams& whole,
                                                            std::mt19937& rng) {
  const Points all = run_classes(whole, 1000);
  Points joined;
  for (const QueryParams& part : random_grid_parts(whole.query, 4, rng)) {
    ClassQueryParams p = whole;
    p.query = part;
    for (const auto& [id, e] : run_classes(p)) EXPECT_TRUE(joined.emplace(id, e).second);
  }
  expect_same(all, joined, "parts");
  std::vector<std::size_t> counts(whole.class_count);
  for (const auto& [id, e] : all) {
    EXPECT_EQ(e.cls, joined.at(id).cls);
    ++counts.at(e.cls);
  }
  return counts;
}

/// Runs `q` in both modes into records and into the compact output with keys (each emitting more than
/// 10,000 points) and expects no allocation among them.
inline void expect_class_queries_allocate_nothing(ClassQueryParams q) {
  std::vector<QueryPoint> out(1 << 16);
  std::vector<std::uint8_t> classes(out.size());
  std::vector<float> xy(2 * out.size());
  std::vector<std::uint64_t> keys(out.size());
  (void)Tileset::builtin();
  const long before = allocations();
  for (QueryMode mode : {QueryMode::kStable, QueryMode::kSmooth}) {
    q.query.mode = mode;
    QueryCursor cursor;
    std::size_t written = 0;
    EXPECT_EQ(query_classes(Tileset::builtin(), q, out.data(), classes.data(), out.size(), &written, &cursor),
              Status::kOk);
    EXPECT_GT(written, 10000u);
    cursor = QueryCursor{};
    EXPECT_EQ(query_classes_compact(Tileset::builtin(), q, CompactPoints{xy.data(), keys.data()},
                                    classes.data(), out.size(), &written, &cursor),
              Status::kOk);
    EXPECT_GT(written, 10000u);
  }
  EXPECT_EQ(allocations(), before);
}

/// Three images over [0, 4)²: a ramp in x, a ramp in y and a bump, each with its max-mip.
struct ThreeImages {
  std::vector<float> values[3], mips[3];
  DensityImageView views[3];
  ThreeImages() {
    for (int k = 0; k < 3; ++k) {
      values[k].resize(32 * 32);
      for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) {
          const double u = (x + 0.5) / 32, v = (y + 0.5) / 32;
          values[k][y * 32 + x] =
              static_cast<float>(k == 0   ? u
                                 : k == 1 ? 0.2 + v
                                          : std::exp(-8 * ((u - 0.5) * (u - 0.5) + (v - 0.5) * (v - 0.5))));
        }
      DensityImageView& view = views[k];
      view.width = view.height = 32;
      view.x1 = view.y1 = 4;
      view.values = values[k].data();
      EXPECT_EQ(make_density_max_mip(view, mips[k]), Status::kOk);
    }
  }
};

}  // namespace kdm::testing
