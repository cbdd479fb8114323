// A rolling-shutter frame's poses: a world point's solved row is the row whose own pose projects it
// onto that row; a global shutter's is its one pose; between rows the pose is interpolated.
#include <gtest/gtest.h>

#include <vector>

#include "geometry/frame_poses.hpp"
#include "geometry/rotation.hpp"

namespace wingman::geometry {
namespace {

const PinholeCamera kCam(200, 200, 319.5, 239.5, 640, 480);

FramePoses moving(double speed_per_row) {
  std::vector<CameraPose> rows;
  for (int r = 0; r < kCam.height(); ++r)
    rows.push_back({rot_z(1e-4 * r) * nadir_R_CW(), Eigen::Vector3d(speed_per_row * (r - 239.5), 0, 20)});
  return FramePoses({nadir_R_CW(), {0, 0, 20}}, rows);
}

TEST(FramePoses, APointIsOnTheRowWhosePoseProjectsItThere) {
  const FramePoses poses = moving(0.01);  // 1 cm per row: 0.1 px per row at 20 m
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(3, 4, 0), Eigen::Vector3d(-10, -7, 1), Eigen::Vector3d(0, 0, 0)}) {
    const Eigen::Vector3d p_C = poses.to_camera(kCam, p);
    const auto uv = kCam.project(p_C);
    ASSERT_TRUE(uv);
    const auto again = kCam.project(poses.at_row(uv->y()).to_camera(p));
    ASSERT_TRUE(again);
    EXPECT_LT((*again - *uv).norm(), 1e-6);
  }
}

TEST(FramePoses, AGlobalShutterHasOnePose) {
  const FramePoses poses(CameraPose{nadir_R_CW(), {1, 2, 20}});
  EXPECT_FALSE(poses.rolling());
  EXPECT_EQ(poses.at_row(400).position, Eigen::Vector3d(1, 2, 20));
  EXPECT_EQ(poses.to_camera(kCam, {1, 2, 0}), Eigen::Vector3d(0, 0, 20));
}

TEST(FramePoses, PosesBetweenRowsAreInterpolatedAndClampedAtTheEdges) {
  const FramePoses poses = moving(0.01);
  EXPECT_NEAR(poses.at_row(10.25).position.x(), 0.01 * (10.25 - 239.5), 1e-12);
  EXPECT_NEAR(poses.at_row(-5).position.x(), 0.01 * (0 - 239.5), 1e-12);
  EXPECT_NEAR(poses.at_row(1e6).position.x(), 0.01 * (479 - 239.5), 1e-12);
  const Eigen::Matrix3d mid = poses.at_row(100.5).R_CW, want = rot_z(1e-4 * 100.5) * nadir_R_CW();
  EXPECT_LT((mid - want).norm(), 1e-9);
}

}  // namespace
}  // namespace wingman::geometry
