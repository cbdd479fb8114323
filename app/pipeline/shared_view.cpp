#include "app/pipeline/shared_view.hpp"

#include <algorithm>
#include <tuple>

namespace wingman::app {

std::optional<Eigen::AlignedBox2d> ground_footprint(const slam::Estimator& est, int j) {
  const slam::CameraRig& rig = est.camera(j);
  const Eigen::Vector3d p = est.camera_position(j);
  const double z = est.lead_position().z();
  const double w = rig.model.width(), h = rig.model.height();
  Eigen::AlignedBox2d box;
  for (const Eigen::Vector2d& uv : {Eigen::Vector2d(0, 0), Eigen::Vector2d(w, 0), Eigen::Vector2d(w, h),
                                   Eigen::Vector2d(0, h)}) {
    const Eigen::Vector3d d = rig.R_CW.transpose() * rig.model.bearing(uv);
    const double s = (z - p.z()) / d.z();
    if (!(d.z() < 0) || !(s > 0)) return std::nullopt;
    box.extend((p + s * d).head<2>());
  }
  return box;
}

std::vector<std::pair<int, int>> pairs_sharing_view(const slam::Estimator& est, const std::vector<bool>& sees) {
  const int n = est.num_cameras();
  std::vector<std::optional<Eigen::AlignedBox2d>> fp(static_cast<std::size_t>(n));
  for (int j = 0; j < n; ++j)
    if (sees[j]) fp[j] = ground_footprint(est, j);
  std::vector<std::tuple<double, int, int>> shared;  // (-overlap, a, b): sorted, largest first
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b) {
      if (!sees[a] || !sees[b]) continue;
      double overlap = 1;
      if (fp[a] && fp[b]) {
        const Eigen::AlignedBox2d both = fp[a]->intersection(*fp[b]);
        const double smaller = std::min(fp[a]->volume(), fp[b]->volume());
        overlap = both.isEmpty() || !(smaller > 0) ? 0 : both.volume() / smaller;
      }
      if (overlap > 0) shared.emplace_back(-overlap, a, b);
    }
  std::sort(shared.begin(), shared.end());
  std::vector<std::pair<int, int>> out;
  for (const auto& [o, a, b] : shared) out.emplace_back(a, b);
  return out;
}

}  // namespace wingman::app
