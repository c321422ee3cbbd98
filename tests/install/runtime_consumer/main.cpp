// Links only the installed runtime's C++ API, built as engines build (no exceptions, no RTTI).
#include <kdm/runtime/query.h>

#include <cstdio>

int main() {
  kdm::QueryParams q;
  q.x1 = q.y1 = 4;
  q.scale = 100;
  kdm::QueryPoint points[4096];
  kdm::QueryCursor cursor;
  std::size_t n = 0;
  const kdm::Status s = kdm::query_points(kdm::Tileset::builtin(), q, points, 4096, &n, &cursor);
  const std::size_t emitted = n;
  kdm::QueryProblem problem;
  q.scale = 1e6;
  kdm::QueryCursor fresh;
  const kdm::Status refused =
      kdm::query_points(kdm::Tileset::builtin(), q, points, 4096, &n, &fresh, &problem);
  std::printf("c++: %zu points; scale 1e6 refused: %s (largest scale %g)\n", emitted,
              kdm::query_problem_message(problem.kind), problem.largest_valid);
  return s == kdm::Status::kOk && emitted > 1540 && emitted < 1660 &&
                 refused == kdm::Status::kInvalidArgument &&
                 problem.kind == kdm::QueryProblem::Kind::kDensityTooHigh
             ? 0
             : 1;
}
