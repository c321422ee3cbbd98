// Near-coincident points of different runs, and (drop_close_glides) of paths along the glide track that
// the keyframes' relaxation could not keep apart. Each patch is sampled with what its run holds fixed, but a
// run never sees every patch a tile puts next to it (a vertical edge's run sees its torus's horizontal
// edges, not those of every tile), so two points of different patches can land almost on top of each
// other: the shipped set without this pass showed 180 pairs closer than 0.3 hexagonal spacings in
// 295,000 points at its top density, all within one tile, mostly new points of the top level.
//
// Thread safety: pure function of its arguments.
#pragma once

#include <cstdint>
#include <map>
#include <set>
#include <tuple>
#include <vector>

#include "corner_layout.h"
#include "kdm/runtime/tileset_format.h"

namespace kdm::gen {

/// One point of a patch: (level, kind, patch index, index in the patch).
using PointKey = std::tuple<std::size_t, int, std::size_t, std::uint32_t>;
/// Points too close to another in some tiles: per point, per tile index, the density (points per tile)
/// from which it may be shown there (infinity: at none).
using Crowded = std::map<PointKey, std::map<std::size_t, double>>;

/// Removes from `levels` the point that appears later (higher emission threshold, by `shape`'s
/// level_nominal) of every pair closer, in some tile of `colours`^4, than `separation` times the hexagonal
/// spacing at that point's threshold, or at the first level's count if higher (the set's range starts
/// there): from there on both are present, and at higher densities the pair is farther apart in spacings. The
/// choice depends on the two points alone, so a shared patch loses the same points in every tile. Call before
/// the glide track is relaxed (patches without frames). Returns how many points were removed.
std::size_t drop_close_pairs(std::vector<LevelPatches>& levels, std::uint32_t colours,
                             const TilesetShape& shape, double separation);

/// What push_close_pairs_apart did: points moved, and points it removed instead.
struct SeparationResult {
  std::size_t moved = 0, removed = 0;
  std::size_t split = 0;  ///< points made per-tile copies instead (split_crowded_points)
};

/// Like drop_close_pairs, but the later point of a close pair moves, by the least that takes it `push`
/// (≥ separation) hexagonal spacings from every earlier point it was too close to in any tile, instead of
/// going: a point removed leaves a hole in every tile that shows its patch, and most tiles never met the
/// point it was close to. The move depends on the pairs alone, so a shared patch moves the same way in
/// every tile. Repeats while moves make new pairs, at most kPushRounds times; what is still too close
/// then is removed. With `split`, points of shared patches that some tile can keep are first split
/// (split_crowded_points: dropped only in the tiles where they are too close) and the rest pushed. With
/// `fill`, a crowded point moves instead into the deepest empty place within kFillReach spacings of it
/// (among every point near it in any tile that shows it, each pair judged in the spacing of the density
/// where both are shown), if that place is at least `push` spacings wide: a close pair is one point too
/// many here, and usually one too few nearby. Pushed, it leaves part of its place empty.
SeparationResult push_close_pairs_apart(std::vector<LevelPatches>& levels, std::uint32_t colours,
                                        const TilesetShape& shape, double separation, double push,
                                        bool split = false, bool fill = false);
inline constexpr int kPushRounds = 8;
inline constexpr double kFillReach = 1.5;  ///< how far `fill` looks for an empty place, in spacings

/// The same along the glide track, once it is relaxed: removes the later point of every pair closer than
/// `separation` hexagonal spacings (plus kGlideMargin, for the file's 8-bit offsets) at some density where
/// both are shown, in some tile or across an edge two tiles can share. Densities are sampled at the
/// keyframes and at 7 more between each two (the half-way density among them). Paths are pushed apart
/// while keyframes are relaxed (keyframes.h); this catches the few that bounds keep from moving. With
/// `split`, a point some tile can keep is split instead (split_crowded_points: in the tiles where it
/// comes close it is shown only from the next density sampled after the last close one, if its level
/// reaches it). Returns how many points were removed and split.
SeparationResult drop_close_glides(std::vector<LevelPatches>& levels, std::uint32_t colours,
                                   const TilesetShape& shape, double separation, bool split = false);

/// A point of a shared patch is shown by every tile that holds the patch, but is too close to another
/// point only in the tiles that also hold that one; removed or moved, it leaves a hole in all the others.
/// So each point of `crowded` that some tile can keep becomes per-tile copies, points of those tiles'
/// interiors at the same level (same position, key and frames): unchanged where the point is not crowded,
/// and where it is, shown only from the density `crowded` gives (its key raised, if its level reaches that
/// density; else no copy there). A crowded interior point, shown by one tile, is thus shown later or not at
/// all. Appends the copies and returns the points split; the caller removes the originals (remove_points)
/// with any others, so that the keys of `crowded` stay valid until then.
std::set<PointKey> split_crowded_points(std::vector<LevelPatches>& levels, std::uint32_t colours,
                                        const TilesetShape& shape, const Crowded& crowded);

/// Removes `points` from their patches, with their frames.
void remove_points(std::vector<LevelPatches>& levels, const std::set<PointKey>& points);

/// kGlideMargin: offsets are rounded to 1/64 of a keyframe's spacing per axis, which moves a pair's
/// distance by at most 0.04 hexagonal spacings.
inline constexpr double kGlideMargin = 0.04;

}  // namespace kdm::gen
