// Baking tile sets (docs/design.md §3): aperiodic corner tiles (Lagae & Dutré 2006) holding a nested
// multi-density pyramid, every patch sampled by the full KDM sampler with everything it touches fixed.
//
// Per level k (N_k = base_points·4^k points per tile), with all of levels < k fixed:
//  1. corner patches, one per colour, each from a run on the 1×1 torus of the tile whose corners all have
//     that colour;
//  2. horizontal edge patches, one per ordered colour pair, from runs on 1×1 and 2×1 tori, with the
//     level's corner patches fixed; then vertical ones (1×1 and 1×2 tori) with the horizontal ones fixed
//     too, since the two touch diagonally at the corner patches' corners;
//  3. interiors, one per tile, from runs on the 2×2 torus around the tile, with corners and edges fixed.
// Each run samples the whole torus and keeps only the patches it is for: the rest is context that is
// sampled and dropped, so each patch is drawn from P(patch | what it touches) of the full model.
// The new points of every patch are then ranked by void-and-cluster against the points present by then
// (earlier levels, and the level's earlier patches up to the same fraction of their own ranking), and the
// fraction becomes the point's emission key (kdm/runtime/tileset_format.h): any density between two levels
// emits the same prefix of a shared patch in every tile.
//
// Thread safety: bake_tileset is reentrant; it uses up to `threads` threads of its own.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "kdm/generator/sampler.h"  // InvalidArgument, default_thread_count
#include "kdm/runtime/tileset_format.h"

namespace kdm::gen {

/// The edge gap of the recipes written before the key existed.
inline constexpr double kFirstEdgeGap = 1.25;

/// Everything that determines a baked tile set; `kdm bake` reads it from a small text file of
/// "key value" lines ('#' starts a comment). Baking the same recipe with the same kdm version gives
/// the same bytes, for any thread count. Each key's range, and which keys need which, are listed in
/// docs/design.md §3 ("Ranges, as the parser checks them"); parse() and validate() name the key at fault.
/// Small sets are refused by their patches rather than a count: with the default band, erosion and
/// edge_gap, base_points below 28.
struct BakeRecipe {
  std::uint64_t seed = 1;
  std::uint32_t colours = 2;       ///< corner colours C: C^4 tiles
  std::uint32_t levels = 6;        ///< pyramid levels; level k holds base_points·4^k points per tile
  std::uint32_t base_points = 32;  ///< points of level 0 per tile
  double temperature = 0.5;        ///< user-facing temperature, as in kdm sample
  int sweeps = 100;                ///< MH sweeps per sampler level (constrained sampling needs more than 15)
  double band = 0.35;              ///< half-width of level 0's corner and edge patches, in tile sides
  /// How much each finer level's patches shrink, in that level's point spacings (corner_layout.h).
  double erosion = 1.5;
  /// Each level's gap between its corner and edge half-widths, in its point spacings (corner_layout.h).
  double edge_gap = kFirstEdgeGap;
  /// Hard core: a new point closer than this fraction of its level's hexagonal spacing to a point placed
  /// before it is dropped (spacing_guard.h says why). 0 (off) in recipes that do not name it.
  double min_distance = 0;
  /// After the pyramid is sampled, the later of any two points of a tile closer than this many hexagonal
  /// spacings (at the density where the later one appears) is removed (bake/close_pairs.h says why). 0 (off)
  /// in recipes that do not name it. It visits every pair of tiles that can meet (C^6 for C colours):
  /// seconds for 2 colours, but C² times the tiles' own work, which grows fast from 5 colours up.
  double separation = 0;
  /// With `separation`: move the later point of a close pair away from the earlier ones it is too close
  /// to, in every tile alike, until it is this many hexagonal spacings from each, instead of removing it,
  /// which leaves a hole wherever its patch shows (close_pairs.h, push_close_pairs_apart). 0 (off) in
  /// recipes that do not name it; at least `separation` otherwise.
  double separation_push = 0;
  /// With `separation` or `glide_separation`: a point of a shared patch that is too close to another in
  /// only some of the tiles that show it becomes per-tile copies, left out (along the glide track: shown
  /// later) only where it is too close, instead of being moved or removed in every tile
  /// (close_pairs.h, split_crowded_points). Off (false) in recipes that do not name it.
  bool split_shared = false;
  /// With `separation_push`: a crowded point moves into the deepest empty place within 1.5 spacings of it
  /// where no point is nearer than `separation_push` spacings, and is pushed only if there is none
  /// (close_pairs.h, push_close_pairs_apart). Off (false) in recipes that do not name it.
  bool separation_fill = false;
  /// With `separation_push`: part each level's close pairs as soon as the level is sampled, so that the
  /// finer levels are sampled around where the moved points end up; otherwise the pass runs once over the
  /// finished pyramid, and a point moved below the top level leaves its place empty at the levels above
  /// (its partner, within `separation` spacings of its own level, is too far to cover it in theirs). Off
  /// (false) in recipes that do not name it.
  bool separation_per_level = false;
  /// After each run is sampled, every empty circle wider than this many hexagonal spacings whose centre
  /// lies in a patch the run keeps gets a new point there, deepest first (bake/hole_finder.h says why). 0
  /// (off) in recipes that do not name it.
  double fill_holes = 0;
  /// How a patch's points are ranked against the run's other new points, stand-ins for the regions ranked
  /// apart (bake.cpp says why): 0 (recipes without the key) not at all; 1 ranked together with them; 2
  /// present in proportion, each weighing the fraction of the patch already ranked.
  int rank_context = 0;
  /// After the glide track is relaxed, the later of any two points closer than this many hexagonal
  /// spacings at some density along it is removed (close_pairs.h, drop_close_glides). 0 (off) in recipes
  /// that do not name it.
  double glide_separation = 0;
  /// Glide track (keyframes.h): keyframes per level (0 = none, the set then only serves stable queries),
  /// and the descent sweeps that relax each keyframe.
  std::uint32_t keyframes_per_level = 0;  ///< recipe key `keyframes`
  int glide_sweeps = 10;
  /// Keyframes of up to this many points per tile move each shared patch by the mean of its moves on every
  /// torus of the bake that holds it, not on its own run's alone (keyframes.h says why). 0 (off) in recipes
  /// that do not name it.
  std::uint32_t glide_consensus = 0;
  /// Keyframes above glide_consensus and up to this many points per tile move their corner patches by
  /// consensus, and their edges and interiors on their own runs: most of consensus's effect on holes for
  /// about a third of its cost (docs/design.md §3). 0 (off) in recipes that do not name it.
  std::uint32_t glide_corner_consensus = 0;
  /// A point new at a keyframe and shown later than this fraction of the way there is left out of that
  /// keyframe's relaxation: the points around it make its room over the next interval, once it is shown,
  /// instead of leaving an empty place for it before (keyframes.h). 0 (off) in recipes that do not name it.
  double glide_late = 0;
  /// The hand-over between depths (bake/handover.h): the half-width, in subtile sides, of the corner
  /// squares and edge bands whose sub-vertices take their colours from that corner or edge alone, with
  /// 2 · zone + 1 below the subtiles per side (an error names the range). 0 (off, recipes that do not
  /// name it): the set ends at its top level. Needs a glide track.
  std::uint32_t handover_zone = 0;
  /// The subtiles' level j the hand-over glides onto: m = √(N_top / N_j) subtiles per side, and a depth's
  /// subtiles never show fewer points than their first keyframe above N_j (levels 0..j are not shown past
  /// depth 0). 0 in recipes that do not name it. Needs handover_zone.
  std::uint32_t handover_level = 0;
  /// Keyframes past the subtiles' first above N_j at which they are handed over (0 to 16; 0 in recipes that
  /// do not name it): with 2 they hold a fifth more points than the tile, every glide but the longest has
  /// arrived before their own points enter, and the leftovers appear farthest from the points present.
  /// Needs handover_zone, and keyframes enough above N_j (an error names the most).
  std::uint32_t handover_slack = 0;

  /// Parses recipe text (lines end at LF, CR LF or CR). Throws InvalidArgument naming the line and problem
  /// (a line that is not one 'key value' pair and why, unknown key, bad value, out-of-range count, a key
  /// given without the key it tunes, patches that erode away), or the bytes of a tile-set file.
  static BakeRecipe parse(const std::string& text);
  /// Throws InvalidArgument, with parse's message less the line, for a recipe parse would refuse: a value
  /// out of its range, or keys that do not fit together (a key that tunes another counts as given when it
  /// is not at its default). bake_tileset calls it first.
  void validate() const;
  /// Whether `text` gives any key (a line with more than blanks and a comment). `kdm bake` and kdm.bake
  /// refuse a recipe that gives none: it is most likely the wrong file, and the defaults bake for minutes.
  static bool gives_any_key(const std::string& text);
  /// Whether `text` looks like a recipe: its first line that gives something is a known key and a value
  /// (`kdm info` and `kdm verify` say so when given one instead of a tile set).
  static bool looks_like_recipe(const std::string& text);
  /// The canonical text form (parse(to_text()) == *this), which a baked set stores: the keys that make
  /// every set (seed to erosion) and the others only where they differ from their defaults.
  std::string to_text() const;
  /// MH sweeps for a level holding `level_points` points in all: `sweeps`, times 4096 / level_points
  /// (at most 64×) for small levels. They are cheap, and every finer level is built on them, so they get
  /// closer to equilibrium. The generator test draws its reference runs with the same schedule.
  int sweeps_for(std::uint64_t level_points) const;
  /// N for the top level: base_points · 4^(levels − 1) points per tile.
  std::uint64_t top_level_points() const { return std::uint64_t(base_points) << (2 * (levels - 1)); }
  /// N_k for every level: the tile set's level_nominal.
  std::vector<std::uint32_t> nominal_counts() const;
};

/// What the passes that keep points apart did (recipe keys separation, separation_push, split_shared and
/// glide_separation), in points.
struct BakeReport {
  std::size_t moved = 0, split = 0, removed = 0;   ///< after the pyramid is sampled
  std::size_t glide_split = 0, glide_removed = 0;  ///< after the glide track is relaxed
};

/// Bakes `recipe` on `threads` worker threads (0: default_thread_count()); the file is the same for any
/// count. `progress` (optional) receives the fraction done; `report` (optional) what the separation passes
/// did. Throws InvalidArgument, before any work, for a recipe BakeRecipe::validate refuses, and while
/// baking for one that passes but leaves a patch no points (a context that holds them all).
TilesetData bake_tileset(const BakeRecipe& recipe, int threads = 0,
                         const std::function<void(double)>& progress = {}, BakeReport* report = nullptr);

/// The 2×2 torus of tiles around tile `index` of a set with `colours` corner colours, on which the baker
/// samples that tile's interior and the generator test judges it: the index of the tile at (tx, ty),
/// tx, ty in {0, 1}, with (0, 0) the tile itself. Its vertices carry the tile's four corner colours.
std::size_t tile_around(std::uint32_t colours, std::size_t index, int tx, int ty);

}  // namespace kdm::gen
