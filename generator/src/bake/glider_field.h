// The paths of the hand-over between depths (bake/handover.h) that can pass near one tile: its own and
// those of every tile that can lie next to it, for finding where a path comes close to another or to a
// point that is about to appear.
//
// Thread safety: a plain value; const functions may be called concurrently.
#pragma once

#include <cstdint>
#include <vector>

#include "kdm/runtime/tileset_format.h"

namespace kdm::gen {

/// A straight glide from (ax, ay) to (bx, by) (tile units) that has moved min(1, (count − top) /
/// (end − top)) of the way at a count per tile past the top level's N_top (the runtime's rule).
struct Glide {
  double ax = 0, ay = 0, bx = 0, by = 0;
  double end = 0;  ///< the count per tile where it arrives (TilesetShape::handover_end of its length)
};

class GliderField {
 public:
  /// Tile t's glides (`glides[t]`, by rank) and, shifted into t's units, those of every tile u that can
  /// lie next to t (its corners agreeing with t's on the vertices between them) whose paths come within
  /// `distance` (tile units) of t. `top` is N_top.
  GliderField(const TilesetData& set, const std::vector<std::vector<Glide>>& glides, std::size_t t,
              double distance, double top);

  /// Whether `g` comes closer than the field's distance to one of its glides at some count, leaving out
  /// tile t's ranks `skip_a` and `skip_b`. Once both have arrived they are not compared (the ends are
  /// the subtiles' own points).
  bool meets(const Glide& g, std::uint32_t skip_a, std::uint32_t skip_b) const;
  /// Whether two glides come closer than the field's distance to each other before both arrive.
  bool meet(const Glide& a, const Glide& b) const { return approach(a, b) < distance_; }
  /// The least distance between two glides before both arrive (tile units).
  double approach(const Glide& a, const Glide& b) const;
  /// The least distance from `g` to any of the field's glides (leaving out tile t's ranks `skip_a` and
  /// `skip_b`) among those that come within the field's distance; the field's distance if none does.
  double nearest(const Glide& g, std::uint32_t skip_a, std::uint32_t skip_b) const;
  /// Replaces tile t's own glide of rank r (its copies shifted as a neighbour of itself are left).
  void replace(std::uint32_t r, const Glide& g);

  /// For each spot (x y pairs, tile units), the count per tile after which no glide comes within
  /// `clearance` of it; a glide that ends that close is left out (the two are then subtile neighbours).
  std::vector<double> clear_counts(const std::vector<double>& spots, double clearance) const;

 private:
  void add(std::uint32_t i);
  void remove(std::uint32_t i);
  template <class Visit>
  void for_cells(const Glide& g, double margin, Visit&& visit) const;
  /// visit(glide) for each glide whose box meets g's but tile t's ranks skip_a and skip_b, until it
  /// returns true.
  template <class Visit>
  void for_glides_near(const Glide& g, std::uint32_t skip_a, std::uint32_t skip_b, Visit&& visit) const;

  double distance_ = 0, top_ = 0, cell_ = 1;
  std::int64_t cells_ = 1;
  std::uint32_t own_ = 0;  ///< glides [0, own_) are tile t's, by rank
  std::vector<Glide> glides_;
  std::vector<std::vector<std::uint32_t>> grid_;  ///< per cell, the glides whose box (± distance) meets it
  mutable std::vector<std::uint32_t> stamp_;      ///< per glide, the query that last saw it
  mutable std::uint32_t query_ = 0;
};

}  // namespace kdm::gen
