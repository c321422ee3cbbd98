// Reading and writing kdm tile sets (format described in kdm/runtime/tileset.h). The reader treats its
// input as untrusted: it checks magic, version, sizes, both checksums and the reader caps before it
// allocates, parses the body as zstd decompresses it (never holding it whole, so a small file that
// decompresses to hundreds of megabytes costs only zstd's window), parses counts against the bytes the
// header says are left, and validates the structure it built. What it allocates goes through the
// tile-set allocator (allocator.h), zstd's memory included.
#define ZSTD_STATIC_LINKING_ONLY  // ZSTD_createDCtx_advanced: zstd's memory through the tile-set allocator
#include <zstd.h>
#include <zstd_errors.h>

#include <algorithm>
#include <cereal/archives/portable_binary.hpp>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <new>
#include <sstream>
#include <streambuf>
#include <tuple>
#include <type_traits>
#include <vector>

#include <sys/stat.h>

#include "crc32.h"
#include "kdm/runtime/tileset_format.h"
#include "query_tables.h"

namespace kdm {
namespace {

constexpr char kMagic[8] = {'K', 'D', 'M', 'T', 'I', 'L', 'E', 'S'};
constexpr std::size_t kFixedHeaderBytes = 64;
constexpr std::size_t kHeaderCrcOffset = 60;

struct ContentError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

Status fail(Status status, std::string* detail, const std::string& message) {
  if (detail) *detail = message;
  return status;
}

void put32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void put64(std::uint8_t* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
std::uint32_t get32(const std::uint8_t* p) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
std::uint64_t get64(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

std::uint32_t header_crc(const std::uint8_t* header, std::size_t size) {
  std::uint8_t zero[4] = {0, 0, 0, 0};
  std::uint32_t crc = detail::crc32(header, kHeaderCrcOffset);
  crc = detail::crc32(zero, 4, crc);
  return detail::crc32(header + kFixedHeaderBytes, size - kFixedHeaderBytes, crc);
}

/// zstd's memory from the tile-set allocator's hooks (operator new without them). zstd frees by address
/// alone, so each block carries its size in front.
constexpr std::size_t kBlockPrefix = alignof(std::max_align_t);
void* zstd_allocate(void* opaque, std::size_t size) {
  const auto& hooks = *static_cast<const AllocatorHooks*>(opaque);
  if (size > SIZE_MAX - kBlockPrefix) return nullptr;
  const std::size_t bytes = size + kBlockPrefix;
  void* p =
      hooks.allocate ? hooks.allocate(bytes, kBlockPrefix, hooks.user) : ::operator new(bytes, std::nothrow);
  if (!p) return nullptr;
  std::memcpy(p, &bytes, sizeof bytes);
  return static_cast<char*>(p) + kBlockPrefix;
}
void zstd_free(void* opaque, void* address) {
  if (!address) return;
  const auto& hooks = *static_cast<const AllocatorHooks*>(opaque);
  void* p = static_cast<char*>(address) - kBlockPrefix;
  std::size_t bytes = 0;
  std::memcpy(&bytes, p, sizeof bytes);
  if (hooks.deallocate)
    hooks.deallocate(p, bytes, kBlockPrefix, hooks.user);
  else
    ::operator delete(p);
}

/// The body as zstd decompresses the payload, a chunk at a time: the parser reads it as a stream, so only
/// zstd's window (at most the body's size) and one chunk are held. It never gives more than the header's
/// body size B, and remaining() is what is left of B, the bound every count is checked against.
class ZstdBody : public std::streambuf {
 public:
  ZstdBody(ZSTD_DCtx* zstd, const void* payload, std::size_t payload_size, std::uint64_t body_size)
      : zstd_(zstd), in_{payload, payload_size, 0}, body_(body_size) {}
  /// The chunk buffer (zstd's block, or the whole body if smaller), through the tile-set allocator
  /// (throws std::bad_alloc when refused).
  void allocate_chunk() {
    chunk_.resize(static_cast<std::size_t>(
        std::max<std::uint64_t>(1, std::min<std::uint64_t>(body_, ZSTD_DStreamOutSize()))));
  }
  std::uint64_t remaining() const { return body_ - (produced_ - std::uint64_t(egptr() - gptr())); }
  /// zstd's error code, where it failed (0 if it did not).
  std::size_t error() const { return error_; }
  /// After the whole body was read: whether the frame ends there (else error() says why, or it is longer).
  bool finish() {
    if (gptr() != egptr() || produced_ != body_) return false;
    char extra;
    while (!ended_) {
      ZSTD_outBuffer out{&extra, 1, 0};
      const std::size_t before = in_.pos, r = ZSTD_decompressStream(zstd_, &out, &in_);
      if (ZSTD_isError(r)) return error_ = r, false;
      if (out.pos) return false;                      // more than B bytes
      if (r != 0 && in_.pos == before) return false;  // no progress: the frame is cut short
      ended_ = r == 0;
    }
    return in_.pos == in_.size;
  }

 protected:
  int_type underflow() override {
    if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
    const std::size_t n = fill(chunk_.data(), chunk_.size());
    if (n == 0) return traits_type::eof();
    setg(chunk_.data(), chunk_.data(), chunk_.data() + n);
    return traits_type::to_int_type(*gptr());
  }
  /// Large reads (a tile's arrays) are decompressed straight into the destination.
  std::streamsize xsgetn(char* s, std::streamsize n) override {
    std::streamsize done = 0;
    while (done < n) {
      if (gptr() == egptr() && std::size_t(n - done) >= chunk_.size()) {
        const std::size_t got = fill(s + done, std::size_t(n - done));
        if (got == 0) break;
        done += std::streamsize(got);
        continue;
      }
      if (gptr() == egptr() && traits_type::eq_int_type(underflow(), traits_type::eof())) break;
      const std::streamsize k = std::min<std::streamsize>(n - done, egptr() - gptr());
      std::memcpy(s + done, gptr(), std::size_t(k));
      gbump(static_cast<int>(k));
      done += k;
    }
    return done;
  }

 private:
  /// Decompresses at most `size` bytes, and never past B, into `out`: how many (0 at B, or where zstd
  /// failed or stopped making progress).
  std::size_t fill(char* out, std::size_t size) {
    ZSTD_outBuffer o{out, static_cast<std::size_t>(std::min<std::uint64_t>(size, body_ - produced_)), 0};
    while (o.pos == 0 && o.size > 0 && error_ == 0 && !ended_) {
      const std::size_t before = in_.pos, r = ZSTD_decompressStream(zstd_, &o, &in_);
      if (ZSTD_isError(r))
        error_ = r;
      else if (r == 0)
        ended_ = true;  // short of B if nothing came (zstd checks the frame's size itself too)
      else if (o.pos == 0 && in_.pos == before)
        break;  // no progress: the frame is cut short
    }
    produced_ += o.pos;
    return o.pos;
  }

  ZSTD_DCtx* zstd_;
  ZSTD_inBuffer in_;
  std::uint64_t body_, produced_ = 0;
  std::size_t error_ = 0;
  bool ended_ = false;  // zstd has said the frame is complete
  TilesetArray<char> chunk_;
};

using InputArchive = cereal::PortableBinaryInputArchive;

template <class Array>
void save_array(cereal::PortableBinaryOutputArchive& ar, const Array& v) {
  using T = typename Array::value_type;
  ar(cereal::make_size_tag(static_cast<cereal::size_type>(v.size())));
  ar(cereal::binary_data(const_cast<T*>(v.data()), v.size() * sizeof(T)));
}

/// An array's size tag, checked against the bytes left of the body's stated size: a count larger than
/// they hold cannot be genuine, and is refused before anything is allocated for it.
cereal::size_type load_count(InputArchive& ar, const ZstdBody& body, std::size_t element_bytes) {
  cereal::size_type n = 0;
  ar(cereal::make_size_tag(n));
  if (n > body.remaining() / element_bytes)
    throw ContentError("an array claims " + std::to_string(n) + " elements, more than the payload holds");
  return n;
}

template <class Array>
void load_array(InputArchive& ar, const ZstdBody& body, Array& v) {
  using T = typename Array::value_type;
  v.resize(static_cast<std::size_t>(load_count(ar, body, sizeof(T))));
  ar(cereal::binary_data(v.data(), v.size() * sizeof(T)));
}

/// Each keyframe's offset of a point that also has one at the keyframe before is stored as the difference
/// (mod 2^8): the values are then the point's motion between two keyframes, a fraction of a spacing, which
/// compresses better than the offsets themselves.
/// glide_differences and glide_sums undo each other; sizes must be valid (validate_tileset).
template <class Value>
std::vector<Value> glide_differences(const TilesetData& set, const Tile& tile,
                                     const std::vector<Value>& offsets) {
  std::vector<Value> v(offsets);
  std::size_t at = v.size();
  for (std::size_t g = set.keyframe_nominal.size(); g-- > 1;) {  // backwards: the earlier keyframe is intact
    const std::size_t n = 2 * std::size_t(set.offsets_at_keyframe(tile, g)),
                      before = 2 * std::size_t(set.offsets_at_keyframe(tile, g - 1));
    at -= n;
    for (std::size_t i = 0; i < before; ++i)
      v[at + i] = static_cast<Value>(v[at + i] - offsets[at - before + i]);
  }
  return v;
}
template <class Array>
void glide_sums(const TilesetData& set, const Tile& tile, Array& v) {
  using Value = typename Array::value_type;
  using Unsigned = std::make_unsigned_t<Value>;  // sums mod 2^bits, as the differences were taken
  std::size_t at = 0;
  for (std::size_t g = 0; g < set.keyframe_nominal.size(); ++g) {
    const std::size_t n = 2 * std::size_t(set.offsets_at_keyframe(tile, g));
    const std::size_t before = g ? 2 * std::size_t(set.offsets_at_keyframe(tile, g - 1)) : 0;
    for (std::size_t i = 0; i < before; ++i)
      v[at + i] =
          static_cast<Value>(static_cast<Unsigned>(Unsigned(v[at + i]) + Unsigned(v[at - before + i])));
    at += n;
  }
}

/// Format 3's glide offsets (16-bit differences, in 1/65536 tile sides) into tile.glide's 8-bit units,
/// rounded and clamped: format 3 sets keep their glide track to within a 64th of a spacing.
void glide_from_format3(const TilesetData& set, TilesetArray<std::uint16_t>& stored, Tile& tile) {
  glide_sums(set, tile, stored);
  tile.glide.resize(stored.size());
  std::size_t at = 0;
  for (std::size_t g = 0; g < set.keyframe_nominal.size(); ++g) {
    const std::size_t n = 2 * std::size_t(set.offsets_at_keyframe(tile, g));
    const double units = 1.0 / (65536.0 * set.glide_unit(g));
    for (std::size_t i = at; i < at + n; ++i) {
      const double u = std::round(static_cast<std::int16_t>(stored[i]) * units);
      tile.glide[i] = static_cast<std::int8_t>(u < -127 ? -127 : (u > 127 ? 127 : u));
    }
    at += n;
  }
}

std::uint32_t version_for(const TilesetData& set) {
  return tileset_format_version_for(set);
}

std::vector<std::uint8_t> serialise_body(const TilesetData& set) {
  std::ostringstream stream(std::ios::binary);
  const std::uint32_t version = version_for(set);
  const bool handover = version >= 5;
  {
    cereal::PortableBinaryOutputArchive ar(stream);
    ar(set.colours, set.levels, static_cast<std::uint32_t>(set.tiles.size()));
    save_array(ar, set.level_nominal);
    save_array(ar, set.keyframe_nominal);
    if (handover) ar(set.handover_zone);
    if (version >= 6) ar(set.handover_level);
    if (version >= 7) ar(set.handover_slack);
    std::vector<std::uint16_t> xy;
    for (const Tile& tile : set.tiles) {
      save_array(ar, tile.level_end);
      xy.resize(tile.points.size() * 2);
      for (std::size_t i = 0; i < tile.points.size(); ++i)
        xy[2 * i] = tile.points[i].x, xy[2 * i + 1] = tile.points[i].y;
      save_array(ar, xy);
      save_array(ar, tile.keys);
      const std::vector<std::uint8_t> offsets(tile.glide.begin(), tile.glide.end());
      save_array(ar, glide_differences(set, tile, offsets));
      if (handover) {
        save_array(ar, tile.handover);
        save_array(ar, tile.appearing);
      }
    }
  }
  const std::string bytes = stream.str();
  return std::vector<std::uint8_t>(bytes.begin(), bytes.end());
}

/// Parses the body from `body` into `set`: format 3's glide offsets into `glide16` (tile.glide only sized),
/// later formats' into tile.glide as stored (differences: glide_sums once the set is validated).
void parse_body(ZstdBody& body, std::uint32_t version, TilesetData& set,
                TilesetArray<TilesetArray<std::uint16_t>>& glide16) {
  // cereal's endianness flag: 1 little-, 0 big-endian; cereal itself would take anything else as "other".
  const auto flag = body.sgetc();
  if (flag != 0 && flag != 1) throw ContentError("bad byte-order flag");
  std::istream stream(&body);
  InputArchive ar(stream);
  std::uint32_t tile_count = 0;
  ar(set.colours, set.levels, tile_count);
  load_array(ar, body, set.level_nominal);
  const bool gliding = version >= 3, handover = version >= 5;
  if (gliding) load_array(ar, body, set.keyframe_nominal);
  if (handover) ar(set.handover_zone);
  if (version >= 6) ar(set.handover_level);
  if (version >= 7) ar(set.handover_slack);
  // Every tile takes at least three size tags (8 bytes each), which bounds the count by the bytes left.
  if (tile_count > body.remaining() / (handover ? 48 : gliding ? 32 : 24))
    throw ContentError("tile count exceeds the payload");
  set.tiles.resize(tile_count);
  if (version == 3) glide16.resize(tile_count);
  static_assert(sizeof(TilePoint) == 2 * sizeof(std::uint16_t) && std::is_standard_layout_v<TilePoint>,
                "a tile's points are its stored (x, y) pairs");
  for (std::size_t t = 0; t < set.tiles.size(); ++t) {
    Tile& tile = set.tiles[t];
    load_array(ar, body, tile.level_end);
    const cereal::size_type xy = load_count(ar, body, sizeof(std::uint16_t));
    if (xy % 2) throw ContentError("a tile has an odd number of coordinates");
    tile.points.resize(static_cast<std::size_t>(xy / 2));
    ar(cereal::binary_data(reinterpret_cast<std::uint16_t*>(tile.points.data()), xy * sizeof(std::uint16_t)));
    load_array(ar, body, tile.keys);
    if (version == 3) {
      load_array(ar, body, glide16[t]);
      tile.glide.resize(glide16[t].size());  // the size for validation; the values after it
    } else if (gliding) {
      load_array(ar, body, tile.glide);
    }
    if (handover) {
      load_array(ar, body, tile.handover);
      load_array(ar, body, tile.appearing);
    }
  }
  if (body.remaining() != 0) throw ContentError("payload has bytes after the last tile");
}

/// Decompresses the payload (one zstd frame of `body_size` bytes, checked) and parses it into `set` as one
/// stream: kOk, or kInvalidContent, kDecompressionFailed (zstd's failure explains whatever the parser made
/// of the bytes it did not get) or kOutOfMemory, with `detail`.
Status read_body(const std::uint8_t* payload, std::size_t payload_size, std::uint64_t body_size,
                 std::uint32_t version, TilesetData& set, TilesetArray<TilesetArray<std::uint16_t>>& glide16,
                 std::string* detail) {
  AllocatorHooks hooks = tileset_allocator();
  const ZSTD_customMem memory{zstd_allocate, zstd_free, &hooks};
  const std::unique_ptr<ZSTD_DCtx, std::size_t (*)(ZSTD_DCtx*)> zstd(ZSTD_createDCtx_advanced(memory),
                                                                     ZSTD_freeDCtx);
  if (!zstd) return fail(Status::kOutOfMemory, detail, "payload: no memory to decompress it");
  // Any window, as a decoder of the whole frame at once takes: zstd's buffer is at most the body's size.
  ZSTD_DCtx_setParameter(zstd.get(), ZSTD_d_windowLogMax, ZSTD_WINDOWLOG_MAX);
  ZstdBody body(zstd.get(), payload, payload_size, body_size);
  Status status = Status::kOk;
  std::string problem;
  try {
    body.allocate_chunk();
    parse_body(body, version, set, glide16);
    if (!body.finish())
      status = Status::kDecompressionFailed, problem = "payload: the frame does not end at the stated size";
  } catch (const std::bad_alloc&) {  // not damage
    status = Status::kOutOfMemory, problem = "payload: an allocation failed";
  } catch (const cereal::Exception&) {  // its own words ("Failed to read 8 bytes ...") say less than these
    status = Status::kInvalidContent, problem = "payload: its records end before their stated sizes";
  } catch (const std::exception& e) {
    status = Status::kInvalidContent, problem = std::string("payload: ") + e.what();
  }
  if (body.error()) {
    if (ZSTD_getErrorCode(body.error()) == ZSTD_error_memory_allocation)
      return fail(Status::kOutOfMemory, detail, "payload: no memory to decompress it");
    return fail(Status::kDecompressionFailed, detail, ZSTD_getErrorName(body.error()));
  }
  return status == Status::kOk ? status : fail(status, detail, problem);
}

/// The first problem of a set's hand-over tables (empty if none): every point of a tile glides onto its own
/// sub-point of that tile's subtiles at the hand-over keyframe h, and those no point takes appear, each once.
std::string handover_problem(const TilesetData& set) {
  const std::uint32_t m = set.subtiles_per_side(), zone = set.handover_zone;
  if (set.keyframe_nominal.size() < 2) return "a hand-over needs a glide track of at least two keyframes";
  if (set.handover_level + 1 >= set.levels)
    return "the hand-over level " + std::to_string(set.handover_level) + " is not below the top level";
  if (m < 2 || m > 256) return "a hand-over needs N_top / N_j to be the square of an integer m in 2..256";
  if (2 * std::uint64_t(zone) + 1 >= m) return "the hand-over zone " + std::to_string(zone) + " is too wide";
  if (set.handover_slack > kMaxHandoverSlack)
    return "the hand-over slack " + std::to_string(set.handover_slack) + " is above " +
           std::to_string(kMaxHandoverSlack);
  const std::size_t h = set.handover_keyframe();
  if (h + 1 >= set.keyframe_nominal.size()) return "the hand-over keyframe is the top one";
  TilesetArray<std::uint32_t> present(set.tiles.size());  // points at keyframe h, per tile
  for (std::size_t t = 0; t < set.tiles.size(); ++t) present[t] = set.points_at_keyframe(set.tiles[t], h);
  TilesetArray<std::uint32_t> type(std::size_t(m) * m);
  TilesetArray<std::uint64_t> first(std::size_t(m) * m + 1);  // m² · 2^32 points would wrap 32 bits
  TilesetArray<char> taken;
  for (std::size_t t = 0; t < set.tiles.size(); ++t) {
    const Tile& tile = set.tiles[t];
    const std::string name = "tile " + std::to_string(t);
    if (tile.handover.size() != tile.points.size())
      return name + " has " + std::to_string(tile.handover.size()) + " hand-over targets for " +
             std::to_string(tile.points.size()) + " points";
    for (std::uint32_t j = 0; j < m * m; ++j) {
      type[j] = std::uint32_t(set.subtile_index(t, j % m, j / m));
      first[j + 1] = first[j] + present[type[j]];
    }
    // Before `taken` is sized by the subtiles' points (m² times a tile's): a forged count costs nothing.
    if (tile.handover.size() + tile.appearing.size() != first.back())
      return name + " leaves some of its subtiles' points out of the hand-over";
    taken.assign(static_cast<std::size_t>(first.back()), 0);
    const auto take = [&](std::uint32_t j, std::uint32_t q) -> std::string {
      if (q >= present[type[j]])
        return name + " names rank " + std::to_string(q) + " of subtile " + std::to_string(j) +
               ", which has " + std::to_string(present[type[j]]) + " at keyframe " + std::to_string(h);
      if (taken[first[j] + q]++) return name + " takes a sub-point twice";
      return {};
    };
    for (std::size_t r = 0; r < tile.points.size(); ++r) {
      const std::uint32_t v = tile.handover[r], d = v % 25;
      const std::int64_t x =
          std::int64_t(TilesetShape::subtile_of(tile.points[r].x, m)) + std::int64_t(d % 5) - 2;
      const std::int64_t y =
          std::int64_t(TilesetShape::subtile_of(tile.points[r].y, m)) + std::int64_t(d / 5) - 2;
      if (x < 0 || y < 0 || x >= m || y >= m) return name + " sends a point to a subtile outside it";
      if (std::string problem = take(std::uint32_t(y * m + x), v / 25); !problem.empty()) return problem;
    }
    for (std::uint32_t v : tile.appearing) {
      if ((v >> 16) >= m * m) return name + " has an appearing sub-point outside its subtiles";
      if (std::string problem = take(v >> 16, v & 0xFFFF); !problem.empty()) return problem;
    }
  }
  return {};
}

}  // namespace

std::uint32_t tileset_format_version_for(const TilesetShape& set) {
  // The oldest that holds it, so that older recipes rebake byte for byte.
  return !set.handover_zone ? 4 : set.handover_slack ? 7 : set.handover_level ? 6 : 5;
}

namespace {

/// coarsest_level_thresholds into `out`, whose tiles' arrays already hold at least their coarsest level's
/// ranks; its scratch through the tile-set allocator.
template <class Thresholds>
void coarsest_thresholds_into(const TilesetData& set, Thresholds& out) {
  struct Coarsest {
    float threshold;
    std::uint32_t tie;  // how many earlier ranks of its tile have the same threshold
    std::uint32_t tile, rank;
  };
  TilesetArray<Coarsest> coarsest;
  for (std::size_t t = 0; t < set.tiles.size(); ++t) {
    const Tile& tile = set.tiles[t];
    const std::uint32_t count = tile.level_end.empty() ? 0 : tile.level_end[0];
    for (std::uint32_t i = 0; i < count; ++i) {
      const float threshold = set.emission_threshold(0, tile.keys[i]);
      const bool tied = i > 0 && coarsest.back().threshold == threshold;
      coarsest.push_back({threshold, tied ? coarsest.back().tie + 1 : 0, static_cast<std::uint32_t>(t), i});
    }
  }
  std::sort(coarsest.begin(), coarsest.end(), [](const Coarsest& a, const Coarsest& b) {
    return std::tie(a.threshold, a.tie, a.tile) < std::tie(b.threshold, b.tie, b.tile);
  });
  // Spread over (0, N_0) as the keys are, so the level is complete where it was.
  const double step = double(set.level_nominal[0]) / double(coarsest.size());
  for (std::size_t i = 0; i < coarsest.size(); ++i)
    out[coarsest[i].tile][coarsest[i].rank] = static_cast<float>((double(i) + 0.5) * step);
}

}  // namespace

std::vector<std::vector<float>> coarsest_level_thresholds(const TilesetData& set) {
  std::vector<std::vector<float>> out(set.tiles.size());
  for (std::size_t t = 0; t < set.tiles.size(); ++t)
    out[t].resize(set.tiles[t].level_end.empty() ? 0 : set.tiles[t].level_end[0]);
  coarsest_thresholds_into(set, out);
  return out;
}

void detail::coarsest_level_thresholds_into(const TilesetData& set, TilesetArray<TilesetArray<float>>& out) {
  coarsest_thresholds_into(set, out);
}

Status validate_tileset(const TilesetData& set, std::string* detail) {
  auto bad = [&](const std::string& m) { return fail(Status::kInvalidContent, detail, m); };
  if (set.colours < 1 || set.colours > kMaxTileColours)
    return bad("colour count " + std::to_string(set.colours) + " is outside 1.." +
               std::to_string(kMaxTileColours));
  if (set.levels < 1 || set.levels > kMaxTileLevels)
    return bad("level count " + std::to_string(set.levels) + " is outside 1.." +
               std::to_string(kMaxTileLevels));
  if (set.level_nominal.size() != set.levels) return bad("the nominal level table has a wrong size");
  for (std::size_t k = 0; k < set.level_nominal.size(); ++k)
    if (set.level_nominal[k] <= (k ? set.level_nominal[k - 1] : 0u))
      return bad("nominal level counts are not strictly increasing");
  const std::size_t expected = std::size_t(set.colours) * set.colours * set.colours * set.colours;
  if (set.tiles.size() != expected)
    return bad("expected " + std::to_string(expected) + " tiles, found " + std::to_string(set.tiles.size()));
  for (std::size_t t = 0; t < set.tiles.size(); ++t) {
    const Tile& tile = set.tiles[t];
    if (tile.level_end.size() != set.levels)
      return bad("tile " + std::to_string(t) + " has a wrong level table size");
    for (std::size_t k = 1; k < tile.level_end.size(); ++k)
      if (tile.level_end[k] < tile.level_end[k - 1])
        return bad("tile " + std::to_string(t) + " has a decreasing level table");
    if (tile.level_end.back() != tile.points.size())
      return bad("tile " + std::to_string(t) + "'s level table does not end at its point count");
    if (tile.keys.size() != tile.points.size())
      return bad("tile " + std::to_string(t) + " has " + std::to_string(tile.keys.size()) + " keys for " +
                 std::to_string(tile.points.size()) + " points");
    for (std::uint32_t k = 0; k < set.levels; ++k)
      for (std::uint32_t i = (k ? tile.level_end[k - 1] : 0) + 1; i < tile.level_end[k]; ++i)
        if (tile.keys[i] < tile.keys[i - 1])
          return bad("tile " + std::to_string(t) + " has unsorted keys in level " + std::to_string(k));
  }
  // A set of empty tiles emits nothing at any density: a damaged or forged file, not a tile set.
  if (std::all_of(set.tiles.begin(), set.tiles.end(), [](const Tile& t) { return t.points.empty(); }))
    return bad("its tiles hold no points");
  // No tile holds far more than its levels promise (baked sets hold them within a few per cent): a forged
  // file whose tile holds millions of points where its level promises 32 would make a query of a few
  // points emit them all at one place.
  for (std::uint32_t k = 0; k < set.levels; ++k)
    for (std::size_t t = 0; t < set.tiles.size(); ++t) {
      const std::uint64_t held = set.tiles[t].level_end[k], nominal = set.level_nominal[k];
      if (held > 4 * nominal + 64)
        return bad("tile " + std::to_string(t) + " holds " + std::to_string(held) + " points in levels 0.." +
                   std::to_string(k) + ", more than 4 times their nominal " + std::to_string(nominal) +
                   " (+64)");
    }
  const std::size_t keyframes = set.keyframe_nominal.size();
  if (keyframes > kMaxKeyframes)
    return bad(std::to_string(keyframes) + " keyframes, more than " + std::to_string(kMaxKeyframes));
  for (std::size_t g = 0; g < keyframes; ++g)
    if (set.keyframe_nominal[g] <= (g ? set.keyframe_nominal[g - 1] : 0u))
      return bad("keyframe counts are not strictly increasing");
  if (keyframes && set.keyframe_nominal.back() != set.level_nominal.back())
    return bad("the last keyframe is not the top level's count");
  for (std::size_t t = 0; t < set.tiles.size(); ++t) {
    std::uint64_t present = 0;  // offset pairs the keyframes need
    for (std::size_t g = 0; g < keyframes; ++g) present += set.offsets_at_keyframe(set.tiles[t], g);
    if (set.tiles[t].glide.size() != 2 * present)
      return bad("tile " + std::to_string(t) + " has " + std::to_string(set.tiles[t].glide.size()) +
                 " glide offsets, its keyframes need " + std::to_string(2 * present));
  }
  if (set.handover_zone) {
    std::string problem;
    try {
      problem = handover_problem(set);
    } catch (const std::bad_alloc&) {  // its scratch, refused by the tile-set allocator
      return fail(Status::kOutOfMemory, detail, "no memory to check the hand-over");
    }
    if (!problem.empty()) return bad(problem);
  } else {
    if (set.handover_level) return bad("a hand-over level in a set without a hand-over");
    if (set.handover_slack) return bad("a hand-over slack in a set without a hand-over");
    for (std::size_t t = 0; t < set.tiles.size(); ++t)
      if (!set.tiles[t].handover.empty() || !set.tiles[t].appearing.empty())
        return bad("tile " + std::to_string(t) + " has hand-over tables in a set without a hand-over");
  }
  return Status::kOk;
}

Status encode_tileset(const TilesetData& set, std::vector<std::uint8_t>& out, std::string* detail) {
  if (validate_tileset(set, detail) != Status::kOk) return Status::kInvalidArgument;
  if (set.recipe.size() + set.generator_version.size() + kFixedHeaderBytes > kMaxTilesetHeaderBytes)
    return fail(Status::kInvalidArgument, detail, "recipe text is too long");
  const std::vector<std::uint8_t> body = serialise_body(set);
  if (body.size() > kMaxTilesetPayloadBytes) return fail(Status::kTooLarge, detail, "tile set is too large");
  std::vector<std::uint8_t> payload(ZSTD_compressBound(body.size()));
  const std::size_t packed = ZSTD_compress(payload.data(), payload.size(), body.data(), body.size(), 19);
  if (ZSTD_isError(packed)) return fail(Status::kInvalidArgument, detail, ZSTD_getErrorName(packed));
  payload.resize(packed);

  const std::size_t header_size = kFixedHeaderBytes + set.recipe.size() + set.generator_version.size();
  out.assign(header_size + payload.size(), 0);
  std::uint8_t* h = out.data();
  std::memcpy(h, kMagic, 8);
  put32(h + 8, version_for(set));
  put32(h + 12, static_cast<std::uint32_t>(header_size));
  put64(h + 16, payload.size());
  put64(h + 24, body.size());
  put32(h + 32, detail::crc32(payload.data(), payload.size()));
  put32(h + 36, static_cast<std::uint32_t>(set.tiles.size()));
  put32(h + 40, set.colours);
  put32(h + 44, set.levels);
  put32(h + 48, static_cast<std::uint32_t>(set.recipe.size()));
  put32(h + 52, static_cast<std::uint32_t>(set.generator_version.size()));
  std::memcpy(h + kFixedHeaderBytes, set.recipe.data(), set.recipe.size());
  std::memcpy(h + kFixedHeaderBytes + set.recipe.size(), set.generator_version.data(),
              set.generator_version.size());
  put32(h + kHeaderCrcOffset, header_crc(h, header_size));
  std::memcpy(h + header_size, payload.data(), payload.size());
  return Status::kOk;
}

Status read_tileset_header(const void* data, std::size_t size, TilesetHeader& out, std::string* detail) {
  out = TilesetHeader{};
  const auto* p = static_cast<const std::uint8_t*>(data);
  if (size > 0 && !p) return fail(Status::kInvalidArgument, detail, "no bytes to read");
  if (size < 8 || std::memcmp(p, kMagic, 8) != 0) {
    const bool prefix = size < 8 && (size == 0 || std::memcmp(p, kMagic, size) == 0);
    return prefix ? fail(Status::kTruncated, detail, "file ends inside the magic number")
                  : fail(Status::kBadMagic, detail, "file does not start with KDMTILES");
  }
  // Byte counts say how much is missing: a download cut short, or a file still being written.
  auto cut_header = [&](const char* part, std::uint64_t need) {
    return fail(Status::kTruncated, detail,
                "file ends inside the header: it has " + std::to_string(size) + " bytes of the " + part +
                    "'s " + std::to_string(need));
  };
  if (size < 12) return cut_header("fixed header", kFixedHeaderBytes);
  const std::uint32_t version = get32(p + 8);
  if (version < kOldestTilesetFormatVersion || version > kTilesetFormatVersion)
    return fail(Status::kUnsupportedVersion, detail,
                "format version " + std::to_string(version) + ", this reader supports " +
                    std::to_string(kOldestTilesetFormatVersion) + " to " +
                    std::to_string(kTilesetFormatVersion));
  if (size < kFixedHeaderBytes) return cut_header("fixed header", kFixedHeaderBytes);
  const std::uint32_t header_size = get32(p + 12);
  if (header_size < kFixedHeaderBytes)
    return fail(Status::kHeaderChecksumMismatch, detail, "header size field is implausible (damaged header)");
  if (header_size > kMaxTilesetHeaderBytes) {
    // Sizes that agree with the texts' are a long recipe, too large to read, not a damaged field (the file
    // reader stops at the fixed header then, so its checksum cannot be judged).
    const bool agree = std::uint64_t(get32(p + 48)) + get32(p + 52) + kFixedHeaderBytes == header_size;
    return agree ? fail(Status::kTooLarge, detail,
                        "header of " + std::to_string(header_size) + " bytes passes this reader's limit of " +
                            std::to_string(kMaxTilesetHeaderBytes))
                 : fail(Status::kHeaderChecksumMismatch, detail,
                        "header size field is implausible (damaged header)");
  }
  if (size < header_size) {  // a cut file, unless the size field disagrees with the header's own text sizes
    const std::uint64_t text_sizes = std::uint64_t(get32(p + 48)) + get32(p + 52);
    return text_sizes + kFixedHeaderBytes != header_size
               ? fail(Status::kHeaderChecksumMismatch, detail, "header size field is damaged")
               : cut_header("header", header_size);
  }
  if (header_crc(p, header_size) != get32(p + kHeaderCrcOffset))
    return fail(Status::kHeaderChecksumMismatch, detail, "header bytes are damaged");
  const std::uint64_t payload_size = get64(p + 16), body_size = get64(p + 24);
  const std::uint32_t tile_count = get32(p + 36), colours = get32(p + 40), levels = get32(p + 44);
  const std::uint64_t recipe_size = get32(p + 48), version_size = get32(p + 52);
  if (recipe_size + version_size + kFixedHeaderBytes != header_size)
    return fail(Status::kInvalidContent, detail, "header text sizes do not add up to the header size");
  if (payload_size > size - header_size)
    return fail(Status::kTruncated, detail,
                "file ends inside the payload: it has " + std::to_string(size) + " bytes, the " +
                    std::to_string(header_size) + "-byte header and " + std::to_string(payload_size) +
                    "-byte payload need " + std::to_string(header_size + payload_size));
  if (payload_size < size - header_size)
    return fail(Status::kTrailingBytes, detail,  // how many is unknown: the file reader stops at one past
                "bytes follow the payload, which ends at byte " + std::to_string(header_size + payload_size));
  if (body_size > kMaxTilesetPayloadBytes)
    return fail(Status::kTooLarge, detail, "payload decompresses to " + std::to_string(body_size) + " bytes");
  // Each count named: a reader of a damaged file learns which one.
  if (colours < 1 || colours > kMaxTileColours)
    return fail(Status::kInvalidContent, detail,
                "header counts are inconsistent: colour count " + std::to_string(colours) +
                    " is outside 1.." + std::to_string(kMaxTileColours));
  if (levels < 1 || levels > kMaxTileLevels)
    return fail(Status::kInvalidContent, detail,
                "header counts are inconsistent: level count " + std::to_string(levels) + " is outside 1.." +
                    std::to_string(kMaxTileLevels));
  if (tile_count != std::uint64_t(colours) * colours * colours * colours)
    return fail(Status::kInvalidContent, detail,
                "header counts are inconsistent: " + std::to_string(tile_count) + " tiles for " +
                    std::to_string(colours) + " colours (colours^4 expected)");
  out.format_version = version;
  out.header_bytes = header_size;
  out.payload_bytes = payload_size, out.decompressed_bytes = body_size;
  out.payload_crc = get32(p + 32);
  out.tiles = tile_count, out.colours = colours, out.levels = levels;
  out.recipe.assign(reinterpret_cast<const char*>(p + kFixedHeaderBytes), recipe_size);
  out.generator_version.assign(reinterpret_cast<const char*>(p + kFixedHeaderBytes + recipe_size),
                               version_size);
  return Status::kOk;
}

Status decode_tileset(const void* data, std::size_t size, TilesetData& out, std::string* detail) {
  out = TilesetData{};
  TilesetHeader header;
  if (const Status s = read_tileset_header(data, size, header, detail); s != Status::kOk) return s;
  const auto* p = static_cast<const std::uint8_t*>(data);
  const std::uint32_t version = header.format_version, header_size = header.header_bytes;
  const std::uint64_t payload_size = header.payload_bytes, body_size = header.decompressed_bytes;
  const std::uint8_t* payload = p + header_size;
  if (detail::crc32(payload, payload_size) != header.payload_crc)
    return fail(Status::kPayloadChecksumMismatch, detail, "payload bytes are damaged");
  const unsigned long long frame = ZSTD_getFrameContentSize(payload, payload_size);
  if (frame == ZSTD_CONTENTSIZE_ERROR || frame == ZSTD_CONTENTSIZE_UNKNOWN || frame != body_size ||
      ZSTD_findFrameCompressedSize(payload, payload_size) != payload_size)  // one frame, nothing after it
    return fail(Status::kDecompressionFailed, detail, "payload is not one zstd frame of the stated size");
  TilesetData set;
  TilesetArray<TilesetArray<std::uint16_t>> glide16;  // format 3's stored glide offsets, per tile
  if (const Status s = read_body(payload, static_cast<std::size_t>(payload_size), body_size, version, set,
                                 glide16, detail);
      s != Status::kOk)
    return s;
  if (set.colours != header.colours || set.levels != header.levels)
    return fail(Status::kInvalidContent, detail, "payload disagrees with the header");
  if (const Status s = validate_tileset(set, detail); s != Status::kOk) return s;
  if (version == 3)
    for (std::size_t t = 0; t < glide16.size(); ++t) glide_from_format3(set, glide16[t], set.tiles[t]);
  else
    for (Tile& tile : set.tiles) glide_sums(set, tile, tile.glide);  // two's complement bytes
  set.recipe = std::move(header.recipe);
  set.generator_version = std::move(header.generator_version);
  out = std::move(set);
  return Status::kOk;
}

namespace {

/// read_tileset_file into any vector of char (the loader's: through the tile-set allocator).
template <class Bytes>
Status read_file_into(const std::string& path, Bytes& bytes, std::string* detail) {
  bytes.clear();
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"), std::fclose);
  if (!file) return fail(Status::kIoError, detail, "cannot open '" + path + "': " + std::strerror(errno));
  struct stat info;
  const bool known = fstat(fileno(file.get()), &info) == 0;
  if (known && S_ISDIR(info.st_mode))
    return fail(Status::kIoError, detail, "'" + path + "' is a directory, not a tile set file");
  const bool regular = known && S_ISREG(info.st_mode);
  bytes.resize(kFixedHeaderBytes);
  std::size_t n = std::fread(bytes.data(), 1, bytes.size(), file.get());
  if (n == kFixedHeaderBytes && std::memcmp(bytes.data(), kMagic, 8) == 0) {
    const auto* h = reinterpret_cast<const std::uint8_t*>(bytes.data());
    const std::uint64_t header_size = get32(h + 12), payload_size = get64(h + 16);
    if (header_size >= kFixedHeaderBytes && header_size <= kMaxTilesetHeaderBytes) {
      // The buffer grows with the bytes the file holds, not with what its unchecked header claims: a
      // damaged 64-byte file must not allocate half a gigabyte. A payload size past any payload's is read
      // up to that bound, not stopped at the fixed header: the header checksum must see the whole header,
      // so that the file is judged as decode_tileset judges its bytes in memory.
      const std::uint64_t most = ZSTD_compressBound(kMaxTilesetPayloadBytes);
      const std::uint64_t wanted = header_size + std::min(payload_size, most) + 1;
      std::uint64_t room = regular ? std::uint64_t(info.st_size) + 1 : std::uint64_t(1) << 16;
      while (n < wanted) {
        room = std::min(wanted, std::max(room, std::uint64_t(n) * 2));
        bytes.resize(static_cast<std::size_t>(room));
        const std::size_t got = std::fread(bytes.data() + n, 1, bytes.size() - n, file.get());
        n += got;
        if (n < bytes.size()) break;  // the end of the file (or an error, told below)
      }
    }
  }
  bytes.resize(n);
  if (std::ferror(file.get())) return fail(Status::kIoError, detail, "cannot read '" + path + "'");
  return Status::kOk;
}

}  // namespace

Status read_tileset_file(const std::string& path, std::vector<char>& bytes, std::string* detail) {
  return read_file_into(path, bytes, detail);
}

Status load_tileset(const std::string& path, TilesetData& out, std::string* detail) {
  out = TilesetData{};
  TilesetArray<char> bytes;  // as large as the file: the tile-set allocator's too
  try {
    if (const Status s = read_file_into(path, bytes, detail); s != Status::kOk) return s;
  } catch (const std::bad_alloc&) {
    return fail(Status::kOutOfMemory, detail, "no memory to read '" + path + "' into");
  }
  return decode_tileset(bytes.data(), bytes.size(), out, detail);
}

namespace {

// A device or a pipe (/dev/null, /dev/stdout, a FIFO): written into, as a shell's > does, since a rename
// would replace it with a regular file.
bool is_special_file(const std::string& path) {
  struct stat info;
  return stat(path.c_str(), &info) == 0 && !S_ISREG(info.st_mode) && !S_ISDIR(info.st_mode);
}

}  // namespace

Status check_tileset_path(const std::string& path, std::string* detail) {
  if (path.empty()) return fail(Status::kIoError, detail, "no file name to save the tile set to");
  struct stat info;
  if (stat(path.c_str(), &info) == 0 && S_ISDIR(info.st_mode))
    return fail(Status::kIoError, detail, "cannot write '" + path + "': it is a directory");
  if (is_special_file(path)) return Status::kOk;
  const std::string temp = path + ".partial";
  if (stat(temp.c_str(), &info) == 0 && S_ISDIR(info.st_mode))
    return fail(Status::kIoError, detail, "cannot create '" + temp + "': it is a directory");
  std::FILE* f = std::fopen(temp.c_str(), "wb");
  if (!f) {  // named by the caller's path: the scratch file beside it is ours
    const std::size_t slash = path.find_last_of('/');
    const std::string dir = slash == std::string::npos ? "." : slash == 0 ? "/" : path.substr(0, slash);
    const int error = errno;
    const bool no_dir = error == ENOENT && stat(dir.c_str(), &info) != 0;
    return fail(Status::kIoError, detail,
                "cannot write '" + path + "': " +
                    (no_dir ? "directory '" + dir + "' does not exist" : std::string(std::strerror(error))));
  }
  std::fclose(f);
  std::remove(temp.c_str());
  return Status::kOk;
}

Status save_tileset(const TilesetData& set, const std::string& given_path, std::string* detail) {
  if (const Status s = check_tileset_path(given_path, detail); s != Status::kOk) return s;
  const bool special = is_special_file(given_path);
  // A symbolic link is written through, as cp and a shell's > do: the rename replaces its target.
  std::string path = given_path;
  std::error_code ec;
  if (!special && std::filesystem::is_symlink(std::filesystem::symlink_status(path, ec))) {
    const std::filesystem::path target = std::filesystem::weakly_canonical(path, ec);
    if (!ec) path = target.string();
  }
  std::vector<std::uint8_t> bytes;
  if (const Status s = encode_tileset(set, bytes, detail); s != Status::kOk) return s;
  const std::string temp = special ? path : path + ".partial";
  {
    std::ofstream f(temp, std::ios::binary | std::ios::trunc);
    if (!f) return fail(Status::kIoError, detail, "cannot create '" + temp + "': " + std::strerror(errno));
    f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    f.flush();
    if (!f) {
      if (!special) std::remove(temp.c_str());
      return fail(Status::kIoError, detail, "cannot write '" + temp + "'");
    }
  }
  if (special) return Status::kOk;
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(temp.c_str());
    return fail(Status::kIoError, detail, "cannot replace '" + path + "': " + reason);
  }
  return Status::kOk;
}

}  // namespace kdm
