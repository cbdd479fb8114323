// Hand-made frames for the matching benchmark's tests: nadir cameras 10 m above the plane z = 0
// (depth 10 m at every pixel), 100 x 100 pixels, f = 50 px, principal point (49.5, 49.5). Camera
// B 2 m further along world x sees every point 10 px left of where A sees it.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "frontend_bench/correspondence.hpp"
#include "geometry/rotation.hpp"

namespace wingman::frontend_bench::test {

inline FrameTruth nadir_frame(const Eigen::Vector3d& centre, geometry::Distortion dist = {},
                              double yaw = 0) {
  FrameTruth f;
  f.camera = geometry::PinholeCamera(50, 50, 49.5, 49.5, 100, 100, dist);
  f.pose = geometry::CameraPose{geometry::nadir_R_CW() * geometry::rot_z(yaw).transpose(), centre};
  f.depth = cv::Mat(100, 100, CV_32F, cv::Scalar(centre.z()));
  return f;
}

}  // namespace wingman::frontend_bench::test
