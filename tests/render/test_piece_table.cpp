// The stochastic tiling's piece table: nearby grid vertices never show copies of the same ground a
// short way apart, where independent draws do.
#include <gtest/gtest.h>

#include "render/piece_table.hpp"

namespace wingman::render {
namespace {

// The shipped ground photo (1000 x 750) at the default cell (a quarter of its shorter side).
constexpr double kAspect = 0.75, kCell = 0.25 * 0.75;

TEST(PieceTable, NearbyVerticesShowNoCopyWithinTwoThirdsOfACell) {
  const PieceTable t = piece_table(kCell, kAspect, 7);
  // 60 m photo: 11.25 m cells; the nearest copy of any point at least 7.5 m away.
  EXPECT_GT(min_copy_distance(t), 0.67 * kCell);
}

TEST(PieceTable, IndependentDrawsPutCopiesMuchNearer) {
  const PieceTable t = random_piece_table(kCell, kAspect, 7);
  EXPECT_LT(min_copy_distance(t), 0.1 * kCell);
}

TEST(PieceTable, CentresKeepAPieceInsideTheImage) {
  const PieceTable t = piece_table(kCell, kAspect, 3);
  for (std::size_t k = 0; k < t.centres.size(); k += 2) {
    ASSERT_GE(t.centres[k], 1.02 * kCell - 1e-6);
    ASSERT_LE(t.centres[k], 1 - 1.02 * kCell + 1e-6);
    ASSERT_GE(t.centres[k + 1], 1.02 * kCell - 1e-6);
    ASSERT_LE(t.centres[k + 1], kAspect - 1.02 * kCell + 1e-6);
  }
}

TEST(PieceTable, TheTableRepeatsEverySizeVerticesAndDependsOnTheSeed) {
  const PieceTable a = piece_table(kCell, kAspect, 3), b = piece_table(kCell, kAspect, 3),
                   c = piece_table(kCell, kAspect, 4);
  EXPECT_EQ(a.centres, b.centres);
  EXPECT_NE(a.centres, c.centres);
  double u0, v0, u1, v1;
  a.centre(5, -2, u0, v0);
  a.centre(5 + PieceTable::kSize, -2 - PieceTable::kSize, u1, v1);
  EXPECT_EQ(u0, u1);
  EXPECT_EQ(v0, v1);
}

TEST(PieceTable, ACellTooLargeForTheImageIsRefused) {
  EXPECT_THROW(piece_table(0.4, 0.75, 1), std::invalid_argument);
}

}  // namespace
}  // namespace wingman::render
