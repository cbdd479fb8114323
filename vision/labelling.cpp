// Ground-truth inlier/outlier labels (see labelling.hpp).
#include "vision/labelling.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace wingman::vision {

void LabelSettings::validate() const {
  auto bad = [](const std::string& what) { throw std::invalid_argument("label settings: " + what); };
  if (!(max_reprojection_px > 0)) bad("max_reprojection_px must be > 0, got " + std::to_string(max_reprojection_px));
  if (depth_abs_m < 0) bad("depth_abs_m must be >= 0, got " + std::to_string(depth_abs_m));
  if (depth_rel < 0) bad("depth_rel must be >= 0, got " + std::to_string(depth_rel));
}

std::optional<double> sample_depth(const cv::Mat& depth, const Eigen::Vector2d& uv) {
  if (depth.empty()) return std::nullopt;
  if (depth.channels() != 1 || (depth.type() != CV_32F && depth.type() != CV_16U))
    throw std::invalid_argument("sample_depth: expected a CV_32F (m) or CV_16U (mm) depth image, got type " +
                                std::to_string(depth.type()));
  const int x = static_cast<int>(std::lround(uv.x())), y = static_cast<int>(std::lround(uv.y()));
  if (x < 0 || y < 0 || x >= depth.cols || y >= depth.rows) return std::nullopt;
  const double z = depth.type() == CV_32F ? depth.at<float>(y, x) : depth.at<std::uint16_t>(y, x) * 1e-3;
  if (!std::isfinite(z) || z <= 0) return std::nullopt;
  return z;
}

std::optional<Eigen::Vector3d> back_project(const Eigen::Vector2d& uv, const geometry::PinholeCamera& cam,
                                            const geometry::FramePoses& true_pose, const cv::Mat& depth) {
  const auto z = sample_depth(depth, uv);
  if (!z) return std::nullopt;
  const Eigen::Vector2d xn = cam.unproject_normalised(uv);
  const Eigen::Vector3d p_C(xn.x() * *z, xn.y() * *z, *z);
  const CameraPose pose = true_pose.at_row(uv.y());
  return pose.R_CW.transpose() * p_C + pose.position;
}

LabelResult label_landmark_observation(const Eigen::Vector3d& point_W, const Eigen::Vector2d& observed_uv,
                                       const geometry::PinholeCamera& cam, const geometry::FramePoses& true_pose,
                                       const cv::Mat& depth, const LabelSettings& cfg) {
  cfg.validate();
  LabelResult r;
  r.reprojection_px = std::numeric_limits<double>::infinity();
  const Eigen::Vector3d p_C = true_pose.to_camera(cam, point_W);
  const auto uv = cam.project(p_C);
  if (!uv) {
    r.reason = "behind camera";
    return r;
  }
  r.true_uv = uv;
  r.reprojection_px = (*uv - observed_uv).norm();
  if (!cam.in_image(*uv)) {
    r.reason = "outside image";
    return r;
  }
  if (depth.empty()) {
    r.depth_consistent = true;
  } else {
    const auto z = sample_depth(depth, *uv);
    r.depth_consistent = z && std::abs(*z - p_C.z()) <= cfg.depth_abs_m + cfg.depth_rel * p_C.z();
  }
  if (!r.depth_consistent) {
    r.reason = "occluded or no surface at the true projection";
    return r;
  }
  if (r.reprojection_px > cfg.max_reprojection_px) {
    r.reason = "pixel too far from the true projection";
    return r;
  }
  r.label = Label::Inlier;
  return r;
}

LabelResult label_pixel_pair(const Eigen::Vector2d& uv_a, const geometry::PinholeCamera& cam_a,
                             const geometry::FramePoses& true_pose_a, const cv::Mat& depth_a,
                             const Eigen::Vector2d& uv_b, const geometry::PinholeCamera& cam_b,
                             const geometry::FramePoses& true_pose_b, const cv::Mat& depth_b,
                             const LabelSettings& cfg) {
  if (depth_a.empty())
    throw std::invalid_argument("label_pixel_pair: camera a's depth image is needed to back-project");
  const auto p = back_project(uv_a, cam_a, true_pose_a, depth_a);
  if (!p) {
    LabelResult r;
    r.reprojection_px = std::numeric_limits<double>::infinity();
    r.reason = "no surface under a's pixel";
    return r;
  }
  return label_landmark_observation(*p, uv_b, cam_b, true_pose_b, depth_b, cfg);
}

}  // namespace wingman::vision
