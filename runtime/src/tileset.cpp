// Loading a tile set for queries: the tables the query loop reads (kdm/runtime/query.h).
#include <algorithm>
#include <cmath>
#include <utility>

#include "kdm/runtime/hash.h"
#include "kdm/runtime/query.h"
#include "keyframe_lookup.h"

namespace kdm {

using detail::kCountBuckets;
using detail::keyframe_table;

namespace {

/// Colour of the tile-grid vertex (vx, vy): a hash, so every region is assembled locally.
std::uint32_t vertex_colour(std::int64_t vx, std::int64_t vy, std::uint32_t colours) {
  const std::uint64_t h =
      mix64(mix64(static_cast<std::uint64_t>(vx) + 0x6b647469ull) ^ static_cast<std::uint64_t>(vy));
  return static_cast<std::uint32_t>(h % colours);
}

AllocatorHooks g_tileset_hooks;  // written only by set_tileset_allocator (documented: not during loads)

}  // namespace

void set_tileset_allocator(const AllocatorHooks& hooks) {
  g_tileset_hooks = (hooks.allocate && hooks.deallocate) ? hooks : AllocatorHooks{};
}

AllocatorHooks tileset_allocator() {
  return g_tileset_hooks;
}

void Tileset::adopt(TilesetData&& set) {
  set_ = std::move(set);
  // Thresholds once per load, so the query loop compares instead of interpolating.
  thresholds_.assign(set_.tiles.size(), {});
  for (std::size_t t = 0; t < set_.tiles.size(); ++t) {
    const Tile& tile = set_.tiles[t];
    TilesetArray<float>& out = thresholds_[t];
    out.resize(tile.points.size());
    for (std::uint32_t k = 0, i = 0; k < set_.levels; ++k)
      for (; i < tile.level_end[k]; ++i) out[i] = set_.emission_threshold(k, tile.keys[i]);
  }
  // Where each keyframe's offsets start in every tile, their units, and how far any point glides.
  glide_start_.assign(set_.tiles.size(), {});
  glide_reach_.assign(set_.keyframe_nominal.size(), 0.0);
  glide_scale_.assign(set_.keyframe_nominal.size(), 0.0);
  for (std::size_t g = 0; g < set_.keyframe_nominal.size(); ++g)
    glide_scale_[g] = 65536.0 * set_.glide_unit(g);
  keyframe_guess_.assign(kCountBuckets, 0);
  for (int b = 0; b < kCountBuckets; ++b) {  // the first keyframe at least the bucket's smallest count
    const double lowest = std::ldexp(1.0 + double(b % detail::kBucketsPerOctave) / detail::kBucketsPerOctave,
                                     b / detail::kBucketsPerOctave - 32);
    const std::uint32_t* k = set_.keyframe_nominal.data();
    keyframe_guess_[b] =
        static_cast<std::uint16_t>(std::lower_bound(k, k + set_.keyframe_nominal.size(), lowest) - k);
  }
  keyframe_one_step_ = true;  // no bucket holds two keyframes (true unless they are under 3.1% apart)
  for (int b = 0; b + 1 < kCountBuckets; ++b)
    keyframe_one_step_ = keyframe_one_step_ && keyframe_guess_[b + 1] <= keyframe_guess_[b] + 1;
  keyframe_ranks_.assign(set_.tiles.size(), {});
  for (std::size_t t = 0; t < set_.tiles.size() && has_glide(); ++t) {
    TilesetArray<std::uint32_t>& start = glide_start_[t];
    start.assign(set_.keyframe_nominal.size() + 1, 0);
    keyframe_ranks_[t].assign(set_.keyframe_nominal.size(), 0);
    for (std::size_t g = 0; g < set_.keyframe_nominal.size(); ++g) {
      start[g + 1] = start[g] + set_.glide_count(set_.tiles[t], g);
      keyframe_ranks_[t][g] = set_.keyframe_count(set_.tiles[t], g);
      int largest = 0;
      for (std::size_t i = 2 * std::size_t(start[g]); i < 2 * std::size_t(start[g + 1]); ++i)
        largest = std::max(largest, std::abs(int(set_.tiles[t].glide[i])));
      glide_reach_[g] = std::max(glide_reach_[g], largest * set_.glide_unit(g));
    }
  }
  glide_reach_from_.assign(glide_reach_.size(), 0.0);
  for (std::size_t g = glide_reach_.size(); g-- > 0;)
    glide_reach_from_[g] =
        std::max(glide_reach_[g], g + 1 < glide_reach_.size() ? glide_reach_from_[g + 1] : 0.0);
  const std::size_t keyframes = set_.keyframe_nominal.size();
  keyframe_counts_.assign(keyframes + 1, HUGE_VAL);
  for (std::size_t g = 0; g < keyframes; ++g) keyframe_counts_[g] = set_.keyframe_nominal[g];
  glide_spans_.assign(keyframes ? keyframes + 1 : 0, {});
  for (std::size_t g = 0; g < glide_spans_.size(); ++g) {
    GlideSpan& span = glide_spans_[g];
    span.g0 = static_cast<std::uint32_t>(g - (g > 0)),
    span.g1 = static_cast<std::uint32_t>(g - (g == keyframes));
    span.base = keyframe_counts_[span.g0];
    if (span.g1 > span.g0) span.inverse_gap = 1.0 / (keyframe_counts_[span.g1] - keyframe_counts_[span.g0]);
    span.scale0 = glide_scale_[span.g0], span.scale1 = glide_scale_[span.g1];
  }
  index_edges();
  min_threshold_ = HUGE_VAL;
  for (const TilesetArray<float>& t : thresholds_)
    if (!t.empty()) min_threshold_ = std::min(min_threshold_, double(t.front()));
}

void Tileset::index_edges() {
  edge_start_.assign(5 * set_.tiles.size(), 0);
  edge_ranks_.assign(set_.tiles.size(), {});
  if (!has_glide()) return;
  for (std::size_t t = 0; t < set_.tiles.size(); ++t) {
    const Tile& tile = set_.tiles[t];
    const std::uint32_t* ranks = keyframe_ranks_[t].data();
    TilesetArray<std::uint32_t>& out = edge_ranks_[t];
    for (int side = 0; side < 4; ++side) {
      std::size_t segment = 0;  // the keyframes whose count rank c is at least: it appears after the last
      for (std::uint32_t c = 0; c < tile.points.size(); ++c) {
        while (segment < keyframe_ranks_[t].size() && ranks[segment] <= c) ++segment;
        // The same reach as the query's culling (emit_tile), so a point left out would be culled there.
        const double reach = glide_reach_from(segment ? segment - 1 : 0) * 65536.0 + kEdgeSlack;
        const double u = (side < 2 ? tile.points[c].x : tile.points[c].y) + 0.5;
        if ((side % 2 == 0) ? u < reach : u > 65536.0 - reach) out.push_back(c);
      }
      edge_start_[5 * t + side + 1] = static_cast<std::uint32_t>(out.size());
    }
    out.shrink_to_fit();
  }
}

std::size_t Tileset::resident_bytes() const {
  std::size_t bytes = sizeof(*this) + set_.level_nominal.capacity() * sizeof(std::uint32_t) +
                      set_.tiles.capacity() * sizeof(Tile) +
                      thresholds_.capacity() * sizeof(TilesetArray<float>) + set_.recipe.capacity() +
                      set_.generator_version.capacity();
  for (const Tile& t : set_.tiles)
    bytes += t.points.capacity() * sizeof(TilePoint) + t.keys.capacity() * sizeof(std::uint16_t) +
             t.level_end.capacity() * sizeof(std::uint32_t);
  for (const TilesetArray<float>& t : thresholds_) bytes += t.capacity() * sizeof(float);
  bytes +=
      glide_start_.capacity() * sizeof(TilesetArray<std::uint32_t>) +
      set_.keyframe_nominal.capacity() * sizeof(std::uint32_t) +
      (glide_reach_.capacity() + glide_reach_from_.capacity() + glide_scale_.capacity()) * sizeof(double) +
      keyframe_ranks_.capacity() * sizeof(TilesetArray<std::uint32_t>) +
      keyframe_guess_.capacity() * sizeof(std::uint16_t);
  for (const TilesetArray<std::uint32_t>& t : glide_start_) bytes += t.capacity() * sizeof(std::uint32_t);
  for (const TilesetArray<std::uint32_t>& t : keyframe_ranks_) bytes += t.capacity() * sizeof(std::uint32_t);
  for (const Tile& t : set_.tiles) bytes += t.glide.capacity() * sizeof(std::int8_t);
  bytes += keyframe_counts_.capacity() * sizeof(double) + glide_spans_.capacity() * sizeof(GlideSpan) +
           edge_ranks_.capacity() * sizeof(TilesetArray<std::uint32_t>) +
           edge_start_.capacity() * sizeof(std::uint32_t);
  for (const TilesetArray<std::uint32_t>& t : edge_ranks_) bytes += t.capacity() * sizeof(std::uint32_t);
  return bytes;
}

Status Tileset::load_memory(const void* data, std::size_t size, Tileset& out, std::string* detail) {
  out = Tileset{};
  TilesetData set;
  const Status s = decode_tileset(data, size, set, detail);
  if (s == Status::kOk) out.adopt(std::move(set));
  return s;
}

Status Tileset::load_file(const std::string& path, Tileset& out, std::string* detail) {
  out = Tileset{};
  TilesetData set;
  const Status s = load_tileset(path, set, detail);
  if (s == Status::kOk) out.adopt(std::move(set));
  return s;
}

std::size_t Tileset::tile_index_at(std::int64_t tx, std::int64_t ty) const {
  const std::uint32_t c = set_.colours;
  if (c == 1) return 0;
  return set_.tile_index(vertex_colour(tx, ty, c), vertex_colour(tx + 1, ty, c),
                         vertex_colour(tx + 1, ty + 1, c), vertex_colour(tx, ty + 1, c));
}

std::uint32_t Tileset::first_keyframe_at_least(double expected) const {
  return has_glide() ? keyframe_table(*this).first_at_least(expected) : 0;
}

}  // namespace kdm
