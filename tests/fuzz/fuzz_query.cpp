// Fuzz target: query_points against the built-in set with parameters taken from the input bytes
// (any doubles, including NaN and infinities), a density of every kind, and a small resumable buffer.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "kdm/runtime/query.h"

namespace {

struct Reader {
  const std::uint8_t* data;
  std::size_t size;
  double next() {
    double v = 0;
    if (size >= sizeof v) {
      std::memcpy(&v, data, sizeof v);
      data += sizeof v, size -= sizeof v;
    }
    return v;
  }
};

double callback(void* user, double x, double y) {
  const double v = *static_cast<const double*>(user);
  return v * (x - y);  // any value, hostile ones included
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  Reader r{data + 1, size - 1};
  kdm::QueryParams q;
  q.x0 = r.next(), q.y0 = r.next(), q.x1 = r.next(), q.y1 = r.next();
  q.origin_x = r.next(), q.origin_y = r.next();
  q.tile_size = r.next(), q.scale = r.next();
  double value = r.next();
  static float texels[4 * 4];
  for (float& t : texels) t = static_cast<float>(r.next());
  kdm::DensityImageView image;
  image.width = image.height = 4;
  image.x0 = r.next(), image.y0 = r.next(), image.x1 = r.next(), image.y1 = r.next();
  image.values = texels;
  std::vector<float> mip;
  switch (data[0] % 3) {
    case 0:
      q.density.constant = value;
      break;
    case 1:
      if (kdm::make_density_max_mip(image, mip) != kdm::Status::kOk) return 0;
      q.density.kind = kdm::QueryDensity::Kind::kImage;
      q.density.image = &image;
      break;
    default:
      q.density.kind = kdm::QueryDensity::Kind::kCallback;
      q.density.callback = callback;
      q.density.user = &value;
      q.density.callback_max = r.next();
  }
  kdm::QueryPoint out[64];
  kdm::QueryCursor cursor;
  std::size_t written = 0;
  // Bounded: a few resumes (each call examines at most kMaxQueryCandidates points).
  for (int i = 0; i < 4 && kdm::query_points(kdm::Tileset::builtin(), q, out, 64, &written, &cursor) ==
                               kdm::Status::kBufferFull;
       ++i) {
  }
  return 0;
}
