// Internal: the loop that emits one depth-0 tile's candidates (query.cpp's driver calls it per tile), for
// each mode, kind of density and output form (query.h's QueryPoint records or compact_query.h's arrays).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "density_bounds.h"
#include "float_runs.h"
#include "glide_runs.h"
#include "image_runs.h"
#include "image_sampler.h"
#include "keyframe_lookup.h"
#include "output_sinks.h"
#include "query_tables.h"
#include "signed_byte_table.h"

namespace kdm::detail {

/// Compact output beside the region, either mode: rectangles in float relative to the origin such that a
/// point whose float position lies inside `sure` lies inside the region by the query's test in double, and
/// one outside `may` outside it. Their margin is far beyond the float formula's error (within
/// 2^-21 · (|p| + S), CompactSink) and a double's rounding at the world's magnitudes.
struct RegionFlagBoxes {
  FloatBox sure, may;
};
inline RegionFlagBoxes region_flag_boxes(const TileJob& j) {
  const double x0 = j.x0 - j.origin_x, x1 = j.x1 - j.origin_x, y0 = j.y0 - j.origin_y, y1 = j.y1 - j.origin_y;
  const double far = std::max({std::fabs(x0), std::fabs(x1), std::fabs(y0), std::fabs(y1)}) + 2 * j.S;
  const double world = std::fabs(j.wx) + std::fabs(j.wy) + std::fabs(j.x0) + std::fabs(j.x1) +
                       std::fabs(j.y0) + std::fabs(j.y1) + std::fabs(j.origin_x) + std::fabs(j.origin_y) +
                       j.S;
  const double m = std::ldexp(far, -18) + 1e-14 * world;
  auto up = [](double v) {  // the least float ≥ v
    const float f = static_cast<float>(v);
    return double(f) < v ? std::nextafter(f, HUGE_VALF) : f;
  };
  auto down = [](double v) {  // the greatest float ≤ v
    const float f = static_cast<float>(v);
    return double(f) > v ? std::nextafter(f, -HUGE_VALF) : f;
  };
  return {{up(x0 + m), up(y0 + m), down(x1 - m), down(y1 - m)},
          {down(x0 - m), down(y0 - m), up(x1 + m), up(y1 + m)}};
}

/// Stable mode with a varying density: a tile's 2^kCellBits × 2^kCellBits cells, whose bounds settle a
/// candidate between the tile's bounds without reading the density where they can.
constexpr std::uint32_t kCellBits = 2;

/// Stable mode, a class query: candidates c … c + count - 1 (count ≤ kImageBlock) of tile j inside the
/// region, their densities rho[i] and classes cls[i] read together, decided as emit_tile's `decide` decides
/// (each written at the next slot, which only an emitted one keeps) from slot n on; returns the rank that did
/// not fit, or ~0u. Their classes are gathered here and written together: a byte stored through the
/// output's pointer could alias the loop's state, which the compiler would then reload at every candidate.
template <class Sink>
[[gnu::always_inline]] inline std::uint32_t put_classed_block(const TileJob& j, const Sink& out,
                                                              std::uint32_t c, std::uint32_t count,
                                                              const double* rho, const std::uint8_t* cls,
                                                              std::size_t capacity, std::size_t& n) {
  std::uint8_t classes[kImageBlock];
  const std::size_t first = n;
  std::size_t m = first;
  std::uint32_t stopped = ~0u;
  for (std::uint32_t i = 0; i < count; ++i) {
    const bool emitted = TilesetShape::emits(j.thresholds[c + i], rho[i] * j.area_scale);
    if (m == capacity) {
      if (!emitted) continue;
      stopped = c + i;
      break;
    }
    out.put_stable_unclassed(m, j, j.points[c + i], c + i);
    classes[m - first] = cls[i];
    m += emitted;
  }
  out.put_classes(first, classes, m - first);
  n = m;
  return stopped;
}

/// Emits the candidates [c, end) of one tile into out[n ..) (at most `capacity` in all); returns the rank
/// it stopped at (end, or the first point that did not fit). kInside: every point the tile can emit, glided
/// or not, lies inside the region, so no point is tested against it. kListed: only the ranks of
/// job.listed are visited, in their order (the others are culled, as the full scan would).
template <class Sink, bool kSmooth, QueryDensity::Kind kKind, bool kInside, bool kListed>
std::uint32_t emit_tile(const TileJob& job, std::uint32_t c, std::uint32_t end, const Sink out,
                        std::size_t capacity, std::size_t& written) {
  const TileJob j = job;  // a local copy, which the writes into `out` cannot alias
  std::size_t n = written;
  constexpr bool kConstant = kKind == QueryDensity::Kind::kConstant;
  if constexpr (!kConstant && kInside && !kSmooth) {  // the ranks sure to be emitted, as a constant's
    if (c < j.sure) {
      const std::uint32_t count =
          static_cast<std::uint32_t>(std::min<std::size_t>(std::min(end, j.sure) - c, capacity - n));
      out.put_stable_run(n, j, c, count);
      n += count, c += count;
      if (c < std::min(end, j.sure) || c == end) {
        written = n;
        return c;
      }
    }
  }
  if constexpr (kConstant && kInside && !kSmooth) {
    // Every candidate is emitted where it stands: a plain loop the compiler can vectorise.
    const std::uint32_t count = static_cast<std::uint32_t>(std::min<std::size_t>(end - c, capacity - n));
    out.put_stable_run(n, j, c, count);
    written = n + count;
    return c + count;
  }
  const GlideBracket constant = kSmooth && kConstant ? GlideBracket(j.keyframes, j.limit) : GlideBracket();
  const double unit = j.S * (1.0 / 65536.0);  // world units per position unit
  ConstantGlide glide{};
  if (kSmooth) {
    glide.o0 = j.glide + 2 * std::size_t(j.starts[constant.g0]);
    glide.o1 = j.glide + 2 * std::size_t(j.starts[constant.g1]);
    glide.w0 = constant.w0, glide.w1 = constant.w1;
    glide.w0f = static_cast<float>(constant.w0 * unit), glide.w1f = static_cast<float>(constant.w1 * unit);
  }
  if constexpr (kConstant && kInside && kSmooth) {  // the same, glided by the tile's two keyframes
    const std::uint32_t count = static_cast<std::uint32_t>(std::min<std::size_t>(end - c, capacity - n));
    out.put_glided_run(n, j, glide, c, count);
    written = n + count;
    return c + count;
  }
  // Culling bounds; with a varying density they narrow with the rank: a point whose threshold is at least
  // K_g is emitted only above it, where it glides no farther than any point does from keyframe g on.
  const std::size_t keyframes = kSmooth ? j.keyframes.n : 0;
  std::size_t segment = 0;  // varying: the keyframes whose count the thresholds from rank c on reach
  double lo_x = 0, hi_x = 0, lo_y = 0, hi_y = 0;
  auto set_reach = [&](double reach) {
    lo_x = j.cull_x0 - reach * 65536.0, hi_x = j.cull_x1 + reach * 65536.0;
    lo_y = j.cull_y0 - reach * 65536.0, hi_y = j.cull_y1 + reach * 65536.0;
  };
  if (kSmooth && !kInside) set_reach(kConstant ? j.reach : j.tables->glide_reach_from[0]);
  // Smooth mode: places candidate c at its stable position (x, y) plus its offsets o0 and o1 weighted by
  // w0 and w1 (GlideBracket): false when the buffer is full.
  auto glide_by = [&](double& x, double& y, const std::int8_t* o0, const std::int8_t* o1, double w0,
                      double w1) {
    const double* v = kSignedByte.value + 128;
    x += (v[o0[0]] * w0 + v[o1[0]] * w1) * unit, y += (v[o0[1]] * w0 + v[o1[1]] * w1) * unit;
  };
  auto outside = [&](double x, double y) { return x < j.x0 || x >= j.x1 || y < j.y0 || y >= j.y1; };
  // `glided`: a batch callback's value at the glided position, read with the batch's (else read here).
  auto place = [&](std::uint32_t c, double x, double y, const std::int8_t* o0, const std::int8_t* o1,
                   double w0, double w1, std::uint8_t cls, const double* glided = nullptr) -> bool {
    glide_by(x, y, o0, o1, w0, w1);
    // Where the region cuts the tile, whether a point lies inside follows no pattern: it is written at the
    // next slot, which only then it keeps.
    const bool in = kInside || ((x >= j.x0) & (x < j.x1) & (y >= j.y0) & (y < j.y1));
    // A point never shows where there is no density: one decided at its stable position could glide up
    // to a spacing past a sharp edge of the density (stray dots outside a stippled shape).
    if (!kConstant && j.zero_possible) {
      if (!in) return true;
      if (kKind == QueryDensity::Kind::kImage && !(j.sampler->at(x, y) > 0)) return true;
      if (kKind == QueryDensity::Kind::kCallback &&
          !(density_or_zero(glided ? *glided : j.density->callback(j.density->user, x, y)) > 0))
        return true;
    }
    if (n == capacity) return !in;
    if constexpr (kConstant)
      out.put_glided(n, j, glide, c);
    else if constexpr (kClassesAtDensity<Sink>)
      out.put_classed(n, x - j.origin_x, y - j.origin_y, PointId{j.tx, j.ty, c}, cls);
    else
      out.put(n, x - j.origin_x, y - j.origin_y, PointId{j.tx, j.ty, c});
    n += in;
    return true;
  };
  // Smooth mode with a varying density: the emitted candidates wait in a batch, so that the long chain from
  // a point's density to its glided position overlaps between points instead of restarting after every
  // mispredicted emission test.
  constexpr bool kBatched = kSmooth && !kConstant;
  constexpr std::uint32_t kNone = ~0u;
  // A batch callback's reads (BatchCallback below): each tile's, kDensityBatch at a time; the second
  // reads at glided positions go with the emitted points' batch, which then holds as many.
  constexpr bool kMayBatchReads = kKind == QueryDensity::Kind::kCallback;
  const bool batch_reads = kMayBatchReads && j.density->batch_callback;
  constexpr int kBatch = kBatched ? (kMayBatchReads ? int(kDensityBatch) : 32) : 1;
  const int batch_size = batch_reads ? kBatch : std::min(kBatch, 32);
  std::uint32_t pending_rank[kBatch];
  constexpr std::size_t kGather = kMayBatchReads ? kDensityBatch : 1;  // of a batch callback's reads
  double glided[kGather], gx[kGather], gy[kGather];
  double pending_expected[kBatch], pending_x[kBatch], pending_y[kBatch];
  std::uint8_t pending_class[kBatch];
  int pending = 0;
  // The expected count each pending point glides by: its own, or glide_count.h's (glide_together), a block
  // of points at a time (glide_runs.h): their corners in one vectorised loop, read in one batch callback's
  // call or the image's vectorised reads, and their counts in another loop.
  auto counts_to_glide_by = [&](double* count) {
    if (!j.glide_together) {
      std::copy(pending_expected, pending_expected + pending, count);
      return;
    }
    static_assert(GlideLattice::kCorners * kGlideBlock <= kDensityBatch,
                  "a block's corners in one batch call");
    glide_counts(
        pending_expected, pending_x, pending_y, std::size_t(pending), j.S, j.area_scale,
        [&](std::size_t reads, const double* cx, const double* cy, double* value) {
          if constexpr (kKind == QueryDensity::Kind::kImage) {
            if (image_runs_fit(*j.sampler->image))
              for (std::size_t r = 0; r < reads; r += kImageBlock)
                image_read_run(cx + r, cy + r, std::min<std::size_t>(kImageBlock, reads - r), *j.sampler,
                               value + r);
            else
              for (std::size_t r = 0; r < reads; ++r) value[r] = j.sampler->at(cx[r], cy[r]);
          } else {
            if (batch_reads)
              j.density->batch_callback(j.density->user, reads, cx, cy, value);
            else
              for (std::size_t r = 0; r < reads; ++r)
                value[r] = j.density->callback(j.density->user, cx[r], cy[r]);
            for (std::size_t r = 0; r < reads; ++r) value[r] = density_or_zero(value[r]);
          }
        },
        count);
  };
  auto flush = [&]() -> std::uint32_t {  // the rank that did not fit, or kNone
    // Two passes, each short enough for the processor to overlap many points' latency chains.
    const std::int8_t *o0[kBatch], *o1[kBatch];
    double w0[kBatch], w1[kBatch], count[kBatch];
    counts_to_glide_by(count);
    for (int i = 0; i < pending; ++i) {
      const GlideBracket b(j.keyframes, count[i]);
      o0[i] = j.glide + 2 * (std::size_t(j.starts[b.g0]) + pending_rank[i]);
      o1[i] = j.glide + 2 * (std::size_t(j.starts[b.g1]) + pending_rank[i]);
      w0[i] = b.w0, w1[i] = b.w1;
    }
    const bool read_glided = batch_reads && j.zero_possible && pending > 0;
    if (read_glided) {  // the densities at the glided positions, in one call
      for (int i = 0; i < pending; ++i) {
        gx[i] = pending_x[i], gy[i] = pending_y[i];
        glide_by(gx[i], gy[i], o0[i], o1[i], w0[i], w1[i]);
      }
      j.density->batch_callback(j.density->user, std::size_t(pending), gx, gy, glided);
    }
    for (int i = 0; i < pending; ++i)
      if (!place(pending_rank[i], pending_x[i], pending_y[i], o0[i], o1[i], w0[i], w1[i], pending_class[i],
                 read_glided ? glided + i : nullptr))
        return pending = 0, pending_rank[i];
    pending = 0;
    return kNone;
  };
  // Stable mode, a density with bounds: each cell's expected counts' bounds (widened by 10^-9 for rounding,
  // as the tile's), read when a candidate first lies in it. The cell's sides are computed as positions are
  // (corner plus a fraction times the side) and rounding is monotonic, so its points lie in its rectangle.
  constexpr bool kCells = !kSmooth && !kConstant;
  constexpr std::uint32_t kCellCount = kCells ? 1u << (2 * kCellBits) : 1;
  static_assert(kCellCount <= 32, "a bit per cell in cells_read");
  double cell_lo[kCellCount], cell_hi[kCellCount];
  std::uint32_t cells_read = 0;
  auto cell_of = [&](TilePoint p) {
    const std::uint32_t cx = p.x >> (16 - kCellBits), cy = p.y >> (16 - kCellBits);
    const std::uint32_t cell = kCells ? cy << kCellBits | cx : 0;
    if (!(cells_read >> cell & 1)) {
      constexpr double kStep = 1.0 / (1 << kCellBits);
      double lo, hi;
      density_bounds(*j.density, j.wx + (cx * kStep) * j.S, j.wy + (cy * kStep) * j.S,
                     j.wx + ((cx + 1) * kStep) * j.S, j.wy + ((cy + 1) * kStep) * j.S, lo, hi);
      cell_lo[cell] = lo * j.area_scale * (1 - 1e-9), cell_hi[cell] = hi * j.area_scale * (1 + 1e-9);
      cells_read |= 1u << cell;
    }
    return cell;
  };
  // One candidate: the rank that did not fit, or kNone. Positions: the stable one (for ρ and in stable
  // mode), then the glide added to it.
  auto culled = [&](TilePoint p) {
    const double sx = p.x + 0.5, sy = p.y + 0.5;
    return sx < lo_x || sx >= hi_x || sy < lo_y || sy >= hi_y;
  };
  // A candidate whose density `rho` is read at its stable position (x, y): written or queued, as visit says.
  // `cls`: its class where the caller found it (a class query), else null.
  auto decide = [&](std::uint32_t c, TilePoint p, double x, double y, double rho,
                    const std::uint8_t* cls = nullptr) -> std::uint32_t {
    const double expected = rho * j.area_scale;
    // Whether a point is emitted follows no pattern a branch predictor could learn: each candidate is
    // written (or queued) at the next slot, which only an emitted one then keeps.
    const bool emitted = TilesetShape::emits(j.thresholds[c], expected);
    if (!kBatched) {
      if (n == capacity) return emitted ? c : kNone;
      if constexpr (kClassesAtDensity<Sink>) {
        if (cls)
          out.put_stable_classed(n, j, p, c, *cls);
        else
          out.put_stable(n, j, p, c);
      } else {
        out.put_stable(n, j, p, c);
      }
      n += emitted;
      return kNone;
    }
    pending_rank[pending] = c, pending_expected[pending] = expected;
    pending_x[pending] = x, pending_y[pending] = y;
    if constexpr (kClassesAtDensity<Sink>) {
      if (emitted) pending_class[pending] = cls ? *cls : out.class_at(j, c, x, y);
    }
    pending += emitted;
    return pending == batch_size ? flush() : kNone;
  };
  // Smooth mode beside the region: whether candidate c (at p) cannot glide into it.
  auto beyond_reach = [&](std::uint32_t c, TilePoint p) {
    if (kSmooth && !kInside) {
      if (!kConstant && kListed && segment > 0 && c < j.ranks[segment - 1]) {  // cells' lists, one by one
        segment = 0;
        set_reach(j.tables->glide_reach_from[0]);
      }
      if (!kConstant && segment < keyframes && j.ranks[segment] <= c) {
        while (segment < keyframes && j.ranks[segment] <= c) ++segment;
        set_reach(j.tables->glide_reach_from[segment - 1]);
      }
      // A listed constant-density candidate is glided and tested without a branch (place): its list has
      // already left out most of those the culling would, and whether it is culled follows no pattern.
      if (!(kConstant && kListed) && culled(p)) return true;
    }
    return false;
  };
  auto visit = [&](std::uint32_t c) -> std::uint32_t {
    const TilePoint p = j.points[c];
    if (beyond_reach(c, p)) return kNone;
    const double x = j.wx + p.unit_x() * j.S, y = j.wy + p.unit_y() * j.S;
    if constexpr (!kSmooth) {
      const bool in = kInside || ((x >= j.x0) & (x < j.x1) & (y >= j.y0) & (y < j.y1));
      if (kConstant || c < j.sure) {  // emitted if inside: written at the next slot, which only then it keeps
        if (n == capacity) return in ? c : kNone;
        out.put_stable(n, j, p, c);
        n += in;
        return kNone;
      }
      if (!in) return kNone;
    }
    if (kConstant)
      return place(c, x, y, glide.o0 + 2 * std::size_t(c), glide.o1 + 2 * std::size_t(c), glide.w0, glide.w1,
                   0)
                 ? kNone
                 : c;
    if (kCells && j.cells) {
      const std::uint32_t cell = cell_of(p);
      if (!TilesetShape::emits(j.thresholds[c], cell_hi[cell])) return kNone;  // not even at its cell's most
      if (TilesetShape::emits(j.thresholds[c], cell_lo[cell])) {
        if (n == capacity) return c;
        out.put_stable(n++, j, p, c);
        return kNone;
      }
    }
    const double rho = kKind == QueryDensity::Kind::kImage
                           ? j.sampler->at(x, y)
                           : density_or_zero(j.density->callback(j.density->user, x, y));
    return decide(c, p, x, y, rho);
  };
  // A batch callback: the candidates visit would read wait, in order and with those it settles unread,
  // until kDensityBatch of them are gathered; one call then reads them all and each is decided as visit
  // decides it. `next` gives the ranks to visit, kNone past the last.
  std::uint32_t rank[kGather], read_rank[kGather];
  bool read[kGather];
  double bx[kGather], by[kGather], rho[kGather];
  // A class query's: the classes of the ranks read, and the ranks emitted unread, classed together after.
  // Smooth mode reads every candidate it visits.
  constexpr bool kClassUnread = kClassesAtDensity<Sink> && !kSmooth;
  constexpr std::size_t kClassed = kClassesAtDensity<Sink> ? kGather : 1,
                        kUnread = kClassUnread ? kGather : 1;
  std::uint8_t read_class[kClassed], unread_class[kUnread];
  std::uint32_t unread_rank[kUnread];
  double ux[kUnread], uy[kUnread];
  auto visit_in_batches = [&](auto next) -> std::uint32_t {
    for (bool more = true; more;) {
      std::size_t gathered = 0, reads = 0, unread = 0;
      while (gathered < kGather) {
        const std::uint32_t r = next();
        if (r == kNone) {
          more = false;
          break;
        }
        const TilePoint p = j.points[r];
        if (beyond_reach(r, p)) continue;
        const double x = j.wx + p.unit_x() * j.S, y = j.wy + p.unit_y() * j.S;
        bool unread_emitted = false;  // stable mode: emitted without a read, as visit emits it
        if constexpr (!kSmooth) {
          if (!(kInside || ((x >= j.x0) & (x < j.x1) & (y >= j.y0) & (y < j.y1)))) continue;
          if (r < j.sure) {
            unread_emitted = true;
          } else if (kCells && j.cells) {
            const std::uint32_t cell = cell_of(p);
            if (!TilesetShape::emits(j.thresholds[r], cell_hi[cell])) continue;
            unread_emitted = TilesetShape::emits(j.thresholds[r], cell_lo[cell]);
          }
        }
        if (unread_emitted && gathered == 0 && !kClassUnread) {  // nothing waits: written at once
          if (n == capacity) return r;
          out.put_stable(n++, j, p, r);
          continue;
        }
        rank[gathered] = r, read[gathered++] = !unread_emitted;
        if (!unread_emitted)
          read_rank[reads] = r, bx[reads] = x, by[reads++] = y;
        else if constexpr (kClassUnread)
          unread_rank[unread] = r, ux[unread] = x, uy[unread++] = y;
      }
      if (reads > 0) {
        j.density->batch_callback(j.density->user, reads, bx, by, rho);
        if constexpr (kClassesAtDensity<Sink>) out.classes_of_reads(j, read_rank, reads, bx, by, read_class);
      }
      if constexpr (kClassUnread) {
        if (unread > 0) out.classes_of_unread(j, unread_rank, unread, ux, uy, unread_class);
      }
      for (std::size_t i = 0, k = 0, u = 0; i < gathered; ++i) {
        const std::uint32_t r = rank[i];
        std::uint32_t stop = kNone;
        if (read[i]) {
          stop = decide(r, j.points[r], bx[k], by[k], density_or_zero(rho[k]),
                        kClassesAtDensity<Sink> ? read_class + k : nullptr);
          ++k;
        } else if (n == capacity) {
          stop = r;
        } else if constexpr (kClassUnread) {
          out.put_stable_classed(n++, j, j.points[r], r, unread_class[u++]);
        } else {
          out.put_stable(n++, j, j.points[r], r);
        }
        if (stop != kNone) return stop;
      }
    }
    return kNone;
  };
  std::uint32_t stopped = kNone;
  if (batch_reads) {
    if constexpr (kListed) {
      const std::uint32_t* it = std::lower_bound(j.listed, j.listed_end, c);
      stopped = visit_in_batches([&] { return it != j.listed_end && *it < end ? *it++ : kNone; });
    } else {
      stopped = visit_in_batches([&] { return c < end ? c++ : kNone; });
    }
  } else if constexpr (kListed) {
    const std::uint32_t* it = std::lower_bound(j.listed, j.listed_end, c);
    for (; it != j.listed_end && *it < end && stopped == kNone; ++it) stopped = visit(*it);
  } else if constexpr (kConstant && !kInside && Sink::kVectorRuns) {
    // Beside the region, compact output: candidates are written a chunk at a time as whole tiles inside
    // are; their float positions, held to the region in one vector pass, settle all but those within
    // rounding of its sides, which are tested as visit tests them; the kept ones are then closed up over
    // the rest. Point by point, whether a point lies inside is a branch the predictor misses where the
    // region cuts the tile, and runs cut at every point near a side leave the vector loop's scalar ends.
    constexpr std::size_t kChunk = 2048;  // written, then read back, while in the first-level cache
    std::uint8_t flags[kChunk];
    const RegionFlagBoxes boxes = region_flag_boxes(j);
    auto lands_inside = [&](std::uint32_t r) {
      const TilePoint p = j.points[r];
      if (kSmooth && culled(p)) return false;
      double x = j.wx + p.unit_x() * j.S, y = j.wy + p.unit_y() * j.S;
      if (kSmooth)
        glide_by(x, y, glide.o0 + 2 * std::size_t(r), glide.o1 + 2 * std::size_t(r), glide.w0, glide.w1);
      return !outside(x, y);
    };
    while (c < end && n < capacity) {
      const auto count = static_cast<std::uint32_t>(std::min<std::size_t>({end - c, capacity - n, kChunk}));
      if constexpr (kSmooth)
        out.put_glided_run(n, j, glide, c, count);
      else
        out.put_stable_run(n, j, c, count);
      box_flags(out.positions(n), count, boxes.sure, boxes.may, flags);
      for (std::uint32_t i = next_unsure(flags, 0, count); i < count; i = next_unsure(flags, i + 1, count))
        flags[i] = lands_inside(c + i);
      n = close_up(out, n, flags, count), c += count;
    }
    // The rest one by one (a full buffer: so that the call stops at the first point that does not fit).
    for (; c < end && stopped == kNone; ++c) stopped = visit(c);
  } else if constexpr (kSmooth && kConstant && !kInside) {
    // Beside the region, QueryPoint records: where the tile reaches well into the region (it has safe
    // cells), each candidate is glided, written at the next slot and kept if inside, with no branch a
    // predictor would miss where the region cuts the tile; elsewhere most are culled, predictably.
    if (j.safe_w != 0 && j.safe_h != 0) {
      for (; c < end && n < capacity; ++c) {
        const TilePoint p = j.points[c];
        double x = j.wx + p.unit_x() * j.S, y = j.wy + p.unit_y() * j.S;
        glide_by(x, y, glide.o0 + 2 * std::size_t(c), glide.o1 + 2 * std::size_t(c), glide.w0, glide.w1);
        const bool in = (x >= j.x0) & (x < j.x1) & (y >= j.y0) & (y < j.y1);
        out.put_glided(n, j, glide, c);
        n += in;
      }
    }
    for (; c < end && stopped == kNone; ++c) stopped = visit(c);
  } else if constexpr (kKind == QueryDensity::Kind::kImage && (kSmooth || kInside)) {
    // Nearly every candidate's density is read (a tile in the region, or at its side): a block of them at
    // once, in a loop the compiler vectorises.
    double bx[kImageBlock], by[kImageBlock], rho[kImageBlock];
    if (!image_runs_fit(*j.sampler->image))
      for (; c < end && stopped == kNone; ++c) stopped = visit(c);
    // Classes by their running sums' images: the union is the last one, and the emitted candidates are
    // classed from the same texels (their classes then at cls[i], else null).
    std::uint8_t cls[kImageBlock] = {};
    double lo[kMaxQueryClasses], hi[kMaxQueryClasses];  // the sums' expected counts' bounds over the tile
    bool bounded = false;
    auto read_block = [&](std::uint32_t count) -> const std::uint8_t* {
      if constexpr (kClassesAtDensity<Sink>) {
        if (const ClassImages* sums = out.images(); sums && sums->cumulative) {
          const double area = out.class_area();
          for (std::uint32_t k = 0; k + 1 < sums->count && !bounded; ++k) {  // widened as the classifier's
            lo[k] = sums->sums[k]->min_over(j.wx, j.wy, j.wx + j.S, j.wy + j.S) * area * (1 - 1e-9);
            hi[k] = sums->sums[k]->max_over(j.wx, j.wy, j.wx + j.S, j.wy + j.S) * area * (1 + 1e-9);
          }
          bounded = true;
          image_classes_run(j.points + c, count, j.wx, j.wy, j.S, *j.sampler, sums->values, sums->count, lo,
                            hi, j.thresholds + c, j.area_scale, area, bx, by, rho, cls);
          return cls;
        }
      }
      image_run(j.points + c, count, j.wx, j.wy, j.S, *j.sampler, bx, by, rho);
      return nullptr;
    };
    while (c < end && stopped == kNone) {
      const std::uint32_t count = std::min(end - c, kImageBlock);
      const std::uint8_t* classed = read_block(count);
      if constexpr (kClassesAtDensity<Sink> && !kSmooth) {
        if (classed) {
          stopped = put_classed_block(j, out, c, count, rho, classed, capacity, n);
          c += count;
          continue;
        }
      }
      for (std::uint32_t i = 0; i < count && stopped == kNone; ++i, ++c)
        if (!beyond_reach(c, j.points[c]))
          stopped = decide(c, j.points[c], bx[i], by[i], rho[i], classed ? classed + i : nullptr);
    }
  } else if constexpr (kKind == QueryDensity::Kind::kCallback && kClassesAtDensity<Sink> &&
                       (kSmooth || kInside)) {
    // Classes that are all images on one grid: their running sums a block at a time, as above.
    const ClassImages* images = out.images();
    if (images && image_runs_fit(*images->grid->image)) {
      double bx[kImageBlock], by[kImageBlock], rho[kImageBlock], sums[kImageBlock * kMaxQueryClasses];
      std::uint8_t cls[kImageBlock];
      const double* total = sums + (images->count - 1) * std::size_t(kImageBlock);
      while (c < end && stopped == kNone) {
        const std::uint32_t count = std::min(end - c, kImageBlock);
        image_sums_run(j.points + c, count, j.wx, j.wy, j.S, *images->grid, images->values, images->count, bx,
                       by, sums);
        out.classes_of_sums(j, c, count, sums, kImageBlock, cls);
        if constexpr (!kSmooth) {
          for (std::uint32_t i = 0; i < count; ++i) rho[i] = density_or_zero(total[i]);
          stopped = put_classed_block(j, out, c, count, rho, cls, capacity, n);
          c += count;
          continue;
        }
        for (std::uint32_t i = 0; i < count && stopped == kNone; ++i, ++c)
          if (!beyond_reach(c, j.points[c]))
            stopped = decide(c, j.points[c], bx[i], by[i], density_or_zero(total[i]), cls + i);
      }
    }
    for (; c < end && stopped == kNone; ++c) stopped = visit(c);
  } else {
    for (; c < end && stopped == kNone; ++c) stopped = visit(c);
  }
  if (kBatched && stopped == kNone) stopped = flush();
  written = n;
  return stopped == kNone ? end : stopped;
}

template <class Sink>
using EmitTile = std::uint32_t (*)(const TileJob&, std::uint32_t, std::uint32_t, Sink, std::size_t,
                                   std::size_t&);

/// The emitter for a mode and kind of density: beside the region (kInside false), inside it, or through
/// a list of ranks (kListed: an edge list, or the points of the cells the region meets).
template <class Sink, bool kInside, bool kListed = false>
EmitTile<Sink> pick_emitter(bool smooth, QueryDensity::Kind kind) {
  using K = QueryDensity::Kind;
  switch (kind) {
    case K::kConstant:
      return smooth ? emit_tile<Sink, true, K::kConstant, kInside, kListed>
                    : emit_tile<Sink, false, K::kConstant, kInside, kListed>;
    case K::kImage:
      return smooth ? emit_tile<Sink, true, K::kImage, kInside, kListed>
                    : emit_tile<Sink, false, K::kImage, kInside, kListed>;
    case K::kCallback:
      break;
  }
  return smooth ? emit_tile<Sink, true, K::kCallback, kInside, kListed>
                : emit_tile<Sink, false, K::kCallback, kInside, kListed>;
}

}  // namespace kdm::detail
