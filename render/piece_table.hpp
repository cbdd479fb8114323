#pragma once
// Where each vertex of the stochastic tiling's triangle grid takes its piece of the ground image
// (world.texture.tiling: stochastic; render/renderer.cpp kStochasticLookup).
//
// Two vertices whose pieces overlap in the image show the same ground twice, displaced in the world
// by the difference of their shifts (shift = piece centre - vertex position). Drawn independently,
// nearby vertices often pick nearly the same shift and show a copy a metre or two away, which a
// cooperative match between two UAVs a few metres apart can land on. The table is filled by
// best-candidate sampling instead: each vertex keeps, of several random centres, the one whose
// copies lie farthest from it among the vertices within `kRadiusCells` cells (the pieces that can
// share a frame). Periodic over kSize x kSize vertices: kSize cells of ground, hundreds of metres.
#include <cstdint>
#include <vector>

namespace wingman::render {

struct PieceTable {
  static constexpr int kSize = 64;        // vertices per side of the periodic table
  static constexpr int kCandidates = 32;  // random centres tried per vertex and sweep
  static constexpr int kSweeps = 3;
  static constexpr double kRadiusCells = 4;  // vertices this near constrain each other
  double cell = 0;                       // grid side, in units of the image's width
  double aspect = 1;                     // the image's height over its width
  std::vector<float> centres;            // (u, v) per vertex, row j = grid row, in width units

  // Centre of vertex (i, j) of the infinite grid (the table repeats every kSize vertices).
  void centre(int i, int j, double& u, double& v) const;
};

// cell: the grid's side in units of the image's width; aspect: height over width. Centres stay at
// least 1.02 cells from the image's border (kStochasticLookup: no piece wraps over a seam).
PieceTable piece_table(double cell, double aspect, std::uint64_t seed);

// The same grid with each centre drawn independently (what a per-vertex hash gives): the reference
// the best-candidate table is measured against.
PieceTable random_piece_table(double cell, double aspect, std::uint64_t seed);

// The smallest displacement, in units of the image's width, between two copies of the same image
// point shown by vertices within kRadiusCells of each other: over pairs whose pieces (hexagons of
// one cell's radius about their centres) can overlap, |shift_a - shift_b|.
double min_copy_distance(const PieceTable& t);

}  // namespace wingman::render
