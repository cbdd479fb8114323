// Ground-truth labels of the frontend's correspondences, for evaluation only (the estimator never
// sees them): a correspondence is an inlier when its pixel lies within a threshold of the true
// projection (docs/design.md, evaluation: 3 px) and the point is visible there, i.e. the rendered depth at the
// true projection agrees with the point's depth (not occluded by something nearer).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>

#include "geometry/camera.hpp"
#include "geometry/frame_poses.hpp"
#include "vision/cross_match.hpp"

namespace wingman::vision {

struct LabelSettings {
  double max_reprojection_px = 3.0;
  // Depth agreement: |depth_image - z| <= depth_abs_m + depth_rel * z.
  double depth_abs_m = 0.10;
  double depth_rel = 0.02;

  void validate() const;  // throws std::invalid_argument naming the bad value
};

enum class Label { Inlier, Outlier };

struct LabelResult {
  Label label = Label::Outlier;
  double reprojection_px = 0;     // observed pixel to true projection (infinite when not projected)
  std::optional<Eigen::Vector2d> true_uv;  // the true projection; nothing behind the camera
  bool depth_consistent = false;  // also true when no depth image was given
  const char* reason = "";        // why an outlier: "behind camera", "outside image", ...
};

// Depth images are metric z-depth (along the optical axis) as CV_32F (metres) or CV_16U
// (millimetres, docs/design.md, files), sampled at the nearest pixel centre; 0, NaN and inf mean "no
// surface". An empty Mat skips the depth test.
std::optional<double> sample_depth(const cv::Mat& depth, const Eigen::Vector2d& uv);

// World point through a pixel: its ray scaled to the rendered depth there, with the true pose (of
// the pixel's row, under a rolling shutter).
// This is also the ground truth of a landmark in rendered mode (docs/design.md, evaluation).
std::optional<Eigen::Vector3d> back_project(const Eigen::Vector2d& uv, const geometry::PinholeCamera& cam,
                                            const geometry::FramePoses& true_pose, const cv::Mat& depth);

// A landmark correspondence: the landmark's true point seen at `observed_uv` by a camera at its
// true pose (under a rolling shutter, that of the row the point is drawn on).
LabelResult label_landmark_observation(const Eigen::Vector3d& point_W, const Eigen::Vector2d& observed_uv,
                                       const geometry::PinholeCamera& cam, const geometry::FramePoses& true_pose,
                                       const cv::Mat& depth, const LabelSettings& settings = {});

// A cross-camera pixel pair: a's pixel is back-projected through a's depth and then labelled in b
// as a landmark observation at uv_b.
LabelResult label_pixel_pair(const Eigen::Vector2d& uv_a, const geometry::PinholeCamera& cam_a,
                             const geometry::FramePoses& true_pose_a, const cv::Mat& depth_a,
                             const Eigen::Vector2d& uv_b, const geometry::PinholeCamera& cam_b,
                             const geometry::FramePoses& true_pose_b, const cv::Mat& depth_b,
                             const LabelSettings& settings = {});

}  // namespace wingman::vision
