// The vocabulary every module shares for where a camera is and what a landmark is called.
#pragma once

#include <Eigen/Core>
#include <cstdint>

namespace wingman::geometry {

// A camera's pose: R_CW rotates world vectors into the camera frame (OpenCV's: x right, y down,
// z along the optical axis) and `position` is the camera centre in the world frame, so a world
// point projects through p_C = R_CW (p_W - position) (the paper's eq. 4 and 6).
struct CameraPose {
  Eigen::Matrix3d R_CW = Eigen::Matrix3d::Identity();
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d to_camera(const Eigen::Vector3d& p_W) const { return R_CW * (p_W - position); }
};

// A landmark's id, the same in the estimator's map, the frontend's descriptor store and the
// evaluation's records.
using LandmarkId = std::int64_t;

}  // namespace wingman::geometry
