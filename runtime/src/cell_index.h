// Internal: a tile's points in the cells a region meets (QueryTables::cell_ranks), visited cell by cell
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

/// Where a tile visited through its cells stopped: the cell (its place in the span, row by row) and the
/// rank in it to go on from (QueryCursor's path, less one, and rank).
struct CellPlace {
  std::uint32_t cell = 0, rank = 0;
};

/// Emits the points of tile `index` that lie in the cells `span` and rank below `end`, cell by cell from
/// `at` on, each cell's in rank order, through `emit` (a listed emitter, which tests each as the full scan
/// would), visiting at most `budget` of them (reduced by those visited). Returns true when the tile is
/// done, false with `at` where it stopped (the buffer full or the budget spent).
template <class Sink>
bool emit_cells(const QueryTables& tables, std::size_t index, const CellSpan& span, TileJob& job,
                CellPlace& at, std::uint32_t end, std::uint64_t& budget, EmitTile<Sink> emit, const Sink& out,
                std::size_t capacity, std::size_t& written) {
  // Several cells' ranks go to the emitter in one list (it takes them in list order), so that a call's
  // cost is shared by cells of a few points each.
  constexpr std::uint32_t kBatch = 2048;
  const std::uint32_t* start = tables.cell_start.data() + (kIndexCells * kIndexCells + 1) * index;
  const std::uint16_t* ranks = tables.cell_ranks[index].data();
  const std::uint32_t columns = span.x1 - span.x0 + 1, cells = span.count();
  std::uint32_t listed[kBatch];
  std::uint32_t cell_of[kIndexCells * kIndexCells + 1], first_of[kIndexCells * kIndexCells + 1];
  const std::uint16_t* p = nullptr;  // the next rank of cell at.cell, once found
  while (at.cell < cells) {
    // A batch: the cells' ranks from at on, while they fit and the budget lasts.
    std::uint32_t m = 0, batched = 0;
    const std::uint64_t most = std::min<std::uint64_t>(kBatch, budget);
    // Cell at.cell is k in the tile's numbering, stepped along rather than divided out at every cell.
    std::uint32_t column = at.cell % columns,
                  k = (span.y0 + at.cell / columns) * kIndexCells + span.x0 + column;
    for (; at.cell < cells; ++at.cell, at.rank = 0, p = nullptr) {
      if (column == columns) column = 0, k += kIndexCells - columns;
      const std::uint16_t* const stop = ranks + start[k + 1];
      if (!p) p = at.rank == 0 ? ranks + start[k] : std::lower_bound(ranks + start[k], stop, at.rank);
      cell_of[batched] = at.cell, first_of[batched++] = m;
      for (; m < most && p != stop && *p < end; ++p) listed[m++] = *p;
      if (m == most && p != stop && *p < end) {  // the cell goes on in the next batch
        at.rank = *p;
        break;
      }
      ++column, ++k;
    }
    if (m == 0) {
      if (at.cell == cells) break;
      return false;  // the budget is spent
    }
    job.listed = listed, job.listed_end = listed + m;
    const std::uint32_t stopped = emit(job, 0, ~0u, out, capacity, written);
    job.listed = job.listed_end = nullptr;
    if (stopped == ~0u) {
      budget -= m;
      continue;
    }
    // The buffer is full at rank `stopped`: its place in the list, and the cell it came from.
    const auto i = static_cast<std::uint32_t>(std::find(listed, listed + m, stopped) - listed);
    budget -= i;
    std::uint32_t b = batched - 1;
    while (first_of[b] > i) --b;
    at = CellPlace{cell_of[b], stopped};
    return false;
  }
  return true;
}

}  // namespace kdm::detail
