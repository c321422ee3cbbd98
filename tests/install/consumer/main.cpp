// Uses the installed sampler and runtime (find_package(kdm) with its default components), and the tile set
// the build baked (kdm_bake_tileset); the runtime's own consumers are in runtime_consumer/. Exits 0 when
// the sampler answers and both tile sets load.
#include <kdm/generator/sampler.h>
#include <kdm/runtime/query.h>

#include <cstdio>
#include <string>

int main() {
  kdm::gen::SamplerOptions o;
  o.n = 100;
  const std::size_t sampled = kdm::gen::sample(o).size();
  const std::uint32_t top = kdm::Tileset::builtin().max_points_per_tile();
  kdm::Tileset baked;
  std::string detail;
  if (kdm::Tileset::load_file(KDM_BAKED_SET, baked, &detail) != kdm::Status::kOk) {
    std::printf("the baked set did not load: %s\n", detail.c_str());
    return 1;
  }
  std::printf("sampler %zu points, built-in set up to %u points per tile, baked set up to %u\n", sampled, top,
              baked.max_points_per_tile());
  return sampled == 100 && top > 0 ? 0 : 1;
}
