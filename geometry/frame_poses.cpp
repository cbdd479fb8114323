#include "geometry/frame_poses.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace wingman::geometry {

double rolling_row_time(double row, int height, double line_delay, bool top_to_bottom) {
  return (top_to_bottom ? 1 : -1) * (row - (height - 1) / 2.0) * line_delay;
}

FramePoses::FramePoses(const CameraPose& centre, std::vector<CameraPose> rows)
    : centre_(centre), rows_(std::move(rows)) {}

CameraPose FramePoses::at_row(double v) const {
  if (rows_.empty()) return centre_;
  const double last = static_cast<double>(rows_.size() - 1);
  const double c = std::clamp(v, 0.0, last);
  const auto r0 = static_cast<std::size_t>(std::floor(c));
  const std::size_t r1 = std::min(r0 + 1, rows_.size() - 1);
  const double a = c - static_cast<double>(r0);
  if (a == 0 || r0 == r1) return rows_[r0];
  const Eigen::Quaterniond q0(rows_[r0].R_CW), q1(rows_[r1].R_CW);
  CameraPose p;
  p.R_CW = q0.slerp(a, q1).toRotationMatrix();
  p.position = (1 - a) * rows_[r0].position + a * rows_[r1].position;
  return p;
}

Eigen::Vector3d FramePoses::to_camera(const PinholeCamera& cam, const Eigen::Vector3d& p_W) const {
  Eigen::Vector3d p_C = centre_.to_camera(p_W);
  if (rows_.empty()) return p_C;
  for (int it = 0; it < 8; ++it) {
    const auto uv = cam.project(p_C);
    if (!uv) break;
    const Eigen::Vector3d next = at_row(uv->y()).to_camera(p_W);
    const bool done = (next - p_C).norm() < 1e-12 * std::max(1.0, p_C.norm());
    p_C = next;
    if (done) break;
  }
  return p_C;
}

}  // namespace wingman::geometry
