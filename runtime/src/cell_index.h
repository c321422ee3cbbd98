// Internal: a tile's points in the cells a region meets (QueryTables::cell_ranks), visited in rank order
// through emit_tile's listed emitter, so that a region covering a small part of a tile (a chunk smaller
// than the tiles, or a tile the region's side cuts near a corner) costs its cells' points, not the tile's.
#pragma once

#include <algorithm>
#include <cstdint>

#include "emit_tile.h"
#include "query_tables.h"

namespace kdm::detail {

/// The cells of a tile (columns x0 … x1, rows y0 … y1, inclusive) that a rectangle of stable positions
/// meets.
struct CellSpan {
  std::uint32_t x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  std::uint32_t count() const { return (x1 - x0 + 1) * (y1 - y0 + 1); }
};

/// The cells meeting lo ≤ u < hi and the same in v, in position units (1/65536 tile sides).
inline CellSpan cells_met(double lo_u, double lo_v, double hi_u, double hi_v) {
  auto column = [](double u) {  // clamped to the tile; NaN gives the first
    constexpr double kCellUnits = 65536.0 / kIndexCells;
    const double c = std::floor(u / kCellUnits);
    return c >= kIndexCells - 1 ? kIndexCells - 1 : c > 0 ? static_cast<std::uint32_t>(c) : 0u;
  };
  return CellSpan{column(lo_u), column(hi_u), column(lo_v), column(hi_v)};
}

inline int lowest_set_bit(std::uint64_t w) {
#if defined(__GNUC__) || defined(__clang__)
  return __builtin_ctzll(w);
#else
  int k = 0;
  for (; !(w & 1); w >>= 1) ++k;
  return k;
#endif
}

/// Emits the ranks [c, end) of tile `index` that lie in the cells `span`, in rank order, through `emit`
/// (a listed emitter, which tests each as the full scan would): the rank it stopped at, or end.
template <class Sink>
std::uint32_t emit_cells(const QueryTables& tables, std::size_t index, const CellSpan& span, TileJob& job,
                         std::uint32_t c, std::uint32_t end, EmitTile<Sink> emit, const Sink& out,
                         std::size_t capacity, std::size_t& written) {
  constexpr std::uint32_t kCells = kIndexCells * kIndexCells;
  constexpr std::uint32_t kWindow = 2048;  // ranks per pass: a bitmap and a list of them on the stack
  const std::uint32_t* start = tables.cell_start.data() + (kCells + 1) * index;
  const std::uint16_t* ranks = tables.cell_ranks[index].data();
  std::uint32_t at[kCells], stop[kCells], cells = 0;
  for (std::uint32_t y = span.y0; y <= span.y1; ++y)
    for (std::uint32_t x = span.x0; x <= span.x1; ++x, ++cells) {
      const std::uint32_t k = y * kIndexCells + x;
      at[cells] =
          static_cast<std::uint32_t>(std::lower_bound(ranks + start[k], ranks + start[k + 1], c) - ranks);
      stop[cells] = start[k + 1];
    }
  std::uint32_t listed[kWindow];
  std::uint64_t bits[kWindow / 64];
  for (std::uint32_t w = c; w < end;) {
    std::uint32_t next = end;  // no window starts before the cells' next rank
    for (std::uint32_t k = 0; k < cells; ++k)
      if (at[k] < stop[k]) next = std::min<std::uint32_t>(next, ranks[at[k]]);
    if (next >= end) break;
    w = std::max(w, next);
    const std::uint32_t w_end = end - w > kWindow ? w + kWindow : end;
    std::fill(bits, bits + kWindow / 64, 0);
    for (std::uint32_t k = 0; k < cells; ++k) {
      std::uint32_t i = at[k];
      for (; i < stop[k] && ranks[i] < w_end; ++i)
        bits[(ranks[i] - w) >> 6] |= std::uint64_t(1) << ((ranks[i] - w) & 63);
      at[k] = i;
    }
    std::uint32_t m = 0;
    for (std::uint32_t b = 0; b < (w_end - w + 63) / 64; ++b)
      for (std::uint64_t word = bits[b]; word != 0; word &= word - 1)
        listed[m++] = w + 64 * b + lowest_set_bit(word);
    job.listed = listed, job.listed_end = listed + m;
    const std::uint32_t stopped = emit(job, w, w_end, out, capacity, written);
    job.listed = job.listed_end = nullptr;
    if (stopped < w_end) return stopped;
    w = w_end;
  }
  return end;
}

}  // namespace kdm::detail
