// Internal: the running fingerprint of a query's parameters (QueryCursor::fingerprint), computed by every
// call: one multiply per value, so that it costs a small call a few nanoseconds, and mixed once at the end.
#pragma once

#include <cstdint>
#include <cstring>

#include "kdm/runtime/hash.h"

namespace kdm::detail {

class Fingerprint {
 public:
  explicit Fingerprint(std::uint64_t seed) : h_(seed) {}
  /// Each step is a bijection of the state (an odd multiplier), so any one value changed changes the result.
  void add(std::uint64_t v) { h_ = (h_ ^ v) * 0x9e3779b97f4a7c15ull; }
  void add_double(double v) {
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    add(bits);
  }
  void add_pointer(const void* p) { add(reinterpret_cast<std::uintptr_t>(p)); }
  /// mix64 spreads the high bits, which alone carry a change in a value's high bits, over every bit.
  std::uint64_t value() const { return mix64(h_); }

 private:
  std::uint64_t h_;
};

}  // namespace kdm::detail
