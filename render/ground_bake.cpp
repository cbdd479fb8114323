#include "render/ground_bake.hpp"

#include <cmath>

namespace wingman::render {

Eigen::AlignedBox2d uv_box(const std::vector<Mesh>& meshes, int material) {
  Eigen::AlignedBox2d box;
  for (const Mesh& m : meshes)
    if (m.material == material)
      for (std::size_t k = 0; k + 1 < m.uvs.size(); k += 2) box.extend(Eigen::Vector2d(m.uvs[k], m.uvs[k + 1]));
  return box;
}

std::optional<GroundBake> plan_ground_bake(const Eigen::AlignedBox2d& uv_box, int cols, int rows, int max_side) {
  if (uv_box.isEmpty() || cols < 1 || rows < 1) return std::nullopt;
  GroundBake b;
  b.density = Eigen::Vector2d(cols, rows);
  const Eigen::Vector2d lo = uv_box.min().cwiseProduct(b.density), hi = uv_box.max().cwiseProduct(b.density);
  // Corner and size in whole blocks of kBakeBlockTexels: the bake's first mipmap levels then
  // average the very texels the image's own levels do.
  const double k = kBakeBlockTexels;
  const double x0 = k * std::floor((lo.x() - kBakePadTexels) / k), y0 = k * std::floor((lo.y() - kBakePadTexels) / k);
  const double w = k * std::ceil((hi.x() + kBakePadTexels - x0) / k), h = k * std::ceil((hi.y() + kBakePadTexels - y0) / k);
  if (w > max_side || h > max_side || w * h > kMaxBakedTexels) return std::nullopt;
  b.width = static_cast<int>(w);
  b.height = static_cast<int>(h);
  b.uv0 = Eigen::Vector2d(x0, y0).cwiseQuotient(b.density);
  return b;
}

}  // namespace wingman::render
