// Baking: recipes, determinism, nesting, and the shipped default set rebuilt bit for bit from its recipe.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <initializer_list>
#include <iterator>

#include "bake/close_pairs.h"
#include "bake/hole_finder.h"
#include "bake/progressive_order.h"
#include "bake/spacing_guard.h"
#include "kdm/analysis/empty_circles.h"
#include "kdm/generator/bake.h"
#include "kdm/generator/sampler.h"
#include "kdm/runtime/query.h"
#include "kdm/runtime/tileset.h"

namespace kdm::gen {
namespace {

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::vector<std::uint8_t> encoded(const TilesetData& set) {
  std::vector<std::uint8_t> bytes;
  EXPECT_EQ(encode_tileset(set, bytes), Status::kOk);
  return bytes;
}

/// parse's refusal of `text`, or "" when it parses.
std::string refusal(const std::string& text) {
  try {
    BakeRecipe::parse(text);
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "";
}

// A key that only tunes another key's pass is refused without it (alone it would do nothing, silently);
// numbers are decimal, a seed is read exactly, and an invisible byte is shown.
TEST(BakeTest, RecipeRefusesKeysThatWouldDoNothingAndOddNumbers) {
  for (const char* text : {"separation_push 0.55\n", "separation 0.3\nseparation_fill 1\n",
                           "separation 0.3\nseparation_per_level 1\n", "split_shared 1\n", "glide_sweeps 5\n",
                           "glide_separation 0.3\n", "glide_consensus 8192\n",
                           "glide_corner_consensus 8192\n", "glide_late 0.5\n"})
    EXPECT_NE(refusal(text).find(" needs "), std::string::npos) << text << ": " << refusal(text);
  EXPECT_NE(refusal("separation 0.5\nseparation_push 0.3\n").find("at least separation 0.5"),
            std::string::npos);
  EXPECT_EQ(refusal("keyframes 2\nglide_sweeps 5\nglide_separation 0.3\nsplit_shared 1\n"), "");
  EXPECT_EQ(BakeRecipe::parse("seed 9007199254740993\n").seed, 9007199254740993u);  // past a double's
  EXPECT_EQ(BakeRecipe::parse("seed 18446744073709551615\n").seed, 18446744073709551615u);
  EXPECT_NE(refusal("seed 18446744073709551616\n").find("seed must be a whole number"), std::string::npos);
  EXPECT_NE(refusal("seed 0x10\n").find("seed must be a whole number"), std::string::npos);
  EXPECT_NE(refusal("levels 0x3\n").find("is not a number"), std::string::npos);
  EXPECT_NE(refusal("band inf\n").find("is not a number"), std::string::npos);
  EXPECT_NE(refusal("band 1e400\n").find("out of range"), std::string::npos);
  EXPECT_NE(refusal(std::string("colours 1\0junk\n", 15)).find("'1\\x00junk' is not a number"),
            std::string::npos)
      << refusal(std::string("colours 1\0junk\n", 15));
  EXPECT_EQ(BakeRecipe::parse("\xEF\xBB\xBFlevels 3\n").levels, 3u);  // a byte order mark is skipped
  EXPECT_NE(refusal("lev\x01"
                    "els 3\n")
                .find("unknown key 'lev\\x01els'"),
            std::string::npos);
  EXPECT_NE(refusal("temperature 2000\n").find("temperature must be in [0, 1000], got '2000'"),
            std::string::npos)
      << refusal("temperature 2000\n");
  EXPECT_NE(refusal("levels -2\n").find("levels must be a whole number in [1, 10], got '-2'"),
            std::string::npos)
      << refusal("levels -2\n");
  EXPECT_EQ(BakeRecipe::parse("fill_holes 0\n").fill_holes, 0.0);  // off, said explicitly
  EXPECT_NE(refusal("levels 1\nkeyframes 8\n").find("keyframes need 2 or more levels"), std::string::npos)
      << refusal("levels 1\nkeyframes 8\n");
  EXPECT_EQ(refusal("levels 2\nkeyframes 8\n"), "");
  // A hand-over whose subtiles hand over more points than the format's hand-over entries address is
  // refused here, not after the bake.
  EXPECT_NE(refusal("levels 3\ncolours 1\nbase_points 700\nkeyframes 1\nhandover_zone 1\n")
                .find("more than a tile set's hand-over addresses (2621)"),
            std::string::npos)
      << refusal("levels 3\ncolours 1\nbase_points 700\nkeyframes 1\nhandover_zone 1\n");
}

TEST(BakeTest, RecipeRoundTripAndErrors) {
  const BakeRecipe r = BakeRecipe::parse(
      "# comment\nseed 7\nlevels 3 # trailing\nbase_points 32\ntemperature 0.25\ncolours 3\nband 0.34\n"
      "erosion 1\n");
  EXPECT_EQ(r.seed, 7u);
  EXPECT_EQ(r.levels, 3u);
  EXPECT_EQ(r.base_points, 32u);
  EXPECT_EQ(r.colours, 3u);
  EXPECT_DOUBLE_EQ(r.temperature, 0.25);
  EXPECT_DOUBLE_EQ(r.band, 0.34);
  EXPECT_DOUBLE_EQ(r.erosion, 1.0);
  EXPECT_EQ(BakeRecipe::parse(r.to_text()).to_text(), r.to_text());
  EXPECT_EQ(r.min_distance, 0.0);  // off unless named, and then not written
  EXPECT_EQ(r.to_text().find("min_distance"), std::string::npos);
  const BakeRecipe guarded = BakeRecipe::parse("min_distance 0.35\n");
  EXPECT_DOUBLE_EQ(guarded.min_distance, 0.35);
  EXPECT_DOUBLE_EQ(BakeRecipe::parse(guarded.to_text()).min_distance, 0.35);
  EXPECT_THROW(BakeRecipe::parse("min_distance 0.8\n"), InvalidArgument);
  EXPECT_THROW(bake_tileset(r, -1), InvalidArgument);  // before any work: 0 or 1 to kMaxThreads
  EXPECT_THROW(bake_tileset(r, kMaxThreads + 1), InvalidArgument);
  try {  // a key given twice: which value was meant is not known
    BakeRecipe::parse("levels 3\ncolours 2\nlevels 4\n");
    ADD_FAILURE() << "a repeated key was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("line 3: levels was already given on line 1"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(r.separation, 0.0);  // off unless named, and then not written
  EXPECT_EQ(r.to_text().find("separation"), std::string::npos);
  EXPECT_DOUBLE_EQ(BakeRecipe::parse(BakeRecipe::parse("separation 0.3\n").to_text()).separation, 0.3);
  EXPECT_THROW(BakeRecipe::parse("separation -0.1\n"), InvalidArgument);
  EXPECT_EQ(r.to_text().find("fill_holes"), std::string::npos);  // off unless named
  EXPECT_DOUBLE_EQ(BakeRecipe::parse(BakeRecipe::parse("fill_holes 0.8\n").to_text()).fill_holes, 0.8);
  EXPECT_THROW(BakeRecipe::parse("fill_holes 0.3\n"), InvalidArgument);
  // In range, but so low on a one-level set that it fills the corners' ordinary gaps until the interior
  // has no points left to draw: the refusal names the key.
  try {
    bake_tileset(BakeRecipe::parse("levels 1\ncolours 1\nsweeps 2\nfill_holes 0.5\n"), 1);
    ADD_FAILURE() << "baked";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("fill_holes 0.5"), std::string::npos) << e.what();
  }
  EXPECT_EQ(r.to_text().find("glide_consensus"), std::string::npos);  // off unless named
  EXPECT_EQ(
      BakeRecipe::parse(BakeRecipe::parse("keyframes 2\nglide_consensus 2048\n").to_text()).glide_consensus,
      2048u);
  EXPECT_THROW(BakeRecipe::parse("glide_consensus 0.5\n"), InvalidArgument);
  EXPECT_EQ(r.to_text().find("glide_corner_consensus"), std::string::npos);  // off unless named
  EXPECT_EQ(BakeRecipe::parse(BakeRecipe::parse("keyframes 2\nglide_corner_consensus 32768\n").to_text())
                .glide_corner_consensus,
            32768u);
  EXPECT_THROW(BakeRecipe::parse("glide_corner_consensus -1\n"), InvalidArgument);
  EXPECT_EQ(r.to_text().find("glide_late"), std::string::npos);  // off unless named
  EXPECT_DOUBLE_EQ(
      BakeRecipe::parse(BakeRecipe::parse("keyframes 2\nglide_late 0.75\n").to_text()).glide_late, 0.75);
  EXPECT_THROW(BakeRecipe::parse("keyframes 2\nglide_late 1\n"), InvalidArgument);
  EXPECT_THROW(BakeRecipe::parse("keyframes 2\nglide_late -0.1\n"), InvalidArgument);
  EXPECT_EQ(r.to_text().find("split_shared"), std::string::npos);  // off unless named
  EXPECT_TRUE(
      BakeRecipe::parse(BakeRecipe::parse("separation 0.3\nsplit_shared 1\n").to_text()).split_shared);
  EXPECT_THROW(BakeRecipe::parse("separation 0.3\nsplit_shared 2\n"), InvalidArgument);
  for (const char* key : {"separation_fill", "separation_per_level"}) {
    EXPECT_EQ(r.to_text().find(key), std::string::npos) << key;  // off unless named
    const std::string push = "separation 0.3\nseparation_push 0.5\n";
    const BakeRecipe on = BakeRecipe::parse(BakeRecipe::parse(push + key + " 1\n").to_text());
    EXPECT_TRUE(std::string(key) == "separation_fill" ? on.separation_fill : on.separation_per_level) << key;
    EXPECT_THROW(BakeRecipe::parse(push + key + " 2\n"), InvalidArgument) << key;
  }
  EXPECT_EQ(r.edge_gap, kFirstEdgeGap);
  EXPECT_EQ(r.rank_context, 0);
  const BakeRecipe later = BakeRecipe::parse("edge_gap 1\nrank_context 1\nerosion 2\nband 0.36\n");
  EXPECT_EQ(BakeRecipe::parse(later.to_text()).to_text(), later.to_text());
  EXPECT_DOUBLE_EQ(BakeRecipe::parse(later.to_text()).edge_gap, 1.0);
  EXPECT_EQ(BakeRecipe::parse(later.to_text()).rank_context, 1);
  EXPECT_EQ(BakeRecipe::parse(BakeRecipe::parse("rank_context 2\n").to_text()).rank_context, 2);
  EXPECT_THROW(BakeRecipe::parse("edge_gap 0.2\n"), InvalidArgument);
  EXPECT_THROW(BakeRecipe::parse("rank_context 3\n"), InvalidArgument);
  try {  // patches too narrow for a sparse coarsest level: the message names base_points, the usual cause
    BakeRecipe::parse("colours 2\nlevels 2\nbase_points 24\n");
    ADD_FAILURE() << "base_points 24 was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("base_points 24"), std::string::npos) << e.what();
  }
  EXPECT_THROW(BakeRecipe::parse("levels three\n"), InvalidArgument);
  EXPECT_THROW(BakeRecipe::parse("colour 1\n"), InvalidArgument);    // unknown key
  EXPECT_THROW(BakeRecipe::parse("levels 0\n"), InvalidArgument);    // out of range
  EXPECT_THROW(BakeRecipe::parse("colours 17\n"), InvalidArgument);  // beyond the format's cap
  EXPECT_THROW(BakeRecipe::parse("levels 2 3\n"), InvalidArgument);  // extra field
  EXPECT_THROW(BakeRecipe::parse("temperature -1\n"), InvalidArgument);
  EXPECT_THROW(BakeRecipe::parse("band 0.5\n"), InvalidArgument);  // corner patches would overlap
  EXPECT_THROW(BakeRecipe::parse("base_points 65536\nlevels 10\n"), InvalidArgument);  // too many points
  // Erosion that eats the patches of the finer levels away.
  EXPECT_THROW(BakeRecipe::parse("base_points 4\nlevels 6\nband 0.3\nerosion 3\n"), InvalidArgument);
}

BakeRecipe small_recipe() {
  BakeRecipe r;
  r.colours = 2;
  r.levels = 2;
  r.base_points = 32;
  r.sweeps = 10;
  return r;
}

// A recipe made in code is held to the text's rules before any work, with parse's messages less the line:
// values out of range, and a key that tunes another given (here: off its default) without it.
TEST(BakeTest, ARecipeMadeInCodeIsCheckedAsItsTextWouldBe) {
  const auto validation = [](const BakeRecipe& r) -> std::string {
    try {
      r.validate();
    } catch (const InvalidArgument& e) {
      return e.what();
    }
    return "";
  };
  struct Case {
    const char* text;  // the same recipe as text
    void (*edit)(BakeRecipe&);
    const char* message;
  };
  const Case cases[] = {
      {"levels 12\n", [](BakeRecipe& r) { r.levels = 12; },
       "levels must be a whole number in [1, 10], got '12'"},
      {"colours 17\n", [](BakeRecipe& r) { r.colours = 17; },
       "colours must be a whole number in [1, 16], got '17'"},
      {"colours 0\n", [](BakeRecipe& r) { r.colours = 0; },
       "colours must be a whole number in [1, 16], got '0'"},
      {"sweeps 0\n", [](BakeRecipe& r) { r.sweeps = 0; },
       "sweeps must be a whole number in [1, 10000], got '0'"},
      {"band 0.5\n", [](BakeRecipe& r) { r.band = 0.5; }, "band must be in (0, 0.5), got '0.5'"},
      {"separation_push 0.5\n", [](BakeRecipe& r) { r.separation_push = 0.5; },
       "separation_push needs separation"},
      {"glide_sweeps 30\n", [](BakeRecipe& r) { r.glide_sweeps = 30; },
       "glide_sweeps needs a glide track (keyframes)"},
      {"handover_slack 2\n", [](BakeRecipe& r) { r.handover_slack = 2; },
       "handover_slack needs handover_zone (a hand-over)"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    BakeRecipe r = small_recipe();
    c.edit(r);
    EXPECT_EQ(validation(r), std::string("recipe: ") + c.message);
    EXPECT_EQ(refusal(c.text), std::string("recipe line 1: ") + c.message);
    EXPECT_THROW(bake_tileset(r, 1), InvalidArgument);  // at once: levels 12 would bake for minutes
  }
  BakeRecipe nan = small_recipe();
  nan.temperature = std::nan("");
  EXPECT_EQ(validation(nan), "recipe: temperature must be in [0, 1000], got 'nan'");
  // What parse accepts, validate accepts: the shipped recipe, and keys given at their defaults.
  EXPECT_EQ(
      validation(BakeRecipe::parse(read_file(std::string(KDM_SOURCE_DIR) + "/tilesets/default.recipe"))), "");
  EXPECT_EQ(validation(BakeRecipe::parse("keyframes 2\nglide_sweeps 10\nseparation 0.3\nsplit_shared 0\n")),
            "");
  EXPECT_EQ(validation(small_recipe()), "");
}

// A hand-over whose subtiles hold fewer points than their parent's top level is refused with the counts
// as points (once it printed the x, y arrays' lengths, twice as many) and the remedy; the remedy bakes.
TEST(BakeTest, AHandOverShortOfPointsIsRefusedWithItsCounts) {
  const std::string text =
      "seed 3\ncolours 1\nlevels 3\nbase_points 32\nsweeps 10\nseparation 0.3\nseparation_push 0.55\n"
      "split_shared 1\nkeyframes 24\nglide_sweeps 3\nhandover_zone 1\n";
  std::string said;
  try {
    bake_tileset(BakeRecipe::parse(text), 1);
  } catch (const InvalidArgument& e) {
    said = e.what();
  }
  int tile = -1, top = 0, subtiles = 0, held = 0;
  ASSERT_EQ(std::sscanf(said.c_str(),
                        "hand-over: tile %d holds %d points at its top level, its %d subtiles only %d", &tile,
                        &top, &subtiles, &held),
            4)
      << said;
  EXPECT_EQ(subtiles, 16);
  EXPECT_GT(top, held);
  EXPECT_NEAR(top, 512, 16) << said;  // the top level: 512 nominal, 517 in this tile
  EXPECT_LE(held, 16 * 34) << said;   // 16 subtiles at the hand-over keyframe's nominal 34 points at most
  EXPECT_NE(said.find("a larger handover_slack (now 0)"), std::string::npos) << said;
  EXPECT_NO_THROW(bake_tileset(BakeRecipe::parse(text + "handover_slack 1\n"), 1));
}

// A refusal of keys that do not fit together names the line of the key at fault, and a key that tunes
// another is refused without it even at 0; patches too narrow name their level and every remedy.
TEST(BakeTest, RecipeRefusalsNameTheLineTheLevelAndTheRemedy) {
  EXPECT_EQ(refusal("levels 2\n# push\nseparation_push 0.5\n"),
            "recipe line 3: separation_push needs separation");
  EXPECT_EQ(refusal("keyframes 2\nlevels 3\nhandover_slack 1\n"),
            "recipe line 3: handover_slack needs handover_zone (a hand-over)");
  EXPECT_EQ(refusal("separation 0.5\nseparation_push 0.3\n"),
            "recipe line 2: separation_push 0.3 must be at least separation 0.5");
  // Too many points at the top: both keys' doing, both lines named (only the first was).
  EXPECT_EQ(refusal("levels 6\nbase_points 65536\n"),
            "recipe lines 1 and 2: levels 6 from base_points 65536 make 67108864 points per tile at the top "
            "level, more than 2^22 (4,194,304)");
  EXPECT_EQ(refusal("# big\nbase_points 65536\n").rfind("recipe line 2: levels 6 from base_points", 0), 0u);
  for (const char* text :
       {"handover_level 0\n", "handover_slack 0\n", "split_shared 0\n", "glide_separation 0\n",
        "separation_fill 0\n", "separation 0\nseparation_push 0\n", "keyframes 0\nglide_late 0\n"})
    EXPECT_NE(refusal(text).find(" needs "), std::string::npos) << text << ": " << refusal(text);
  // The stored recipe is normalised: keys at their defaults are left out.
  const std::string stored =
      BakeRecipe::parse("levels 2\nedge_gap 1.25\nseparation 0.3\nsplit_shared 0\n").to_text();
  EXPECT_EQ(stored.find("edge_gap"), std::string::npos) << stored;
  EXPECT_EQ(stored.find("split_shared"), std::string::npos) << stored;
  EXPECT_NE(stored.find("separation 0.3\n"), std::string::npos) << stored;
  EXPECT_EQ(
      refusal("levels 2\nband 0.3\n"),
      "recipe: base_points 32 with band 0.3, erosion 1.5 and edge_gap 1.25 leaves level 0's edge patches "
      "narrower than half a point spacing (more base_points, a larger band, or a smaller erosion or "
      "edge_gap, widens them)");
  EXPECT_NE(refusal("levels 3\nerosion 3\n").find("leaves level 1's edge patches"), std::string::npos)
      << refusal("levels 3\nerosion 3\n");
}

// A line that is not one 'key value' pair says what is wrong with it; lines end at LF, CR LF or CR; the
// bytes of a tile set are named as such, and a recipe is told from other text.
TEST(BakeTest, RecipeLinesSayWhatIsWrongWithThem) {
  EXPECT_EQ(refusal("levels = 2\n"), "recipe line 1: '=' is not used: write 'levels 2'");
  EXPECT_EQ(refusal("colours 1\nlevels=2\n"), "recipe line 2: '=' is not used: write 'levels 2'");
  EXPECT_EQ(refusal("levels 2 3\n"),
            "recipe line 1: 3 words: expected 'key value' (a comment starts with '#')");
  EXPECT_EQ(refusal("levels\n"), "recipe line 1: 'levels' has no value: expected 'key value'");
  EXPECT_EQ(
      refusal("levels\xC2\xA0"
              "2\n"),
      "recipe line 1: a non-ASCII space (bytes C2 A0) is not a blank here: write the line with ASCII spaces");
  EXPECT_NE(refusal("levels 2\xE3\x80\x80# ideographic\n").find("(bytes E3 80 80)"), std::string::npos);
  const BakeRecipe mac = BakeRecipe::parse("levels 2\rcolours 1\r# a comment\rbase_points 64");
  EXPECT_EQ(mac.levels, 2u);
  EXPECT_EQ(mac.colours, 1u);
  EXPECT_EQ(mac.base_points, 64u);
  EXPECT_EQ(refusal("levels 2\rcolours 1\rlevels 3\r"), "recipe line 3: levels was already given on line 1");
  EXPECT_EQ(refusal("levels 2\r\ncolours 1\r\n\r\nlevels 3\r\n"),
            "recipe line 4: levels was already given on line 1");
  EXPECT_TRUE(BakeRecipe::gives_any_key("# only\rlevels 2"));
  EXPECT_FALSE(BakeRecipe::gives_any_key("# only\r\r  # comments\r"));
  EXPECT_NE(refusal(std::string("KDMTILES\x07\0\0\0levels 2\n", 21)).find("this is a kdm tile-set file"),
            std::string::npos);
  EXPECT_TRUE(BakeRecipe::looks_like_recipe("# comment\n\nlevels 2 # two\n"));
  EXPECT_TRUE(
      BakeRecipe::looks_like_recipe(read_file(std::string(KDM_SOURCE_DIR) + "/tilesets/default.recipe")));
  EXPECT_FALSE(BakeRecipe::looks_like_recipe("shopping list\n"));
  EXPECT_FALSE(BakeRecipe::looks_like_recipe("levels\n"));
  EXPECT_FALSE(BakeRecipe::looks_like_recipe(""));
}

TEST(BakeTest, DeterministicNestedCornerTiles) {
  const BakeRecipe r = small_recipe();
  const TilesetData a = bake_tileset(r, 1);
  const TilesetData b = bake_tileset(r, 2);
  EXPECT_EQ(encoded(a), encoded(b));  // same bytes for any thread count
  ASSERT_EQ(a.tiles.size(), 16u);
  EXPECT_EQ(validate_tileset(a), Status::kOk);
  EXPECT_EQ(std::vector<std::uint32_t>(a.level_nominal.begin(), a.level_nominal.end()),
            (std::vector<std::uint32_t>{32, 128}));
  for (const Tile& tile : a.tiles)
    for (std::uint32_t k = 0; k < r.levels;
         ++k)  // each level holds about its nominal count (patch sizes vary)
      EXPECT_NEAR(double(tile.level_end[k]), a.level_nominal[k], 0.1 * a.level_nominal[k]);
  BakeRecipe other = r;
  other.seed = 2;
  EXPECT_NE(bake_tileset(other, 2).tiles[0].points, a.tiles[0].points);
}

// Tiles that share a corner colour hold the same points near that corner (the corner patch), and tiles
// that share an edge's colours hold the same points along it; tiles differ in their interiors.
// Both with the first recipes' settings and with the hard core, its margins, context ranking and separation.
class SharedPatches : public testing::TestWithParam<bool> {};

TEST_P(SharedPatches, TilesShareTheirCornerAndEdgePatches) {
  BakeRecipe r = small_recipe();
  if (GetParam())
    r.erosion = 2, r.edge_gap = 1, r.min_distance = 0.35, r.rank_context = 2, r.separation = 0.3;
  const TilesetData set = bake_tileset(r, 0);
  const std::uint32_t C = set.colours;
  auto points_in = [&](std::size_t t, double x0, double y0, double x1, double y1) {
    std::vector<std::pair<std::uint16_t, std::uint16_t>> out;
    const Tile& tile = set.tiles[t];
    for (std::size_t i = 0; i < tile.level_end[0]; ++i) {
      const double x = tile.points[i].unit_x(), y = tile.points[i].unit_y();
      if (x >= x0 && x < x1 && y >= y0 && y < y1) out.push_back({tile.points[i].x, tile.points[i].y});
    }
    std::sort(out.begin(), out.end());
    return out;
  };
  // Inside level 0's edge patches: base 32 and band 0.35 give corner patches of half-width 0.35 and edge
  // patches of 0.35 − edge_gap / sqrt(32) (corner_layout.h). Interior points, sampled after the bands,
  // may slip into them by thermal motion and stay with their own tile (place_new_point): we have seen one
  // 0.18 spacings deep. Half a spacing (0.088) inside the band only shared points remain.
  const double spacing = 1 / std::sqrt(32.0);
  const double h = 0.35 - r.edge_gap * spacing - 0.5 * spacing;
  std::size_t shared = 0;
  for (std::uint32_t sw = 0; sw < C; ++sw)
    for (std::uint32_t se = 0; se < C; ++se) {
      // All tiles with these two bottom corners share the bottom edge and both bottom corner patches.
      const auto bottom = points_in(set.tile_index(sw, se, 0, 0), 0, 0, 1, h);
      shared += bottom.size();
      for (std::uint32_t ne = 0; ne < C; ++ne)
        for (std::uint32_t nw = 0; nw < C; ++nw)
          EXPECT_EQ(points_in(set.tile_index(sw, se, ne, nw), 0, 0, 1, h), bottom);
    }
  EXPECT_GT(shared, 0u);
  // Interiors are sampled per tile.
  EXPECT_NE(points_in(set.tile_index(0, 0, 0, 0), 0.36, 0.36, 0.64, 0.64),
            points_in(set.tile_index(0, 0, 0, 1), 0.36, 0.36, 0.64, 0.64));
}

INSTANTIATE_TEST_SUITE_P(BakeTest, SharedPatches, testing::Bool());

TEST(BakeTest, ProgressiveOrderFillsLargestHolesFirst) {
  // Fixed: one point. New: a point right next to it and one across the torus. The far one comes first.
  RankingInput in;
  in.fixed = {0.1, 0.1};
  in.candidates = {0.12, 0.1, 0.6, 0.6};
  in.filter_width = 0.1;
  EXPECT_EQ(progressive_order(in), (std::vector<std::uint32_t>{1, 0}));
  // Timed points count only once the ranking reaches their key.
  in.fixed = {0.1, 0.35};
  in.candidates = {0.6, 0.6, 0.1, 0.6};
  EXPECT_EQ(progressive_order(in), (std::vector<std::uint32_t>{0, 1}));  // (0.6, 0.6) is farther from all
  in.timed = {0.6, 0.62};
  in.timed_keys = {0};  // present before the first pick: now (0.1, 0.6) lies in the deeper void
  EXPECT_EQ(progressive_order(in), (std::vector<std::uint32_t>{1, 0}));
  in.timed_keys = {65535};  // never reached
  EXPECT_EQ(progressive_order(in), (std::vector<std::uint32_t>{0, 1}));
  EXPECT_EQ(rank_key(0, 1), 32768u);
  EXPECT_EQ(rank_key(0, 4), 8192u);
}

// A patch that is a thin strip of the torus (4 point spacings, as an edge patch), ranked alone: the rest
// of the torus holds only the coarser level, a void, so the first picks crowd along the strip's borders and
// its middle fills last (a tile edge fills last between levels). With the rest's new points pending
// (present in proportion), the middle gets its share of the picks.
TEST(BakeTest, PendingPointsKeepAPatchFillingEvenly) {
  RankingInput in;
  in.filter_width = 0.05, in.filter_width_end = 0.025;  // half a spacing of the coarser level, of this one
  std::uint64_t state = 7;
  auto jitter = [&]() {  // a fixed-seed LCG: a position within its grid cell
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return double(state >> 11) / double(1ull << 53);
  };
  const int side = 40;  // coarser level: a jittered 20 × 20 grid; new: 40 × 40, rows below 0.1 the strip
  for (int i = 0; i < side / 2; ++i)
    for (int k = 0; k < side / 2; ++k)
      in.fixed.insert(in.fixed.end(), {2 * (k + jitter()) / side, 2 * (i + jitter()) / side});
  for (int i = 0; i < side; ++i)
    for (int k = 0; k < side; ++k) {
      const double x = (k + jitter()) / side, y = (i + jitter()) / side;
      std::vector<double>& to = y < 0.1 ? in.candidates : in.pending;
      to.insert(to.end(), {x, y});
    }
  auto middle_share = [&](const RankingInput& input) {  // of the first half of the picks
    const std::vector<std::uint32_t> order = progressive_order(input);
    std::size_t middle = 0;
    for (std::size_t s = 0; s < order.size() / 2; ++s) {
      const double y = input.candidates[2 * order[s] + 1];
      middle += y >= 0.025 && y < 0.075;  // the strip's middle half
    }
    return double(middle) / double(order.size() / 2);
  };
  const double with_pending = middle_share(in);
  in.pending.clear();
  const double alone = middle_share(in);
  // Measured with LCG seeds 7–10: alone 0.13–0.21, with pending 0.45–0.53 (even: 0.5).
  EXPECT_LT(alone, 0.3);
  EXPECT_GT(with_pending, 0.38);
}

TEST(BakeTest, SpacingGuardTestsTorusDistances) {
  SpacingGuard guard(2, 1, 0.1, 100);
  EXPECT_TRUE(guard.clear(0.5, 0.5));
  guard.add(0.5, 0.5);
  guard.add(1.98, 0.99);
  EXPECT_FALSE(guard.clear(0.55, 0.58));  // 0.094 away
  EXPECT_TRUE(guard.clear(0.5, 0.61));    // 0.11 away
  EXPECT_FALSE(guard.clear(0.03, 0.02));  // 0.058 away across both wraps
  EXPECT_TRUE(guard.clear(1.0, 0.5));
  SpacingGuard off(1, 1, 0, 10);  // a hard core of 0 lets anything through
  off.add(0.5, 0.5);
  EXPECT_TRUE(off.clear(0.5, 0.5));
}

// The stable points of the world region [0, side)² of unit tiles at `points_per_tile` (out[0..n)).
std::vector<QueryPoint> region_points(const Tileset& set, double points_per_tile, double side,
                                      std::size_t& n) {
  QueryParams q;
  q.x1 = q.y1 = side;
  q.scale = points_per_tile;
  std::vector<QueryPoint> out(std::size_t(side * side * points_per_tile * 1.2) + 64);
  n = 0;
  QueryCursor cursor;
  EXPECT_EQ(query_points(set, q, out.data(), out.size(), &n, &cursor), Status::kOk);
  return out;
}

// The smallest distance between two points of a world region, in hexagonal spacings of its density.
double closest_pair(const Tileset& set, double points_per_tile, double side) {
  std::size_t n = 0;
  std::vector<QueryPoint> out = region_points(set, points_per_tile, side, n);
  // Sort by x and sweep: the closest pair lies within a strip of the best distance so far.
  std::sort(out.begin(), out.begin() + n, [](const QueryPoint& a, const QueryPoint& b) { return a.x < b.x; });
  double best = 1e300;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n && out[j].x - out[i].x < best; ++j)
      best = std::min(best, std::hypot(out[j].x - out[i].x, out[j].y - out[i].y));
  return best / std::sqrt(2 / (std::sqrt(3.0) * points_per_tile));
}

// Bakes `remedied` without its remedy (`plain`, the control, which must show a pair closer than 0.3
// hexagonal spacings at 2048 points per tile, so the test can fail) and with it, where no pair may be that
// close at any of `counts` points per tile.
void expect_remedy_keeps_points_apart(const BakeRecipe& plain, const BakeRecipe& remedied,
                                      std::initializer_list<double> counts) {
  auto load = [](const BakeRecipe& recipe, Tileset& set) {
    const std::vector<std::uint8_t> bytes = encoded(bake_tileset(recipe, 0));
    return Tileset::load_memory(bytes.data(), bytes.size(), set);
  };
  Tileset without, with;
  ASSERT_EQ(load(plain, without), Status::kOk);
  EXPECT_LT(closest_pair(without, 2048, 4), 0.3);
  ASSERT_EQ(load(remedied, with), Status::kOk);
  for (double count : counts) EXPECT_GE(closest_pair(with, count, 4), 0.3) << count << " points per tile";
}

// A recipe whose few sweeps make near-coincident points common (measured with margins of a spacing:
// 107 pairs per 166,000 points at 2048 per tile).
BakeRecipe few_sweeps() {
  BakeRecipe r;
  r.levels = 2, r.base_points = 512, r.sweeps = 20, r.band = 0.2;
  return r;
}

// The hard core (min_distance) with margins of a spacing between levels (erosion − edge_gap = 1): no two
// points closer than 0.3 hexagonal spacings at the complete levels and between them.
TEST(BakeTest, HardCoreKeepsPointsApartAtEveryDensity) {
  BakeRecipe plain = few_sweeps();
  plain.erosion = 2, plain.edge_gap = 1;
  BakeRecipe guarded = plain;
  guarded.min_distance = 0.35;
  expect_remedy_keeps_points_apart(plain, guarded, {512.0, 768.0, 1024.0, 1536.0, 2048.0});
}

// The separation pass on its own (the first recipes' margins, no hard core), likewise.
TEST(BakeTest, SeparationRemovesNearCoincidentPointsAtEveryDensity) {
  BakeRecipe separated = few_sweeps();
  separated.separation = 0.3;
  expect_remedy_keeps_points_apart(few_sweeps(), separated, {300.0, 512.0, 768.0, 1024.0, 1536.0, 2048.0});
}

// Large empty circles (holes, in d_hex) of a query of `side`² tiles at `points_per_tile`, at least one
// d_hex inside the region: a removed point leaves one of about 1.0 d_hex; a well-spread set has none.
std::size_t holes_over(const Tileset& set, double points_per_tile, int side, double radius) {
  std::size_t n = 0;
  const std::vector<QueryPoint> out = region_points(set, points_per_tile, side, n);
  tools::PointSet points;
  points.dim = 2;
  for (std::size_t i = 0; i < n; ++i)
    points.coords.insert(points.coords.end(), {out[i].x / side, out[i].y / side});
  analysis::EmptyCircleOptions o;
  o.torus = false;
  const analysis::EmptyCircles e = analysis::empty_circles({points}, o);
  return radius > 0.9 ? e.over_100 : e.over_085;
}

// Pushed apart instead of removed: the same guarantee (no pair closer than 0.3 d_hex at any density),
// without the removed points' holes; split per tile first (split_shared), a shared point stays where it
// is in every tile but the crowded ones. Over 10 × 10 tiles at the top level (205,000 points), empty
// circles above 1.0 (0.85) d_hex, measured: 16 (157) without the pass, 69 (677) removing, 16 (381)
// pushing, 16 (217) split and pushed: pushing leaves no more than the recipe without the pass plus a
// third of what removing adds above 1.0, and splitting takes at least half of what pushing adds above
// 0.85 (it took 73%).
TEST(BakeTest, SeparationPushKeepsPointsApartWithoutLeavingHoles) {
  BakeRecipe removed = few_sweeps();
  removed.separation = 0.3;
  BakeRecipe pushed = removed;
  pushed.separation_push = 0.55;
  BakeRecipe split = pushed;
  split.split_shared = true;
  BakeRecipe filled = split;
  filled.separation_fill = filled.separation_per_level = true;
  Tileset sets[5];
  const BakeRecipe recipes[5] = {few_sweeps(), removed, pushed, split, filled};
  std::size_t holes[5], holes85[5];
  for (int i = 0; i < 5; ++i) {
    const std::vector<std::uint8_t> bytes = encoded(bake_tileset(recipes[i], 0));
    ASSERT_EQ(Tileset::load_memory(bytes.data(), bytes.size(), sets[i]), Status::kOk);
    holes[i] = holes_over(sets[i], 2048, 10, 1.0), holes85[i] = holes_over(sets[i], 2048, 10, 0.85);
  }
  std::printf(
      "holes above 1.0 (0.85) d_hex at 2048 points per tile: no pass %zu (%zu), removing %zu (%zu), "
      "pushing %zu (%zu), split and pushed %zu (%zu), also filled and per level %zu (%zu)\n",
      holes[0], holes85[0], holes[1], holes85[1], holes[2], holes85[2], holes[3], holes85[3], holes[4],
      holes85[4]);
  EXPECT_LT(closest_pair(sets[0], 2048, 4), 0.3);  // the control: the pass has pairs to part
  for (int i : {2, 3, 4})
    for (double count : {300.0, 512.0, 768.0, 1024.0, 1536.0, 2048.0})
      EXPECT_GE(closest_pair(sets[i], count, 4), 0.3) << count << " points per tile, recipe " << i;
  ASSERT_GE(holes[1], holes[0] + 20);  // removing makes holes: the test could fail
  EXPECT_LE(holes[2], holes[0] + (holes[1] - holes[0]) / 3);
  EXPECT_LE(holes[3], holes[2]);
  ASSERT_GE(holes85[2], holes85[0] + 40);  // pushing leaves holes above 0.85 for splitting to save
  EXPECT_LE(holes85[3], holes85[0] + (holes85[2] - holes85[0]) / 2);
  EXPECT_LE(holes85[4], holes85[3]);  // here no crowded point finds a place: filling must not make it worse
}

// Filled and parted level by level (separation_fill, separation_per_level), on the shipped recipe's
// pyramid at 5 levels (no glide track): a crowded point of the top level moves into an empty place near it
// instead of being pushed, and one of a lower level moves before the levels above are sampled around it.
// Circles above 0.85 d_hex over 8 × 8 tiles at the top level (524,000 points), measured: 15 without the
// pass, 75 pushed once over the pyramid, 29 filled and per level (36 per level alone, 45 filled alone); the
// bar is a third of what pushing adds. About five minutes: a slow test.
TEST(BakeTest, SeparationFillLeavesFewerHolesThanPushing) {
#ifndef KDM_SLOW_TESTS
  GTEST_SKIP() << "configure with -DKDM_SLOW_TESTS=ON to bake three 5-level pyramids here";
#else
  BakeRecipe plain;
  plain.levels = 5, plain.rank_context = 2, plain.fill_holes = 0.8;
  BakeRecipe pushed = plain;
  pushed.separation = 0.3, pushed.separation_push = 0.55, pushed.split_shared = true;
  BakeRecipe filled = pushed;
  filled.separation_fill = filled.separation_per_level = true;
  const BakeRecipe recipes[3] = {plain, pushed, filled};
  std::size_t holes[3];
  Tileset sets[3];
  for (int i = 0; i < 3; ++i) {
    const std::vector<std::uint8_t> bytes = encoded(bake_tileset(recipes[i], 0));
    ASSERT_EQ(Tileset::load_memory(bytes.data(), bytes.size(), sets[i]), Status::kOk);
    holes[i] = holes_over(sets[i], 8192, 8, 0.85);
  }
  std::printf("holes above 0.85 d_hex at 8192 points per tile: no pass %zu, pushed %zu, filled %zu\n",
              holes[0], holes[1], holes[2]);
  ASSERT_GE(holes[1], holes[0] + 30);  // pushing adds holes: the test could fail
  EXPECT_LE(holes[2], holes[0] + (holes[1] - holes[0]) / 3);
  for (double count : {2048.0, 3000.0, 4096.0, 6000.0, 8192.0})
    EXPECT_GE(closest_pair(sets[2], count, 4), 0.3) << count;
#endif
}

// Runs that end a point short freeze holes at patch borders; filling them in each run removes most.
// Over 10 × 10 tiles (51,000 and 205,000 points), circles above 0.85 d_hex, measured: 0 and 157 without,
// 0 and 65 filled (what is left lies where a run's torus showed other neighbours than a tile does). One
// seed: the bar, half, leaves room for another draw.
TEST(BakeTest, FillHolesLeavesNoWideEmptyCircles) {
  BakeRecipe filled = few_sweeps();
  filled.fill_holes = 0.8;
  Tileset sets[2];
  const BakeRecipe recipes[2] = {few_sweeps(), filled};
  std::size_t holes[2][2];
  for (int i = 0; i < 2; ++i) {
    const std::vector<std::uint8_t> bytes = encoded(bake_tileset(recipes[i], 0));
    ASSERT_EQ(Tileset::load_memory(bytes.data(), bytes.size(), sets[i]), Status::kOk);
    holes[i][0] = holes_over(sets[i], 512, 10, 0.85), holes[i][1] = holes_over(sets[i], 2048, 10, 0.85);
  }
  std::printf("holes above 0.85 d_hex at 512 and 2048 points per tile: %zu %zu without, %zu %zu filled\n",
              holes[0][0], holes[0][1], holes[1][0], holes[1][1]);
  ASSERT_GE(holes[0][0] + holes[0][1], 10u);  // the control has holes to fill: the test could fail
  EXPECT_LE(holes[1][0] + holes[1][1], (holes[0][0] + holes[0][1]) / 2);
}

// The finder on a hexagonal lattice with one point taken out: the only node beyond 0.85 spacings is
// within half a grid step (times √2) of the missing point, and putting it back leaves none.
TEST(BakeTest, HoleFinderFindsTheMissingPointOfALattice) {
  const int rows = 16, cols = 16;  // 16 × 16 points on a 1 × (16·√3/2 / 16) torus
  const double a = 1.0 / cols, height = rows * a * std::sqrt(3.0) / 2;
  std::vector<double> points;
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < cols; ++i)
      if (!(i == 7 && j == 6))
        points.insert(points.end(), {(i + 0.5 * (j % 2)) * a, j * a * std::sqrt(3.0) / 2});
  const double step = 0.05 * a;
  HoleFinder finder(1.0, height, step, 2 * a, points);
  const std::vector<double> centres = finder.centres_beyond(0.85 * a);
  ASSERT_FALSE(centres.empty());
  const double mx = 7 * a, my = 6 * a * std::sqrt(3.0) / 2;
  EXPECT_LE(std::hypot(centres[0] - mx, centres[1] - my), step);
  for (std::size_t c = 0; c < centres.size(); c += 2)
    EXPECT_LT(std::hypot(centres[c] - mx, centres[c + 1] - my), 0.2 * a) << c;
  finder.add(mx, my);
  EXPECT_TRUE(finder.centres_beyond(0.85 * a).empty());
}

// drop_close_pairs by hand: one tile (one colour), a corner point and two interior points. The interior
// point beside the corner point appears later and goes; the far one stays; the radius is that of the
// later point's density.
TEST(BakeTest, DropClosePairsRemovesTheLaterPoint) {
  std::vector<LevelPatches> levels(2, LevelPatches(1));
  TilesetData table;
  table.level_nominal = {16, 64};
  levels[0].corners[0].add(0.2, 0.2, 100);     // threshold 0.03: first
  levels[1].interiors[0].add(0.21, 0.2, 300);  // 0.01 away, threshold 16.2: d_hex(16.2) = 0.27
  levels[1].interiors[0].add(0.5, 0.5, 200);   // far from both
  levels[0].interiors[0].add(0.7, 0.7, 60000);
  levels[1].interiors[0].add(0.75, 0.7, 65000);  // 0.05 away, threshold 63.6: 0.3 · d_hex = 0.040 < 0.05
  // Below the first level's count (outside the set's range) the radius stays that of 16: 0.081 < 0.09.
  levels[0].interiors[0].add(0.3, 0.85, 16384);   // threshold 4
  levels[0].interiors[0].add(0.39, 0.85, 40960);  // threshold 10: 0.3 · d_hex(10) = 0.10 would drop it
  EXPECT_EQ(drop_close_pairs(levels, 1, table, 0.3), 1u);
  EXPECT_EQ(levels[0].interiors[0].size(), 3u);
  EXPECT_EQ(levels[0].corners[0].size(), 1u);
  ASSERT_EQ(levels[1].interiors[0].size(), 2u);
  EXPECT_EQ(levels[1].interiors[0].keys, (std::vector<std::uint16_t>{200, 65000}));
  EXPECT_EQ(levels[1].interiors[0].xy, (std::vector<double>{0.5, 0.5, 0.75, 0.7}));
  EXPECT_EQ(drop_close_pairs(levels, 1, table, 0.4), 2u);  // now 0.05 < 0.4 · 0.135, 0.09 < 0.4 · 0.27
  EXPECT_EQ(levels[1].interiors[0].keys, (std::vector<std::uint16_t>{200}));
  EXPECT_EQ(levels[0].interiors[0].keys, (std::vector<std::uint16_t>{60000, 16384}));
  EXPECT_EQ(drop_close_pairs(levels, 1, table, 0), 0u);
}

// A pair across a tile edge (one tile colour: the interior meets itself): 0.015 apart in the world, 0.985
// within the tile. The pass looks across edges too, and removes the later point.
TEST(BakeTest, DropClosePairsLooksAcrossTileEdges) {
  std::vector<LevelPatches> levels(2, LevelPatches(1));
  TilesetData table;
  table.level_nominal = {16, 64};
  levels[1].interiors[0].add(0.99, 0.5, 1000);   // threshold 16.7
  levels[1].interiors[0].add(0.005, 0.5, 2000);  // threshold 17.5: later
  levels[1].interiors[0].add(0.5, 0.995, 3000);
  levels[1].interiors[0].add(0.5, 0.01, 100);  // earlier than the one above, across the top edge
  EXPECT_EQ(drop_close_pairs(levels, 1, table, 0.3), 2u);
  EXPECT_EQ(levels[1].interiors[0].keys, (std::vector<std::uint16_t>{1000, 100}));
}

// Pushed apart instead of removed: the later point of a close pair moves straight away from the earlier one
// until it is `push` spacings from it, and every other point stays where it was.
TEST(BakeTest, PushClosePairsApartMovesTheLaterPointOut) {
  std::vector<LevelPatches> levels(2, LevelPatches(1));
  TilesetData table;
  table.level_nominal = {16, 64};
  levels[0].corners[0].add(0.2, 0.2, 100);     // threshold 0.03: first
  levels[1].interiors[0].add(0.21, 0.2, 300);  // 0.01 away, threshold 16.2: radius 0.3 · d_hex = 0.080
  levels[1].interiors[0].add(0.5, 0.5, 200);
  levels[1].interiors[0].add(0.99, 0.6, 1000);  // across the tile's right edge from the next one
  levels[1].interiors[0].add(0.005, 0.6, 2000);
  const std::vector<double> before = levels[1].interiors[0].xy;
  const SeparationResult result = push_close_pairs_apart(levels, 1, table, 0.3, 0.5);
  EXPECT_EQ(result.removed, 0u);
  EXPECT_EQ(result.moved, 2u);
  ASSERT_EQ(levels[1].interiors[0].size(), 4u);
  const std::vector<double>& xy = levels[1].interiors[0].xy;
  const double push = 0.5 * std::sqrt(2.0 / (std::sqrt(3.0) * table.emission_threshold(1, 300)));
  EXPECT_NEAR(xy[0], 0.2 + push, 1e-12);  // along +x, away from (0.2, 0.2)
  EXPECT_DOUBLE_EQ(xy[1], 0.2);
  for (int i : {2, 3, 4, 5}) EXPECT_EQ(xy[i], before[i]) << i;
  // Across the edge: 0.015 apart in the world, the later one pushed on, further from the edge.
  const double push2 = 0.5 * std::sqrt(2.0 / (std::sqrt(3.0) * table.emission_threshold(1, 2000)));
  EXPECT_NEAR(xy[6], 0.99 + push2 - 1, 1e-12);
  EXPECT_EQ(levels[0].corners[0].xy, (std::vector<double>{0.2, 0.2}));
  // Nothing close is left: the removing pass finds nothing to remove.
  EXPECT_EQ(drop_close_pairs(levels, 1, table, 0.3), 0u);
}

// A later point next to an earlier one by its tile's top edge, pushed up and to the right: the move stays
// inside its tile (a point pushed across a tile edge would be shown by another tile), sliding along the
// edge until it is `push` spacings clear.
TEST(BakeTest, PushClosePairsApartKeepsPointsInTheirTile) {
  std::vector<LevelPatches> levels(2, LevelPatches(1));
  TilesetData table;
  table.level_nominal = {16, 64};
  levels[1].interiors[0].add(0.49, 0.975, 100);  // threshold 16.1: earlier
  levels[1].interiors[0].add(0.5, 0.985, 1000);  // threshold 16.7, 0.014 away
  const SeparationResult result = push_close_pairs_apart(levels, 1, table, 0.3, 0.5);
  EXPECT_EQ(result.removed, 0u);
  EXPECT_EQ(result.moved, 1u);
  const std::vector<double>& xy = levels[1].interiors[0].xy;
  EXPECT_DOUBLE_EQ(xy[3], 0.985);  // already closer to the edge than the margin: held, not moved out
  const double push = 0.5 * std::sqrt(2.0 / (std::sqrt(3.0) * table.emission_threshold(1, 1000)));
  EXPECT_GE(std::hypot(xy[2] - 0.49, xy[3] - 0.975), push * (1 - 1e-9));
  EXPECT_GT(xy[2], 0.5);
  EXPECT_EQ(drop_close_pairs(levels, 1, table, 0.3), 0u);
}

// A corner point too close to a point of one tile's interior: split, it stays, unmoved and with its key, in
// every other tile that shows it (as a point of that tile's interior), and only the crowded tile goes
// without it. Moved or removed, it would leave a hole in all seven.
TEST(BakeTest, SplitSharedKeepsACrowdedPointWhereItIsNotCrowded) {
  std::vector<LevelPatches> levels(2, LevelPatches(2));
  TilesetData table;
  table.colours = 2;
  table.level_nominal = {16, 64};
  levels[0].interiors[0].add(0.025, 0.02, 100);  // tile 0 (every corner colour 0): threshold 0.02
  levels[1].corners[0].add(0.02, 0.02, 1000);    // north-east of every colour-0 vertex: threshold 16.7
  const SeparationResult result = push_close_pairs_apart(levels, 2, table, 0.3, 0.5, /*split=*/true);
  EXPECT_EQ(result.split, 1u);
  EXPECT_EQ(result.moved, 0u);
  EXPECT_EQ(result.removed, 0u);
  EXPECT_EQ(levels[1].corners[0].size(), 0u);
  for (std::size_t t = 0; t < 16; ++t) {
    const Patch& interior = levels[1].interiors[t];
    if (t == 0 || t >= 8) {  // the crowded tile, and the tiles whose south-west corner is colour 1
      EXPECT_EQ(interior.size(), 0u) << t;
      continue;
    }
    ASSERT_EQ(interior.size(), 1u) << t;
    EXPECT_EQ(interior.xy, (std::vector<double>{0.02, 0.02})) << t;
    EXPECT_EQ(interior.keys[0], 1000) << t;
  }
  EXPECT_EQ(levels[0].interiors[0].size(), 1u);
  EXPECT_EQ(drop_close_pairs(levels, 2, table, 0.3), 0u);
}

// Along the glide track a crowded point that its level lets wait is shown later rather than removed: two
// paths that cross half-way between keyframes 0 and 1 and again between 1 and 2, the later point shown
// from the density after the last crossing, still within its level, with its frames.
TEST(BakeTest, SplitSharedShowsACrowdedGliderLater) {
  TilesetData table;
  table.level_nominal = {16, 64};
  table.keyframe_nominal = {16, 32, 64};
  std::vector<LevelPatches> levels(2, LevelPatches(1));
  Patch& patch = levels[1].interiors[0];
  patch.add(0.3, 0.5, 10);  // thresholds 16.01 and 16.02: both shown from keyframe 0
  patch.add(0.7, 0.5, 20);
  patch.frames = {{0.3, 0.5, 0.7, 0.5}, {0.7, 0.5, 0.3, 0.5}, {0.3, 0.5, 0.7, 0.5}};
  const SeparationResult result = drop_close_glides(levels, 1, table, 0.3, /*split=*/true);
  EXPECT_EQ(result.split, 1u);
  EXPECT_EQ(result.removed, 0u);
  ASSERT_EQ(patch.size(), 2u);
  EXPECT_EQ(patch.keys[0], 10);
  // They meet at 24 and 48 points per tile (half-way); sampled eight times per keyframe interval, the
  // next density after 48 is 52.
  const float threshold = table.emission_threshold(1, patch.keys[1]);
  EXPECT_GE(threshold, 52.0f);
  EXPECT_LT(threshold, 52.01f);
  EXPECT_EQ(patch.xy, (std::vector<double>{0.3, 0.5, 0.7, 0.5}));
  EXPECT_EQ(patch.frames[1], (std::vector<double>{0.7, 0.5, 0.3, 0.5}));
  EXPECT_EQ(drop_close_glides(levels, 1, table, 0.3, true).split, 0u);
  // A level that ends before the last meeting cannot wait: the point goes, as without splitting.
  std::vector<LevelPatches> short_levels(2, LevelPatches(1));
  table.keyframe_nominal = {16, 32, 64, 128};
  table.level_nominal = {16, 64};
  Patch& early = short_levels[1].interiors[0];
  early = patch;
  early.keys = {10, 20};
  early.frames.push_back({0.7, 0.5, 0.3, 0.5});  // a third crossing, past 64
  const SeparationResult late = drop_close_glides(short_levels, 1, table, 0.3, true);
  EXPECT_EQ(late.split, 0u);
  EXPECT_EQ(late.removed, 1u);
}

// Two points far apart at every keyframe whose paths cross half-way between two: the later one goes, with
// its frames. Paths that do not cross keep both.
TEST(BakeTest, DropCloseGlidesRemovesPointsWhosePathsMeet) {
  TilesetData table;
  table.level_nominal = {16, 64};
  table.keyframe_nominal = {16, 32, 64};
  for (bool cross : {false, true}) {
    std::vector<LevelPatches> levels(2, LevelPatches(1));
    Patch& patch = levels[0].interiors[0];
    patch.add(0.3, 0.5, 100);  // thresholds 0.03 and 0.05: both shown at every keyframe
    patch.add(0.7, 0.5, 200);
    patch.add(0.5, 0.1, 300);  // far from both
    // 0.4 apart at keyframes 0 and 2; at keyframe 1 the crossing pair has swapped sides, and half-way to
    // it (24 points per tile: 0.3 · d_hex = 0.066) both stand at x = 0.5.
    const double a1 = cross ? 0.7 : 0.3, b1 = cross ? 0.3 : 0.7;
    patch.frames = {
        {0.3, 0.5, 0.7, 0.5, 0.5, 0.1}, {a1, 0.5, b1, 0.5, 0.5, 0.1}, {0.3, 0.5, 0.7, 0.5, 0.5, 0.1}};
    EXPECT_EQ(drop_close_glides(levels, 1, table, 0).removed, 0u);
    EXPECT_EQ(drop_close_glides(levels, 1, table, 0.3).removed, cross ? 1u : 0u);
    const std::vector<std::uint16_t> kept =
        cross ? std::vector<std::uint16_t>{100, 300} : std::vector<std::uint16_t>{100, 200, 300};
    EXPECT_EQ(patch.keys, kept);
    for (const std::vector<double>& frame : patch.frames) EXPECT_EQ(frame.size(), patch.xy.size());
    if (cross) {
      EXPECT_EQ(patch.frames[1], (std::vector<double>{0.7, 0.5, 0.5, 0.1}));
    }
  }
}

TEST(BakeTest, ShippedDefaultSetRebakesBitIdentically) {
#ifndef KDM_RELEASE_BUILD
  // Bit-identical output is promised per build configuration; the shipped file comes from a Release
  // build, and other flags (sanitizers, -O0) round floating point differently.
  GTEST_SKIP() << "the shipped tile set is reproduced by Release builds";
#endif
#ifndef KDM_SLOW_TESTS
  // Baking the default set takes minutes: .ci/run rebakes it with `kdm bake` and compares the bytes.
  GTEST_SKIP() << "configure with -DKDM_SLOW_TESTS=ON to rebake the shipped set here";
#endif
  const std::string dir = std::string(KDM_SOURCE_DIR) + "/tilesets/";
  const BakeRecipe recipe = BakeRecipe::parse(read_file(dir + "default.recipe"));
  const std::vector<std::uint8_t> bytes = encoded(bake_tileset(recipe, 0));
  const std::string rebaked(bytes.begin(), bytes.end());
  const std::string shipped = read_file(dir + "default.kdmt");
  ASSERT_FALSE(shipped.empty());
  EXPECT_TRUE(rebaked == shipped)
      << "tilesets/default.kdmt is stale: rebake it with kdm bake tilesets/default.recipe -o "
         "tilesets/default.kdmt";
}

}  // namespace
}  // namespace kdm::gen
