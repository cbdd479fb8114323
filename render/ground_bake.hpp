// The stochastically tiled ground (Material::stochastic_cell) baked once per world into one
// texture: a frame then pays one filtered lookup where the live tiling pays three and a piece
// table fetch each. The texture covers the ground's texture coordinates at the image's own texel
// density, so its level 0 holds the live tiling's level-0 colours and its mipmaps are filtered
// from them. Where that would not fit the limits below, the ground is drawn live.
#pragma once

#include <Eigen/Geometry>

#include <optional>
#include <vector>

#include "render/scene.hpp"

namespace wingman::render {

// The most texels a baked ground may hold (RGBA8: 4 bytes each, a third more with mipmaps).
inline constexpr double kMaxBakedTexels = 80e6;
// Texels of room around the ground's coordinates (bilinear filtering at its edge).
inline constexpr int kBakePadTexels = 2;
// The bake's corner and size are whole blocks of this many texels, and the live tiling shifts its
// pieces by whole blocks (render/shaders.cpp, kStochasticLookup): levels 0-3 of the bake's mipmaps
// and of the image's then cover the same texels.
inline constexpr int kBakeBlockTexels = 8;

struct GroundBake {
  int width = 0, height = 0;   // texels
  Eigen::Vector2d uv0{0, 0};   // the texture coordinate at the baked texture's corner
  Eigen::Vector2d density{1, 1};  // baked texels per unit of texture coordinate (the image's size)
  // The baked texture's coordinate of the ground's texture coordinate uv.
  Eigen::Vector2d map(const Eigen::Vector2d& uv) const {
    return (uv - uv0).cwiseProduct(density).cwiseQuotient(Eigen::Vector2d(width, height));
  }
};

// The texture coordinates of the meshes of material `material`.
Eigen::AlignedBox2d uv_box(const std::vector<Mesh>& meshes, int material);

// The bake of the texture coordinates in uv_box for an image of cols x rows texels, or nothing
// when it would be wider or taller than max_side or hold more than kMaxBakedTexels.
std::optional<GroundBake> plan_ground_bake(const Eigen::AlignedBox2d& uv_box, int cols, int rows, int max_side);

}  // namespace wingman::render
