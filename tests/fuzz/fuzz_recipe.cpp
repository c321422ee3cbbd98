// Fuzz target: BakeRecipe::parse (the text of a `kdm bake` recipe) on arbitrary bytes. Checks: it either
// throws InvalidArgument with a message (any other exception escapes and is reported as a crash) or
// returns a recipe whose every field lies in its documented range (at most 2^22 points per tile), that
// BakeRecipe::validate accepts, whose canonical text parses back to the same recipe, and whose level counts
// agree with it.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "kdm/generator/bake.h"
#include "kdm/generator/sampler.h"

namespace {

[[noreturn]] void fail() {
  std::abort();
}

bool same(const kdm::gen::BakeRecipe& a, const kdm::gen::BakeRecipe& b) {
  return a.seed == b.seed && a.colours == b.colours && a.levels == b.levels &&
         a.base_points == b.base_points && a.temperature == b.temperature && a.sweeps == b.sweeps &&
         a.band == b.band && a.erosion == b.erosion && a.edge_gap == b.edge_gap &&
         a.min_distance == b.min_distance && a.rank_context == b.rank_context &&
         a.separation == b.separation && a.separation_push == b.separation_push &&
         a.fill_holes == b.fill_holes && a.keyframes_per_level == b.keyframes_per_level &&
         a.glide_separation == b.glide_separation && a.glide_consensus == b.glide_consensus &&
         a.glide_late == b.glide_late && a.glide_corner_consensus == b.glide_corner_consensus &&
         a.handover_zone == b.handover_zone && a.handover_level == b.handover_level &&
         (a.keyframes_per_level == 0 || a.glide_sweeps == b.glide_sweeps);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using kdm::gen::BakeRecipe;
  BakeRecipe r;
  try {
    r = BakeRecipe::parse(std::string(reinterpret_cast<const char*>(data), size));
  } catch (const kdm::gen::InvalidArgument& e) {
    if (!*e.what()) fail();
    return 0;
  }
  if (r.colours < 1 || r.colours > kdm::kMaxTileColours || r.levels < 1 || r.levels > 10 ||
      r.base_points < 1 || r.base_points > (1u << 16) || r.sweeps < 1 || r.sweeps > 10000)
    fail();
  if (!(r.band > 0 && r.band < 0.5) || !(r.erosion >= 0 && r.erosion <= 8) ||
      !(r.min_distance >= 0 && r.min_distance <= 0.7) || !(r.separation >= 0 && r.separation <= 0.7) ||
      !(r.edge_gap >= 0.5 && r.edge_gap <= 4) || !(r.temperature >= 0 && r.temperature <= 1000) ||
      !(r.fill_holes == 0 || (r.fill_holes >= 0.5 && r.fill_holes <= 2)) ||
      (r.separation_push > 0 && !(r.separation > 0 && r.separation_push >= r.separation)) ||
      (r.keyframes_per_level == 0 && (r.glide_late > 0 || r.glide_consensus || r.glide_separation > 0)))
    fail();
  try {
    r.validate();  // what bake_tileset checks: the text's rules, on the fields
  } catch (const kdm::gen::InvalidArgument&) {
    fail();
  }
  if (r.top_level_points() > (1u << 22)) fail();
  const auto counts = r.nominal_counts();
  if (counts.size() != r.levels || counts.back() != r.top_level_points()) fail();
  if (r.sweeps_for(1) < r.sweeps || r.sweeps_for(r.top_level_points()) < r.sweeps) fail();
  const std::string text = r.to_text();
  BakeRecipe back;
  try {
    back = BakeRecipe::parse(text);
  } catch (const kdm::gen::InvalidArgument&) {
    fail();  // the canonical text of an accepted recipe is accepted
  }
  if (!same(back, r) || back.to_text() != text) fail();
  return 0;
}
