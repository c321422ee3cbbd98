// The README's C++ example, compiled and run by the tests (tests/runtime/CMakeLists.txt) so it stays true.
#include <kdm/runtime/query.h>
#include <vector>

std::vector<kdm::QueryPoint> scatter(double x0, double y0, double x1, double y1) {
  kdm::QueryParams q;
  q.x0 = x0, q.y0 = y0, q.x1 = x1, q.y1 = y1;  // half-open world rectangle
  q.scale = 50;                                // points per unit area at density 1
  q.density.constant = 0.8;                    // or an image (bilinear + max-mip) or a callback
  q.tile_size = 1;                             // default: 0.8 · 50 · 1² = 40 points a tile (32–32,768)
  std::vector<kdm::QueryPoint> out(4096);
  kdm::QueryCursor cursor;
  std::size_t n = 0, total = 0;
  kdm::Status status;
  while ((status = kdm::query_points(kdm::Tileset::builtin(), q, out.data() + total, out.size() - total, &n,
                                     &cursor)) == kdm::Status::kBufferFull) {
    total += n;
    if (total == out.size()) out.resize(out.size() * 2);  // full; else it paused at its work bound
  }
  out.resize(status == kdm::Status::kOk ? total + n : 0);  // else kdm::status_message(status) says why
  return out;  // each point has a stable id (tile_x, tile_y, rank, depth) to key instances on
}

#include <cstdio>

int main() {
  const std::vector<kdm::QueryPoint> points = scatter(0, 0, 20, 20);
  // 20 × 20 units at 50 points per unit area and density 0.8: about 16,000 points.
  std::printf("%zu points\n", points.size());
  return points.size() > 15000 && points.size() < 17000 ? 0 : 1;
}
