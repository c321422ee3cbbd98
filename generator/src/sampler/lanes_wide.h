// The passes of Algorithm 1 (Fattal 2011, chain.h) on wide vectors, for x86-64 CPUs with AVX2 or AVX-512:
// a footprint row of 8, 12 or 16 nodes is one 16-lane vector (AVX-512) or two 8-lane ones (AVX2), where
// lanes.h takes two to four four-lane vectors. They give exactly the bits of lanes.h's per-lane passes
// (measure_per_lane, add, restore): every node is evaluated by the same float operations, never fused, and
// each lane's sums are added up in the same order. So a point set does not depend on the machine.
#pragma once

#include <cstdint>

#include "sampler/grid.h"
#include "sampler/kernel.h"

namespace kdm::gen::wide {

/// The widest instruction set this CPU runs the passes with (kNone: none, use lanes.h). Checked once;
/// thread-safe.
Isa best();

/// Whether the CPU runs any of the wide passes.
inline bool available() {
  return best() != Isa::kNone;
}

/// The widest instruction set this CPU has whose vectors hold at most `lanes` floats (16: AVX-512, 8: AVX2;
/// kNone below 8). Thread-safe.
Isa widest(int lanes);

/// Whether the wide code takes a row of this many lanes.
inline bool fits_width(int width) {
  return width == 8 || width == 12 || width == 16;
}

/// Whether the wide passes take this footprint: a contiguous window of 8, 12 or 16 nodes.
template <int D>
bool fits(const Footprint<D>& fp) {
  return fp.contiguous && fits_width(fp.width);
}

// Each requires fits(fp) and an `isa` other than kNone that the CPU has (at most best()); they are
// lanes.h's passes of the same name with per-lane sums. Thread-safe on disjoint R.

/// Removes fp's kernel from R, returning Σ(|R_before| - |R_after|) and eq. 7's gradient; R_before goes to
/// `saved` (width × rows floats).
template <int D>
double remove(Isa isa, float* R, const Grid<D>& grid, const Footprint<D>& fp, Vec<D>& gradient, float* saved);
/// For fp's kernel not in R: Σ(|R + K| - |R|) and the gradient at the new configuration.
template <int D>
double added(Isa isa, const float* R, const Grid<D>& grid, const Footprint<D>& fp, Vec<D>& gradient);
/// R += sign · K.
template <int D>
void add(Isa isa, float* R, const Grid<D>& grid, const Footprint<D>& fp, float sign);
/// Writes `saved` (from remove) back into fp's nodes.
template <int D>
void restore(Isa isa, float* R, const Grid<D>& grid, const Footprint<D>& fp, const float* saved);

/// kernel.cpp's tabulated axis factor (axis_lanes with a KernelTable) for 8, 12 or 16 lanes, with the same
/// bits: lane k is node j0 + k; `coef` points at the table piece's lane for j0, with `stride` floats between
/// its coefficient rows; `s` is the position within the piece. Writes `width` lanes of v and dv.
void tabulated_axis(Isa isa, const float* coef, int stride, int width, float s, std::int32_t j0,
                    std::int32_t jlo, std::int32_t jhi, float edge, bool with_derivative, float* v,
                    float* dv);

/// kernel.cpp's computed axis factor (axis_lanes without a table: simd.h's exp4 of -t², t = a + k'·inv at
/// lane k, k' = j0 + k) for 8, 12 or 16 lanes, with the same bits. Writes `width` lanes of v and dv.
void computed_axis(Isa isa, int width, float a, float inv, float dscale, std::int32_t j0, std::int32_t jlo,
                   std::int32_t jhi, float edge, bool with_derivative, float* v, float* dv);

}  // namespace kdm::gen::wide
