#include "frontend_bench/correspondence.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace wingman::frontend_bench {

void CorrespondenceOptions::validate() const {
  if (!(depth_abs_m >= 0) || !(depth_rel >= 0))
    throw std::invalid_argument("correspondence depth tolerance must be >= 0, got " +
                                std::to_string(depth_abs_m) + " m + " + std::to_string(depth_rel));
}

const char* to_string(CorrespondenceStatus s) {
  switch (s) {
    case CorrespondenceStatus::Found: return "found";
    case CorrespondenceStatus::NoDepth: return "no depth in A";
    case CorrespondenceStatus::BehindCamera: return "behind camera B";
    case CorrespondenceStatus::OutsideImage: return "outside image B";
    case CorrespondenceStatus::Occluded: return "occluded in B";
  }
  return "?";
}

double depth_at(const cv::Mat& depth, const Eigen::Vector2d& uv) {
  if (depth.empty() || depth.type() != CV_32F)
    throw std::invalid_argument("depth_at: a CV_32F depth image in metres is needed");
  const long x = std::lround(uv.x()), y = std::lround(uv.y());
  if (!std::isfinite(uv.x()) || !std::isfinite(uv.y()) || x < 0 || y < 0 || x >= depth.cols ||
      y >= depth.rows)
    return 0;
  const float z = depth.at<float>(static_cast<int>(y), static_cast<int>(x));
  return std::isfinite(z) && z > 0 ? z : 0.0;
}

Correspondence true_correspondence(const FrameTruth& a, const FrameTruth& b,
                                   const Eigen::Vector2d& uv_a,
                                   const CorrespondenceOptions& options) {
  Correspondence c;
  const double z_a = depth_at(a.depth, uv_a);
  if (z_a <= 0) return c;  // NoDepth
  const Eigen::Vector2d xn = a.camera.unproject_normalised(uv_a);
  const geometry::CameraPose pose_a = a.pose.at_row(uv_a.y());
  c.point_W = pose_a.R_CW.transpose() * Eigen::Vector3d(xn.x() * z_a, xn.y() * z_a, z_a) + pose_a.position;
  const Eigen::Vector3d p_B = b.pose.to_camera(b.camera, c.point_W);
  c.depth_b = p_B.z();
  const auto uv = b.camera.project(p_B);
  if (!uv) {
    c.status = CorrespondenceStatus::BehindCamera;
    return c;
  }
  c.uv_b = *uv;
  if (!b.camera.in_image(*uv)) {
    c.status = CorrespondenceStatus::OutsideImage;
    return c;
  }
  const double z_b = depth_at(b.depth, *uv);
  const bool visible = z_b > 0 && std::abs(z_b - p_B.z()) <= options.depth_abs_m + options.depth_rel * p_B.z();
  c.status = visible ? CorrespondenceStatus::Found : CorrespondenceStatus::Occluded;
  return c;
}

}  // namespace wingman::frontend_bench
