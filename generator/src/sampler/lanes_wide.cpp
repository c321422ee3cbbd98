// Wide passes of Algorithm 1 (Fattal 2011); see lanes_wide.h. The passes are written once
// (lanes_wide_passes.inc) and compiled twice: for AVX-512, a row in one 16-lane vector, and for AVX2, in
// two 8-lane ones. Only functions marked with their target use those instructions, and only after best()
// said the CPU has them: the rest of the program keeps the baseline instruction set. The target is set per
// function rather than for this file, so no inline function that other files share is ever compiled here
// with wider instructions.
#include "sampler/lanes_wide.h"

#include <array>
#include <cstdint>
#include <cstdlib>
#include <type_traits>

#include "kdm/runtime/check.h"
#include "sampler/lanes.h"
#include "sampler/simd.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define KDM_HAVE_WIDE_PASSES 1
// GCC 12's AVX-512 casts and inserts start from a deliberately undefined vector, which -Wuninitialized
// reports from inside immintrin.h, a false positive that GCC 13 no longer gives.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <immintrin.h>
#endif

namespace kdm::gen::wide {

#ifdef KDM_HAVE_WIDE_PASSES

namespace {

// Checked once each (thread-safe statics).
bool cpu_has_avx512f() {
  static const bool has = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f") != 0;
  }();
  return has;
}
bool cpu_has_avx2() {
  static const bool has = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") != 0;
  }();
  return has;
}

// Calls f(std::integral_constant<int, W>) for the footprint's width (fits() said it is 8, 12 or 16).
template <class F>
decltype(auto) by_width(int width, F&& f) {
  if (width == 8) return f(std::integral_constant<int, 8>{});
  if (width == 12) return f(std::integral_constant<int, 12>{});
  return f(std::integral_constant<int, 16>{});
}

namespace avx512 {
#define KDM_TARGET __attribute__((target("avx512f")))
using V = __m512;

KDM_TARGET inline V zero() {
  return _mm512_setzero_ps();
}
KDM_TARGET inline V set1(float x) {
  return _mm512_set1_ps(x);
}
KDM_TARGET inline V add(V a, V b) {
  return _mm512_add_ps(a, b);
}
KDM_TARGET inline V sub(V a, V b) {
  return _mm512_sub_ps(a, b);
}
KDM_TARGET inline V mul(V a, V b) {
  return _mm512_mul_ps(a, b);
}
KDM_TARGET inline V abs_of(V a) {
  return _mm512_abs_ps(a);
}
KDM_TARGET inline V signed_by(V r, V x) {
  const __m512i sign = _mm512_and_si512(_mm512_castps_si512(r), _mm512_set1_epi32(INT32_MIN));
  return _mm512_castsi512_ps(_mm512_xor_si512(_mm512_castps_si512(x), sign));
}
// A row of W = 8, 12 or 16 nodes in the low lanes, the rest zero. Plain 8- and 4-lane loads and stores, not
// masked ones: this CPU family forwards a store to a later masked load slowly, and the passes read nodes
// that the previous update has just written (docs/design.md §2.9).
template <int W>
KDM_TARGET inline V load_row(const float* p) {
  static_assert(W == 8 || W == 12 || W == 16, "rows of 8, 12 or 16 nodes");
  if constexpr (W == 16) return _mm512_loadu_ps(p);
  const __m512 low = _mm512_zextps256_ps512(_mm256_loadu_ps(p));
  if constexpr (W == 8) return low;
  return _mm512_insertf32x4(low, _mm_loadu_ps(p + 8), 2);
}
template <int W>
KDM_TARGET inline void store_row(float* p, V v) {
  if constexpr (W == 16) {
    _mm512_storeu_ps(p, v);
  } else {
    _mm256_storeu_ps(p, _mm512_castps512_ps256(v));
    if constexpr (W == 12) _mm_storeu_ps(p + 8, _mm512_extractf32x4_ps(v, 2));
  }
}
// lanes.h's sum_lanes over the W / 4 lane vectors of a row.
template <int W>
KDM_TARGET inline double sum_lanes(V v) {
  __m128 t = _mm_add_ps(_mm512_castps512_ps128(v), _mm512_extractf32x4_ps(v, 1));
  if constexpr (W >= 12) t = _mm_add_ps(t, _mm512_extractf32x4_ps(v, 2));
  if constexpr (W == 16) t = _mm_add_ps(t, _mm512_extractf32x4_ps(v, 3));
  return sum4(reinterpret_cast<F4>(t));
}
// x where lane k's node j0 + k lies in [jlo, jhi] and value > 0, else +0.
KDM_TARGET inline V keep_inside(V x, V value, std::int32_t j0, std::int32_t jlo, std::int32_t jhi) {
  const __m512i j = _mm512_add_epi32(_mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15),
                                     _mm512_set1_epi32(j0));
  const __mmask16 keep = _mm512_cmpgt_epi32_mask(j, _mm512_set1_epi32(jlo - 1)) &
                         _mm512_cmpgt_epi32_mask(_mm512_set1_epi32(jhi + 1), j) &
                         _mm512_cmp_ps_mask(value, _mm512_setzero_ps(), _CMP_GT_OQ);
  return _mm512_maskz_mov_ps(keep, x);
}

// Lane k holds float(j0 + k), as the four-lane code's convertvector does.
KDM_TARGET inline V lane_nodes(std::int32_t j0) {
  return _mm512_cvtepi32_ps(_mm512_add_epi32(
      _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15), _mm512_set1_epi32(j0)));
}
KDM_TARGET inline V negate(V x) {
  return _mm512_castsi512_ps(_mm512_xor_si512(_mm512_castps_si512(x), _mm512_set1_epi32(INT32_MIN)));
}
// y where y >= c, else c (simd.h's exp4 clamps its argument so).
KDM_TARGET inline V at_least(V y, float c) {
  return _mm512_mask_mov_ps(y, _mm512_cmp_ps_mask(y, set1(c), _CMP_LT_OQ), set1(c));
}
// 2^n for whole numbers n held as floats, built in the exponent bits as exp4 does.
KDM_TARGET inline V two_to(V n) {
  return _mm512_castsi512_ps(
      _mm512_slli_epi32(_mm512_add_epi32(_mm512_cvttps_epi32(n), _mm512_set1_epi32(127)), 23));
}

#include "sampler/lanes_wide_passes.inc"
#undef KDM_TARGET
}  // namespace avx512

namespace avx2 {
#define KDM_TARGET __attribute__((target("avx2")))
struct V {
  __m256 low, high;  // lanes 0-7 and 8-15
};

KDM_TARGET inline V zero() {
  return {_mm256_setzero_ps(), _mm256_setzero_ps()};
}
KDM_TARGET inline V set1(float x) {
  const __m256 v = _mm256_set1_ps(x);
  return {v, v};
}
KDM_TARGET inline V add(V a, V b) {
  return {_mm256_add_ps(a.low, b.low), _mm256_add_ps(a.high, b.high)};
}
KDM_TARGET inline V sub(V a, V b) {
  return {_mm256_sub_ps(a.low, b.low), _mm256_sub_ps(a.high, b.high)};
}
KDM_TARGET inline V mul(V a, V b) {
  return {_mm256_mul_ps(a.low, b.low), _mm256_mul_ps(a.high, b.high)};
}
KDM_TARGET inline V abs_of(V a) {
  const __m256 sign = _mm256_set1_ps(-0.0f);
  return {_mm256_andnot_ps(sign, a.low), _mm256_andnot_ps(sign, a.high)};
}
KDM_TARGET inline V signed_by(V r, V x) {
  const __m256 sign = _mm256_set1_ps(-0.0f);
  return {_mm256_xor_ps(x.low, _mm256_and_ps(r.low, sign)),
          _mm256_xor_ps(x.high, _mm256_and_ps(r.high, sign))};
}
template <int W>
KDM_TARGET inline V load_row(const float* p) {
  static_assert(W == 8 || W == 12 || W == 16, "rows of 8, 12 or 16 nodes");
  if constexpr (W == 8) return {_mm256_loadu_ps(p), _mm256_setzero_ps()};
  if constexpr (W == 12) return {_mm256_loadu_ps(p), _mm256_zextps128_ps256(_mm_loadu_ps(p + 8))};
  return {_mm256_loadu_ps(p), _mm256_loadu_ps(p + 8)};
}
template <int W>
KDM_TARGET inline void store_row(float* p, V v) {
  _mm256_storeu_ps(p, v.low);
  if constexpr (W == 12) _mm_storeu_ps(p + 8, _mm256_castps256_ps128(v.high));
  if constexpr (W == 16) _mm256_storeu_ps(p + 8, v.high);
}
template <int W>
KDM_TARGET inline double sum_lanes(V v) {
  __m128 t = _mm_add_ps(_mm256_castps256_ps128(v.low), _mm256_extractf128_ps(v.low, 1));
  if constexpr (W >= 12) t = _mm_add_ps(t, _mm256_castps256_ps128(v.high));
  if constexpr (W == 16) t = _mm_add_ps(t, _mm256_extractf128_ps(v.high, 1));
  return sum4(reinterpret_cast<F4>(t));
}
KDM_TARGET inline __m256 keep_inside8(__m256 x, __m256 value, __m256i j, std::int32_t jlo, std::int32_t jhi) {
  const __m256i inside = _mm256_and_si256(_mm256_cmpgt_epi32(j, _mm256_set1_epi32(jlo - 1)),
                                          _mm256_cmpgt_epi32(_mm256_set1_epi32(jhi + 1), j));
  const __m256 positive = _mm256_cmp_ps(value, _mm256_setzero_ps(), _CMP_GT_OQ);
  return _mm256_and_ps(_mm256_and_ps(_mm256_castsi256_ps(inside), positive), x);
}
KDM_TARGET inline V keep_inside(V x, V value, std::int32_t j0, std::int32_t jlo, std::int32_t jhi) {
  const __m256i j = _mm256_add_epi32(_mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7), _mm256_set1_epi32(j0));
  return {keep_inside8(x.low, value.low, j, jlo, jhi),
          keep_inside8(x.high, value.high, _mm256_add_epi32(j, _mm256_set1_epi32(8)), jlo, jhi)};
}

KDM_TARGET inline V lane_nodes(std::int32_t j0) {
  const __m256i j = _mm256_add_epi32(_mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7), _mm256_set1_epi32(j0));
  return {_mm256_cvtepi32_ps(j), _mm256_cvtepi32_ps(_mm256_add_epi32(j, _mm256_set1_epi32(8)))};
}
KDM_TARGET inline V negate(V x) {
  const __m256 sign = _mm256_set1_ps(-0.0f);
  return {_mm256_xor_ps(x.low, sign), _mm256_xor_ps(x.high, sign)};
}
KDM_TARGET inline V at_least(V y, float c) {
  const __m256 floor = _mm256_set1_ps(c);
  return {_mm256_blendv_ps(y.low, floor, _mm256_cmp_ps(y.low, floor, _CMP_LT_OQ)),
          _mm256_blendv_ps(y.high, floor, _mm256_cmp_ps(y.high, floor, _CMP_LT_OQ))};
}
KDM_TARGET inline __m256 two_to8(__m256 n) {
  return _mm256_castsi256_ps(
      _mm256_slli_epi32(_mm256_add_epi32(_mm256_cvttps_epi32(n), _mm256_set1_epi32(127)), 23));
}
KDM_TARGET inline V two_to(V n) {
  return {two_to8(n.low), two_to8(n.high)};
}

#include "sampler/lanes_wide_passes.inc"
#undef KDM_TARGET
}  // namespace avx2

}  // namespace

Isa best() {
  return cpu_has_avx512f() ? Isa::kAvx512 : cpu_has_avx2() ? Isa::kAvx2 : Isa::kNone;
}

Isa widest(int lanes) {
  if (lanes >= 16 && cpu_has_avx512f()) return Isa::kAvx512;
  return lanes >= 8 && cpu_has_avx2() ? Isa::kAvx2 : Isa::kNone;
}

// The entry points keep the baseline target (a different target would make them other versions of the
// declared functions); each is one call into a body of the chosen instruction set.
template <int D>
double remove(Isa isa, float* R, const Grid<D>& grid, const Footprint<D>& fp, Vec<D>& gradient,
              float* saved) {
  KDM_CHECK(fits(fp) && isa != Isa::kNone && isa <= best());
  return by_width(fp.width, [&](auto w) {
    return isa == Isa::kAvx512 ? avx512::remove_rows<D, w()>(R, grid, fp, gradient, saved)
                               : avx2::remove_rows<D, w()>(R, grid, fp, gradient, saved);
  });
}
template <int D>
double added(Isa isa, const float* R, const Grid<D>& grid, const Footprint<D>& fp, Vec<D>& gradient) {
  KDM_CHECK(fits(fp) && isa != Isa::kNone && isa <= best());
  return by_width(fp.width, [&](auto w) {
    return isa == Isa::kAvx512 ? avx512::added_rows<D, w()>(R, grid, fp, gradient)
                               : avx2::added_rows<D, w()>(R, grid, fp, gradient);
  });
}
template <int D>
void add(Isa isa, float* R, const Grid<D>& grid, const Footprint<D>& fp, float sign) {
  KDM_CHECK(fits(fp) && isa != Isa::kNone && isa <= best());
  by_width(fp.width, [&](auto w) {
    if (isa == Isa::kAvx512) return avx512::add_rows<D, w()>(R, grid, fp, sign);
    avx2::add_rows<D, w()>(R, grid, fp, sign);
  });
}
template <int D>
void restore(Isa isa, float* R, const Grid<D>& grid, const Footprint<D>& fp, const float* saved) {
  KDM_CHECK(fits(fp) && isa != Isa::kNone && isa <= best());
  by_width(fp.width, [&](auto w) {
    if (isa == Isa::kAvx512) return avx512::restore_rows<D, w()>(R, grid, fp, saved);
    avx2::restore_rows<D, w()>(R, grid, fp, saved);
  });
}

void tabulated_axis(Isa isa, const float* coef, int stride, int width, float s, std::int32_t j0,
                    std::int32_t jlo, std::int32_t jhi, float edge, bool with_derivative, float* v,
                    float* dv) {
  by_width(width, [&](auto w) {
    if (isa == Isa::kAvx512)
      return avx512::tabulated_lanes<w()>(coef, stride, s, j0, jlo, jhi, edge, with_derivative, v, dv);
    avx2::tabulated_lanes<w()>(coef, stride, s, j0, jlo, jhi, edge, with_derivative, v, dv);
  });
}

void computed_axis(Isa isa, int width, float a, float inv, float dscale, std::int32_t j0, std::int32_t jlo,
                   std::int32_t jhi, float edge, bool with_derivative, float* v, float* dv) {
  by_width(width, [&](auto w) {
    if (isa == Isa::kAvx512)
      return avx512::computed_lanes<w()>(a, inv, dscale, j0, jlo, jhi, edge, with_derivative, v, dv);
    avx2::computed_lanes<w()>(a, inv, dscale, j0, jlo, jhi, edge, with_derivative, v, dv);
  });
}

#else  // no wide passes on this platform: best() is kNone, so nothing below is ever called

Isa best() {
  return Isa::kNone;
}
Isa widest(int) {
  return Isa::kNone;
}
template <int D>
double remove(Isa, float*, const Grid<D>&, const Footprint<D>&, Vec<D>&, float*) {
  std::abort();
}
template <int D>
double added(Isa, const float*, const Grid<D>&, const Footprint<D>&, Vec<D>&) {
  std::abort();
}
template <int D>
void add(Isa, float*, const Grid<D>&, const Footprint<D>&, float) {
  std::abort();
}
template <int D>
void restore(Isa, float*, const Grid<D>&, const Footprint<D>&, const float*) {
  std::abort();
}
void tabulated_axis(Isa, const float*, int, int, float, std::int32_t, std::int32_t, std::int32_t, float, bool,
                    float*, float*) {
  std::abort();
}
void computed_axis(Isa, int, float, float, float, std::int32_t, std::int32_t, std::int32_t, float, bool,
                   float*, float*) {
  std::abort();
}

#endif

template double remove<2>(Isa, float*, const Grid<2>&, const Footprint<2>&, Vec<2>&, float*);
template double remove<3>(Isa, float*, const Grid<3>&, const Footprint<3>&, Vec<3>&, float*);
template double added<2>(Isa, const float*, const Grid<2>&, const Footprint<2>&, Vec<2>&);
template double added<3>(Isa, const float*, const Grid<3>&, const Footprint<3>&, Vec<3>&);
template void add<2>(Isa, float*, const Grid<2>&, const Footprint<2>&, float);
template void add<3>(Isa, float*, const Grid<3>&, const Footprint<3>&, float);
template void restore<2>(Isa, float*, const Grid<2>&, const Footprint<2>&, const float*);
template void restore<3>(Isa, float*, const Grid<3>&, const Footprint<3>&, const float*);

}  // namespace kdm::gen::wide
