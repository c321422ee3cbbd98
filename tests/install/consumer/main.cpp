// Uses the installed sampler and runtime (find_package(kdm) with its default components), and the tile set
// the build baked (kdm_bake_tileset), from its file and embedded; the runtime's own consumers are in
// runtime_consumer/. Exits 0 when the sampler answers, both tile sets load
// and the embedded bytes are the file's.
#include <kdm/generator/sampler.h>
#include <kdm/runtime/query.h>

#include "small_tiles_data.h"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

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
  kdm::Tileset embedded;
  if (kdm::Tileset::load_memory(small_tiles_data, small_tiles_data_size, embedded, &detail) !=
      kdm::Status::kOk) {
    std::printf("the embedded set did not load: %s\n", detail.c_str());
    return 1;
  }
  std::ifstream file(KDM_BAKED_SET, std::ios::binary);
  const std::vector<char> bytes{std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
  const bool same = bytes.size() == small_tiles_data_size &&
                    std::memcmp(bytes.data(), small_tiles_data, small_tiles_data_size) == 0;
  std::printf(
      "sampler %zu points, built-in set up to %u points per tile, baked set up to %u (embedded %u, %s)\n",
      sampled, top, baked.max_points_per_tile(), embedded.max_points_per_tile(),
      same ? "the file's bytes" : "NOT the file's bytes");
  return sampled == 100 && top > 0 && same ? 0 : 1;
}
