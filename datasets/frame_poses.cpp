#include "datasets/frame_poses.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <vector>

namespace wingman::datasets {

namespace {

Eigen::Quaterniond quaternion(const PoseSample& s) {
  return Eigen::Quaterniond(s.q_xyzw[3], s.q_xyzw[0], s.q_xyzw[1], s.q_xyzw[2]).normalized();
}

double seconds(std::int64_t ns) { return 1e-9 * static_cast<double>(ns); }

// The body at time t (ns): between two ground-truth samples the cubic through their positions and
// velocities and the slerp of their rotations; outside them the nearest sample carried on at its
// velocity.
struct Body {
  Eigen::Vector3d p;
  Eigen::Quaterniond q;
};
Body body_at(const std::vector<PoseSample>& gt, double t_ns) {
  const auto it = std::lower_bound(gt.begin(), gt.end(), t_ns,
                                   [](const PoseSample& s, double t) { return static_cast<double>(s.t_ns) < t; });
  if (it == gt.begin() || it == gt.end()) {
    const PoseSample& s = it == gt.end() ? gt.back() : gt.front();
    return {s.p + s.v * 1e-9 * (t_ns - static_cast<double>(s.t_ns)), quaternion(s)};
  }
  const PoseSample &s0 = *(it - 1), &s1 = *it;
  const double h = seconds(s1.t_ns - s0.t_ns), a = 1e-9 * (t_ns - static_cast<double>(s0.t_ns)) / h;
  const double h00 = (1 + 2 * a) * (1 - a) * (1 - a), h10 = a * (1 - a) * (1 - a), h01 = a * a * (3 - 2 * a),
               h11 = a * a * (a - 1);
  return {h00 * s0.p + h10 * h * s0.v + h01 * s1.p + h11 * h * s1.v, quaternion(s0).slerp(a, quaternion(s1))};
}

// The camera's rotation dt seconds after frame k: the slerp toward the next frame's (or, before
// the frame or at the last one, away from the previous frame's).
Eigen::Quaterniond rotation_at(const AgentData& a, std::size_t k, double dt) {
  const Eigen::Quaterniond q = quaternion(a.camera_pose[k]);
  if (a.camera_pose.size() < 2 || dt == 0) return q;
  const bool next = (dt > 0 && k + 1 < a.camera_pose.size()) || k == 0;
  const std::size_t j = next ? k + 1 : k - 1;
  const double span = seconds(a.frames[j] - a.frames[k]);  // negative toward the previous frame
  return q.slerp(dt / span, quaternion(a.camera_pose[j]));
}

geometry::CameraPose camera_pose(const Eigen::Quaterniond& q_CW, const Eigen::Vector3d& centre) {
  return {q_CW.toRotationMatrix(), centre};
}

}  // namespace

double row_time(const CameraInfo& c, double row) {
  if (!c.rolling) return 0;
  return geometry::rolling_row_time(row, c.camera.height(), c.line_delay_s, c.top_to_bottom);
}

geometry::FramePoses frame_poses(const AgentData& a, std::size_t k) {
  if (!a.camera || k >= a.frames.size() || k >= a.camera_pose.size())
    throw DatasetError(fmt::format("{}: no camera frame {}", a.name, k));
  const PoseSample& centre = a.camera_pose[k];
  const geometry::CameraPose middle = camera_pose(quaternion(centre), centre.p);
  if (!a.camera->rolling || a.groundtruth.empty()) return geometry::FramePoses(middle);
  const auto t = static_cast<double>(a.frames[k]);
  const Body b0 = body_at(a.groundtruth, t);
  const Eigen::Vector3d& p_BS = a.camera->offset;
  std::vector<geometry::CameraPose> rows(static_cast<std::size_t>(a.camera->camera.height()));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const double dt = row_time(*a.camera, static_cast<double>(r));
    const Body b = body_at(a.groundtruth, t + 1e9 * dt);
    const Eigen::Vector3d p = centre.p + (b.p - b0.p) + (b.q * p_BS - b0.q * p_BS);
    rows[r] = camera_pose(rotation_at(a, k, dt), p);
  }
  return geometry::FramePoses(middle, std::move(rows));
}

}  // namespace wingman::datasets
