#include "app/pipeline/lead_label.hpp"

#include <algorithm>
#include <cmath>

namespace wingman::app {

namespace {

// Counts the silhouette's pixels and those the frame shows, and bounds the shown ones.
void visible_pixels(const geometry::PinholeCamera& model, const cv::Mat& depth, const render::LeadSilhouette& s,
                    geometry::LeadImage& out) {
  const bool distorted = !model.distortion().is_zero();
  int total = 0, shown = 0;
  int u0 = model.width(), v0 = model.height(), u1 = -1, v1 = -1;
  for (int r = 0; r < s.depth.rows; ++r) {
    const float* d = s.depth.ptr<float>(r);
    for (int c = 0; c < s.depth.cols; ++c) {
      if (d[c] <= 0) continue;
      ++total;
      Eigen::Vector2d uv(s.window.x + c, s.window.y + r);  // pinhole pixel
      if (distorted)
        uv = model.distort_normalised({(uv.x() - model.cx()) / model.fx(), (uv.y() - model.cy()) / model.fy()});
      const int u = static_cast<int>(std::lround(uv.x())), v = static_cast<int>(std::lround(uv.y()));
      if (u < 0 || v < 0 || u >= depth.cols || v >= depth.rows) continue;
      const float seen = depth.at<float>(v, u);
      if (seen <= 0 || seen < d[c] - (0.05f + 0.01f * d[c])) continue;
      ++shown;
      u0 = std::min(u0, u), v0 = std::min(v0, v), u1 = std::max(u1, u), v1 = std::max(v1, v);
    }
  }
  out.visible = total > 0 ? static_cast<double>(shown) / total : 0.0;
  if (shown > 0) out.box_u0 = u0, out.box_v0 = v0, out.box_u1 = u1 + 1, out.box_v1 = v1 + 1;
}

}  // namespace

geometry::LeadImage lead_label(const Eigen::Vector3d& x_h_W, const geometry::PinholeCamera& model,
                               const geometry::FramePoses& poses, const cv::Mat& depth,
                               const std::optional<render::LeadSilhouette>& silhouette) {
  geometry::LeadImage out;
  out.distance = (x_h_W - poses.centre().position).norm();
  if (const auto uv = model.project(poses.to_camera(model, x_h_W))) out.uv = *uv;
  if (silhouette) visible_pixels(model, depth, *silhouette, out);
  return out;
}

}  // namespace wingman::app
