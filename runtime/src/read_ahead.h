// Internal: a batch callback's values read ahead of the loop that uses them (QueryDensity::batch_callback).
// Past the top level a candidate's reads depend on one another (its count, its ancestors' counts, its
// sub-point's, its glided position's), so they cannot be gathered in one sweep: the loop is run dry over a
// block of ranks, every candidate stopping at its first value not yet read, and the positions it stopped
// at are read in one call; the runs repeat until nothing is missing, then the real run finds every value
// here. Values are looked up by the position's exact bits, so they are the very values one call each
// would give.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "density_bounds.h"
#include "kdm/runtime/query.h"

namespace kdm::detail {

class ReadAhead {
 public:
  /// Positions a block may ask for: half the table, so that probes stay short.
  static constexpr std::size_t kCapacity = 256;

  explicit ReadAhead(const QueryDensity& density) : density_(density) {}

  /// Forgets every value (a new block).
  void clear() {
    if (++generation_ == 0) {  // wrapped: stale slots could match the new generation
      for (Slot& s : slots_) s.generation = 0;
      generation_ = 1;
    }
    size_ = 0;
  }

  /// The value at (x, y), if read.
  bool find(double x, double y, double& value) const {
    for (std::size_t i = hash(x, y);; i = (i + 1) & (kSlots - 1)) {
      const Slot& s = slots_[i];
      if (s.generation != generation_) return false;
      if (same(s.x, x) && same(s.y, y)) return value = s.value, true;
    }
  }

  /// Asks for (x, y) in the next read (nothing if it is read or the table is full); false when full.
  bool want(double x, double y) {
    if (size_ + pending_ >= kCapacity) return false;
    double unused;
    if (find(x, y, unused)) return true;
    for (std::size_t k = 0; k < pending_; ++k)
      if (same(x_[k], x) && same(y_[k], y)) return true;
    x_[pending_] = x, y_[pending_] = y, ++pending_;
    if (pending_ == kDensityBatch) read();
    return true;
  }

  /// Reads every position asked for; returns how many values it added.
  std::size_t read() {
    if (pending_ == 0) return 0;
    double v[kDensityBatch];
    density_.batch_callback(density_.user, pending_, x_, y_, v);
    for (std::size_t k = 0; k < pending_; ++k) insert(x_[k], y_[k], density_or_zero(v[k]));
    const std::size_t added = pending_;
    pending_ = 0, added_ += added;
    return added;
  }

  /// Values read since clear().
  std::size_t size() const { return size_; }

  /// Values added since the last call (how a dry run knows it found something to read).
  std::size_t take_added() {
    const std::size_t a = added_;
    added_ = 0;
    return a;
  }

 private:
  static constexpr std::size_t kSlots = 2 * kCapacity;
  struct Slot {
    double x, y, value;
    std::uint32_t generation;
  };
  static bool same(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
  static std::size_t hash(double x, double y) {
    std::uint64_t bx, by;
    std::memcpy(&bx, &x, sizeof bx), std::memcpy(&by, &y, sizeof by);
    const std::uint64_t h = bx * 0x9E3779B97F4A7C15u ^ (by + 0x632BE59BD9B4E019u) * 0xC2B2AE3D27D4EB4Fu;
    return static_cast<std::size_t>(h >> 55) & (kSlots - 1);
  }
  void insert(double x, double y, double value) {
    std::size_t i = hash(x, y);
    while (slots_[i].generation == generation_) i = (i + 1) & (kSlots - 1);
    slots_[i] = Slot{x, y, value, generation_};
    ++size_;
  }

  const QueryDensity& density_;
  Slot slots_[kSlots] = {};
  std::uint32_t generation_ = 1;
  std::size_t size_ = 0, pending_ = 0, added_ = 0;
  double x_[kDensityBatch], y_[kDensityBatch];
};

}  // namespace kdm::detail
