// Four-lane float vectors for the sampler's inner loops (GCC/Clang vector extensions: SSE2 on x86-64,
// NEON on ARM). Every reduction keeps four explicit lanes summed in a fixed order at the end, so results
// depend on the source, not on how wide the machine's vectors are or how the compiler schedules them.
#pragma once

#include <cstdint>
#include <cstring>

namespace kdm::gen {

using F4 = float __attribute__((vector_size(16)));
using I4 = std::int32_t __attribute__((vector_size(16)));

inline F4 load4(const float* p) {
  F4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store4(float* p, F4 v) {
  std::memcpy(p, &v, sizeof v);
}
inline F4 splat4(float x) {
  return F4{x, x, x, x};
}
inline F4 abs4(F4 x) {
  return reinterpret_cast<F4>(reinterpret_cast<I4>(x) & 0x7fffffff);
}
/// copysign(1, r)·x: x with its sign flipped where r is negative (or -0), exactly.
inline F4 signed_by(F4 r, F4 x) {
  return reinterpret_cast<F4>(reinterpret_cast<I4>(x) ^
                              (reinterpret_cast<I4>(r) & static_cast<std::int32_t>(0x80000000u)));
}
inline double sum4(F4 x) {
  return (double(x[0]) + double(x[1])) + (double(x[2]) + double(x[3]));
}

/// e^y for y in [-87, 0] to about one float ulp (Cody–Waite reduction and Cephes' expf polynomial).
/// Plain arithmetic, so the kernel's values are the same on every platform and libm.
inline F4 exp4(F4 y) {
  y = y < -87.0f ? splat4(-87.0f) : y;
  const F4 magic = splat4(12582912.0f);  // 1.5·2^23: adding it rounds to an integer
  const F4 n = (y * 1.44269504088896341f + magic) - magic;
  F4 f = y - n * 0.693359375f;
  f = f - n * -2.12194440e-4f;
  F4 p = splat4(1.9875691500e-4f);
  p = p * f + 1.3981999507e-3f;
  p = p * f + 8.3334519073e-3f;
  p = p * f + 4.1665795894e-2f;
  p = p * f + 1.6666665459e-1f;
  p = p * f + 5.0000001201e-1f;
  p = p * f * f + f + 1.0f;
  const I4 scale = (__builtin_convertvector(n, I4) + 127) << 23;
  return p * reinterpret_cast<F4>(scale);
}

}  // namespace kdm::gen
