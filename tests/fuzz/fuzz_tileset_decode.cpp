// Fuzz target: decode_tileset on arbitrary bytes must never crash, hang or overrun; whatever it accepts
// must be a valid tile set that queries can use.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "kdm/runtime/query.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  kdm::Tileset set;
  if (kdm::Tileset::load_memory(data, size, set) != kdm::Status::kOk) return 0;
  if (kdm::validate_tileset(set.data()) != kdm::Status::kOk) std::abort();  // accepted means valid
  kdm::QueryParams q;
  q.x1 = q.y1 = 3;
  q.scale = set.max_points_per_tile() / 2.0;
  kdm::QueryPoint out[256];
  kdm::QueryCursor cursor;
  std::size_t written = 0;
  for (int i = 0;
       i < 64 && kdm::query_points(set, q, out, 256, &written, &cursor) == kdm::Status::kBufferFull; ++i) {
  }
  // Smooth mode three times past the top level: a set with a hand-over descends into its subtiles.
  q.mode = kdm::QueryMode::kSmooth, q.x1 = q.y1 = 0.05, q.scale = 3.0 * set.max_points_per_tile() / 0.0025;
  q.scale = std::min(q.scale, kdm::query_density_limit(set, q.mode));
  cursor = kdm::QueryCursor{};
  for (int i = 0;
       i < 64 && kdm::query_points(set, q, out, 256, &written, &cursor) == kdm::Status::kBufferFull; ++i) {
  }
  return 0;
}
