// The sub-vertex colouring of the hand-over (kdm/runtime/subdivision.h): every tile that holds a
// sub-vertex gives it one colour, whatever its other corners, and each zone depends on its own colours.
#include <gtest/gtest.h>

#include <random>
#include <set>
#include <vector>

#include "kdm/runtime/subdivision.h"

namespace kdm {
namespace {

TEST(SubdivisionTest, TilesSharingASubVertexGiveItOneColour) {
  // A 6×6 world of tiles with random corner colours: each sub-vertex on a tile edge or corner is held by
  // two or four tiles.
  const Subdivision sub{3, 32, 3};
  const int side = 6;
  std::mt19937 rng(5);
  std::vector<std::uint32_t> corner(std::size_t(side + 1) * (side + 1));
  for (auto& c : corner) c = rng() % sub.colours;
  const auto at = [&](int x, int y) { return corner[std::size_t(y) * (side + 1) + x]; };
  const int world = side * int(sub.m);
  std::vector<std::set<std::uint32_t>> seen(std::size_t(world + 1) * (world + 1));
  std::set<std::uint32_t> used;
  for (int ty = 0; ty < side; ++ty)
    for (int tx = 0; tx < side; ++tx)
      for (std::uint32_t j = 0; j <= sub.m; ++j)
        for (std::uint32_t i = 0; i <= sub.m; ++i) {
          const std::uint32_t c =
              sub.vertex_colour(at(tx, ty), at(tx + 1, ty), at(tx + 1, ty + 1), at(tx, ty + 1), i, j);
          ASSERT_LT(c, sub.colours);
          used.insert(c);
          seen[std::size_t(ty * sub.m + j) * (world + 1) + tx * sub.m + i].insert(c);
        }
  for (const auto& colours : seen) EXPECT_EQ(colours.size(), 1u);
  EXPECT_EQ(used.size(), sub.colours);  // every colour occurs
}

TEST(SubdivisionTest, ACornerZoneDependsOnItsCornerAloneAndAnEdgeBandOnItsEnds) {
  const Subdivision sub{2, 32, 3};
  int corner_changed = 0, band_changed = 0, interior_changed = 0;
  for (std::uint32_t j = 0; j <= sub.m; ++j)
    for (std::uint32_t i = 0; i <= sub.m; ++i) {
      // Tiles that differ only in their north-east corner.
      const std::uint32_t a = sub.vertex_colour(0, 1, 0, 1, i, j), b = sub.vertex_colour(0, 1, 1, 1, i, j);
      const Subdivision::Zone zone = sub.zone_of(i, j);
      const bool touches_ne = (2 * i > sub.m && zone != Subdivision::Zone::kHorizontalEdge) ||
                              (2 * j > sub.m && zone != Subdivision::Zone::kVerticalEdge);
      if (zone == Subdivision::Zone::kInterior) {
        interior_changed += a != b;
      } else if (!(2 * i > sub.m && 2 * j > sub.m) && zone == Subdivision::Zone::kCorner) {
        EXPECT_EQ(a, b) << "corner zone at " << i << ", " << j;
      } else if (!touches_ne) {
        EXPECT_EQ(a, b) << "edge band at " << i << ", " << j;
      } else {
        (zone == Subdivision::Zone::kCorner ? corner_changed : band_changed) += a != b;
      }
    }
  // The zones that do depend on the changed corner change somewhere (2 colours: about half the vertices).
  EXPECT_GT(corner_changed, 2);
  EXPECT_GT(band_changed, 10);
  EXPECT_GT(interior_changed, 100);
}

}  // namespace
}  // namespace kdm
