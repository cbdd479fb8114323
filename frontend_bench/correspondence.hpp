// Ground-truth pixel correspondences between two rendered frames (docs/frontend.md, benchmark):
// a pixel of frame A is undistorted, back-projected to the rendered depth (metres along A's
// optical axis) with A's true pose, and projected with lens distortion into frame B at its true
// pose. It has a correspondence only when the point lies in B's image and B's own depth there
// agrees with the point's depth in B (otherwise something nearer hides it). Under a rolling
// shutter the pose is the row's: A's pixel is back-projected with its row's pose, and the point
// lands in B on the row whose own pose projects it onto that row, where B's depth (each row drawn
// from its own pose) is compared with its depth in that row's camera.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "geometry/camera.hpp"
#include "geometry/frame_poses.hpp"

namespace wingman::frontend_bench {

// One frame's truth: its camera, its true poses (one, or one per row under a rolling shutter) and
// the rendered depth (CV_32F metres along the optical axis, 0 = no surface).
struct FrameTruth {
  geometry::PinholeCamera camera;
  geometry::FramePoses pose;
  cv::Mat depth;
};

struct CorrespondenceOptions {
  // B's depth at the projection must satisfy |depth_B - z_B| <= depth_abs_m + depth_rel * z_B
  // (the tolerance of vision/labelling.hpp: a few rendered depth steps at a surface's slope).
  double depth_abs_m = 0.10;
  double depth_rel = 0.02;
  void validate() const;  // throws std::invalid_argument naming the bad value
};

enum class CorrespondenceStatus { Found, NoDepth, BehindCamera, OutsideImage, Occluded };
const char* to_string(CorrespondenceStatus s);

struct Correspondence {
  CorrespondenceStatus status = CorrespondenceStatus::NoDepth;
  Eigen::Vector2d uv_b = Eigen::Vector2d::Zero();       // set from BehindCamera on: the projection
  Eigen::Vector3d point_W = Eigen::Vector3d::Zero();    // the back-projected point
  double depth_b = 0;                                   // its depth along B's optical axis
  bool found() const { return status == CorrespondenceStatus::Found; }
};

// Depth at the pixel centre nearest uv; 0 outside the image or where there is no surface.
double depth_at(const cv::Mat& depth, const Eigen::Vector2d& uv);

// The true correspondence in B of A's pixel uv_a (OpenCV's pixel convention: (0,0) is the centre
// of the top-left pixel). A's depth is read at the nearest pixel centre.
Correspondence true_correspondence(const FrameTruth& a, const FrameTruth& b,
                                   const Eigen::Vector2d& uv_a,
                                   const CorrespondenceOptions& options = {});

}  // namespace wingman::frontend_bench
