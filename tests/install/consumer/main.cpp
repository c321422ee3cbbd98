// Uses the installed sampler (find_package(kdm) with its default components); the runtime's own
// consumers are in runtime_consumer/. Exits 0 when the sampler answers and the runtime it builds on links.
#include <kdm/generator/sampler.h>
#include <kdm/runtime/query.h>

#include <cstdio>

int main() {
  kdm::gen::SamplerOptions o;
  o.n = 100;
  const std::size_t sampled = kdm::gen::sample(o).size();
  const std::uint32_t top = kdm::Tileset::builtin().max_points_per_tile();
  std::printf("sampler %zu points, built-in set up to %u points per tile\n", sampled, top);
  return sampled == 100 && top > 0 ? 0 : 1;
}
