// Sixteen-lane passes of Algorithm 1 (Fattal 2011); see lanes_wide.h. Only the functions marked
// KDM_AVX512 use AVX-512, and only after available() said yes: the rest of the program keeps the
// baseline instruction set. The target is set per function rather than for this file, so no inline
// function that other files share is ever compiled here with AVX-512 instructions.
#include "lanes_wide.h"

#include <array>
#include <cstdint>
#include <cstdlib>
#include <type_traits>

#include "lanes.h"
#include "simd.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define KDM_HAVE_AVX512_PASSES 1
// GCC 12's AVX-512 casts and inserts start from a deliberately undefined vector, which -Wuninitialized
// reports from inside immintrin.h (GCC bug 105593, fixed in GCC 13).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <immintrin.h>
#define KDM_AVX512 __attribute__((target("avx512f")))
#endif

namespace kdm::gen::wide {

#ifdef KDM_HAVE_AVX512_PASSES

bool available() {
  static const bool has = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f") != 0;
  }();
  return has;
}

namespace {

KDM_AVX512 inline __m512 signed_by(__m512 r, __m512 x) {
  const __m512i sign = _mm512_and_si512(_mm512_castps_si512(r), _mm512_set1_epi32(INT32_MIN));
  return _mm512_castsi512_ps(_mm512_xor_si512(_mm512_castps_si512(x), sign));
}

// A row of W = 8, 12 or 16 nodes in the low lanes of a vector, the rest zero. Plain 8- and 4-lane loads and
// stores, not masked ones: this CPU family forwards a store to a later masked load slowly, and the passes
// read nodes that the previous update has just written (measured: masked rows made the passes 8% slower).
template <int W>
KDM_AVX512 inline __m512 load_row(const float* p) {
  static_assert(W == 8 || W == 12 || W == 16, "rows of 8, 12 or 16 nodes");
  if constexpr (W == 16) return _mm512_loadu_ps(p);
  const __m512 low = _mm512_zextps256_ps512(_mm256_loadu_ps(p));
  if constexpr (W == 8) return low;
  return _mm512_insertf32x4(low, _mm_loadu_ps(p + 8), 2);
}
template <int W>
KDM_AVX512 inline void store_row(float* p, __m512 v) {
  if constexpr (W == 16) {
    _mm512_storeu_ps(p, v);
  } else {
    _mm256_storeu_ps(p, _mm512_castps512_ps256(v));
    if constexpr (W == 12) _mm_storeu_ps(p + 8, _mm512_extractf32x4_ps(v, 2));
  }
}

// lanes.h's sum_lanes over the W / 4 lane vectors of a row.
template <int W>
KDM_AVX512 inline double sum_lanes(__m512 v) {
  __m128 t = _mm_add_ps(_mm512_castps512_ps128(v), _mm512_extractf32x4_ps(v, 1));
  if constexpr (W >= 12) t = _mm_add_ps(t, _mm512_extractf32x4_ps(v, 2));
  if constexpr (W == 16) t = _mm_add_ps(t, _mm512_extractf32x4_ps(v, 3));
  return sum4(reinterpret_cast<F4>(t));
}

// The window's lanes and the per-lane sums shared by the two measuring passes.
template <int D, int W>
struct Sums {
  __m512 value, deriv, energy;
  __m512 gradient[D];
  KDM_AVX512 explicit Sums(const Footprint<D>& fp)
      : value(load_row<W>(fp.row_value.data())),
        deriv(load_row<W>(fp.row_deriv.data())),
        energy(_mm512_setzero_ps()) {
    for (__m512& g : gradient) g = _mm512_setzero_ps();
  }
  // Adds one row's gradient terms, the sign taken from `s` (R with the kernel in it).
  KDM_AVX512 void add_gradient(__m512 s, __m512 pf, const std::array<float, D>& pd) {
    gradient[0] = _mm512_add_ps(gradient[0], _mm512_mul_ps(pf, signed_by(s, deriv)));
    const __m512 sv = signed_by(s, value);
    for (int k = 1; k < D; ++k)
      gradient[k] = _mm512_add_ps(gradient[k], _mm512_mul_ps(_mm512_set1_ps(pd[k]), sv));
  }
  KDM_AVX512 double finish(Vec<D>& out) const {
    for (int k = 0; k < D; ++k) out[k] = sum_lanes<W>(gradient[k]);
    return sum_lanes<W>(energy);
  }
};

// The remove pass (kRemove: R -= K, the old R kept in `out`) and the measuring pass (R + K, nothing
// written) are one pass seen from either side: the kernel is in R `with` and not `without`.
template <int D, int W, bool kRemove>
struct MeasurePass {
  Sums<D, W> sums;
  std::conditional_t<kRemove, float*, const float*> R;
  float* out;  // kRemove only
  KDM_AVX512 void operator()(std::int64_t base, float p, const std::array<float, D>& pd) {
    const __m512 pf = _mm512_set1_ps(p);
    const __m512 r = load_row<W>(R + base);
    const __m512 rn = kRemove ? _mm512_sub_ps(r, _mm512_mul_ps(pf, sums.value))
                              : _mm512_add_ps(r, _mm512_mul_ps(pf, sums.value));
    const __m512 with = kRemove ? r : rn, without = kRemove ? rn : r;
    sums.add_gradient(with, pf, pd);
    sums.energy = _mm512_add_ps(sums.energy, _mm512_sub_ps(_mm512_abs_ps(with), _mm512_abs_ps(without)));
    if constexpr (kRemove) {
      store_row<W>(out, r);
      store_row<W>(R + base, rn);
      out += W;
    }
  }
};

template <int D, int W>
struct AddPass {
  __m512 value;
  float* R;
  float sign;
  KDM_AVX512 void operator()(std::int64_t base, float p, const std::array<float, D>&) {
    const __m512 r = load_row<W>(R + base);
    store_row<W>(R + base, _mm512_add_ps(r, _mm512_mul_ps(_mm512_set1_ps(sign * p), value)));
  }
};

template <int D, int W>
struct RestorePass {
  float* R;
  const float* in;
  KDM_AVX512 void operator()(std::int64_t base, float, const std::array<float, D>&) {
    store_row<W>(R + base, load_row<W>(in));
    in += W;
  }
};

template <int D, int W>
KDM_AVX512 double remove_avx512(float* R, const Grid<D>& grid, const Footprint<D>& fp, Vec<D>& gradient,
                                float* saved) {
  MeasurePass<D, W, true> pass{Sums<D, W>(fp), R, saved};
  lanes::rows(grid, fp, pass);
  return pass.sums.finish(gradient);
}

template <int D, int W>
KDM_AVX512 double added_avx512(const float* R, const Grid<D>& grid, const Footprint<D>& fp,
                               Vec<D>& gradient) {
  MeasurePass<D, W, false> pass{Sums<D, W>(fp), R, nullptr};
  lanes::rows(grid, fp, pass);
  return pass.sums.finish(gradient);
}

template <int D, int W>
KDM_AVX512 void add_avx512(float* R, const Grid<D>& grid, const Footprint<D>& fp, float sign) {
  AddPass<D, W> pass{load_row<W>(fp.row_value.data()), R, sign};
  lanes::rows(grid, fp, pass);
}

template <int D, int W>
KDM_AVX512 void restore_avx512(float* R, const Grid<D>& grid, const Footprint<D>& fp, const float* saved) {
  RestorePass<D, W> pass{R, saved};
  lanes::rows(grid, fp, pass);
}

template <int W>
KDM_AVX512 void tabulated_axis_avx512(const float* coef, int stride, float s_, std::int32_t j0,
                                      std::int32_t jlo, std::int32_t jhi, float edge, bool with_derivative,
                                      float* v, float* dv) {
  const __m512 s = _mm512_set1_ps(s_);
  __m512 g = _mm512_add_ps(_mm512_mul_ps(load_row<W>(coef + 3 * stride), s), load_row<W>(coef + 2 * stride));
  g = _mm512_add_ps(_mm512_mul_ps(g, s), load_row<W>(coef + stride));
  g = _mm512_add_ps(_mm512_mul_ps(g, s), load_row<W>(coef));
  const __m512 value = _mm512_sub_ps(g, _mm512_set1_ps(edge));
  const __m512i j = _mm512_add_epi32(_mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15),
                                     _mm512_set1_epi32(j0));
  const __mmask16 keep = _mm512_cmpgt_epi32_mask(j, _mm512_set1_epi32(jlo - 1)) &
                         _mm512_cmpgt_epi32_mask(_mm512_set1_epi32(jhi + 1), j) &
                         _mm512_cmp_ps_mask(value, _mm512_setzero_ps(), _CMP_GT_OQ);
  store_row<W>(v, _mm512_maskz_mov_ps(keep, value));
  __m512 d = _mm512_setzero_ps();
  if (with_derivative) {
    d = _mm512_add_ps(_mm512_mul_ps(load_row<W>(coef + 6 * stride), s), load_row<W>(coef + 5 * stride));
    d = _mm512_add_ps(_mm512_mul_ps(d, s), load_row<W>(coef + 4 * stride));
  }
  store_row<W>(dv, _mm512_maskz_mov_ps(keep, d));
}

// Calls f(std::integral_constant<int, W>) for the footprint's width (fits() said it is 8, 12 or 16).
template <class F>
decltype(auto) by_width(int width, F&& f) {
  if (width == 8) return f(std::integral_constant<int, 8>{});
  if (width == 12) return f(std::integral_constant<int, 12>{});
  return f(std::integral_constant<int, 16>{});
}

}  // namespace

// The entry points keep the baseline target (a different target would make them other versions of the
// declared functions); each is one call into its AVX-512 body.
template <int D>
double remove(float* R, const Grid<D>& grid, const Footprint<D>& fp, Vec<D>& gradient, float* saved) {
  return by_width(fp.width, [&](auto w) { return remove_avx512<D, w()>(R, grid, fp, gradient, saved); });
}
template <int D>
double added(const float* R, const Grid<D>& grid, const Footprint<D>& fp, Vec<D>& gradient) {
  return by_width(fp.width, [&](auto w) { return added_avx512<D, w()>(R, grid, fp, gradient); });
}
template <int D>
void add(float* R, const Grid<D>& grid, const Footprint<D>& fp, float sign) {
  by_width(fp.width, [&](auto w) { add_avx512<D, w()>(R, grid, fp, sign); });
}
template <int D>
void restore(float* R, const Grid<D>& grid, const Footprint<D>& fp, const float* saved) {
  by_width(fp.width, [&](auto w) { restore_avx512<D, w()>(R, grid, fp, saved); });
}

void tabulated_axis(const float* coef, int stride, int width, float s, std::int32_t j0, std::int32_t jlo,
                    std::int32_t jhi, float edge, bool with_derivative, float* v, float* dv) {
  by_width(width, [&](auto w) {
    tabulated_axis_avx512<w()>(coef, stride, s, j0, jlo, jhi, edge, with_derivative, v, dv);
  });
}

#else  // no AVX-512 passes on this platform: available() is false, so nothing below is ever called

bool available() {
  return false;
}
template <int D>
double remove(float*, const Grid<D>&, const Footprint<D>&, Vec<D>&, float*) {
  std::abort();
}
template <int D>
double added(const float*, const Grid<D>&, const Footprint<D>&, Vec<D>&) {
  std::abort();
}
template <int D>
void add(float*, const Grid<D>&, const Footprint<D>&, float) {
  std::abort();
}
template <int D>
void restore(float*, const Grid<D>&, const Footprint<D>&, const float*) {
  std::abort();
}
void tabulated_axis(const float*, int, int, float, std::int32_t, std::int32_t, std::int32_t, float, bool,
                    float*, float*) {
  std::abort();
}

#endif

template double remove<2>(float*, const Grid<2>&, const Footprint<2>&, Vec<2>&, float*);
template double remove<3>(float*, const Grid<3>&, const Footprint<3>&, Vec<3>&, float*);
template double added<2>(const float*, const Grid<2>&, const Footprint<2>&, Vec<2>&);
template double added<3>(const float*, const Grid<3>&, const Footprint<3>&, Vec<3>&);
template void add<2>(float*, const Grid<2>&, const Footprint<2>&, float);
template void add<3>(float*, const Grid<3>&, const Footprint<3>&, float);
template void restore<2>(float*, const Grid<2>&, const Footprint<2>&, const float*);
template void restore<3>(float*, const Grid<3>&, const Footprint<3>&, const float*);

}  // namespace kdm::gen::wide
