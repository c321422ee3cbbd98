// Test helpers: a query run to completion through a resumed buffer, and bitwise comparison of results.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "kdm/runtime/query.h"

namespace kdm::testing {

/// Every point of `q` on the built-in set, collected through a buffer of `chunk` points.
inline std::vector<QueryPoint> run_query(const QueryParams& q, std::size_t chunk = 1 << 14) {
  std::vector<QueryPoint> all, out(chunk);
  QueryCursor cursor;
  for (;;) {
    std::size_t written = 0;
    const Status s = query_points(Tileset::builtin(), q, out.data(), out.size(), &written, &cursor);
    EXPECT_TRUE(s == Status::kOk || s == Status::kBufferFull) << status_message(s);
    all.insert(all.end(), out.begin(), out.begin() + written);
    if (s != Status::kBufferFull) return all;
  }
}

/// Why query_points refuses `q` (a failure if it does not).
inline QueryProblem refusal(const QueryParams& q) {
  std::vector<QueryPoint> out(16);
  std::size_t written = 0;
  QueryCursor cursor;
  QueryProblem problem;
  EXPECT_EQ(query_points(Tileset::builtin(), q, out.data(), out.size(), &written, &cursor, &problem),
            Status::kInvalidArgument);
  return problem;
}

/// Whether two results are the same points in the same order, bit for bit.
inline bool same_bits(const std::vector<QueryPoint>& a, const std::vector<QueryPoint>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(QueryPoint)) == 0;
}

}  // namespace kdm::testing
