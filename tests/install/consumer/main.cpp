// Uses the installed runtime (built-in tile set) and sampler; exits 0 when both answer sensibly.
#include <kdm/generator/sampler.h>
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
  kdm::gen::SamplerOptions o;
  o.n = 100;
  const std::size_t sampled = kdm::gen::sample(o).size();
  std::printf("runtime %zu points, sampler %zu points\n", n, sampled);
  // 4×4 tiles at 100 points each: tiles hold their level's nominal count within a few percent.
  return s == kdm::Status::kOk && n > 1540 && n < 1660 && sampled == 100 ? 0 : 1;
}
