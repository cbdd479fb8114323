// True correspondences into a rolling-shutter frame (frontend_bench/correspondence.hpp with the
// row poses of datasets/frame_poses.hpp): a camera 10 m over the plane z = 0 flying at 40 m/s
// (400 px/s), accelerating sideways, yawing and with its gimbal turning, read out over 24 ms. A
// ground point must land where the pose of the row it lands on projects it, found here by
// bisection over the rows with the analytic motion, independently of the code under test.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>

#include "datasets/frame_poses.hpp"
#include "frontend_bench/correspondence.hpp"
#include "geometry/rotation.hpp"

namespace wingman::frontend_bench {
namespace {

constexpr double kLineDelay = 2e-4;  // s a row: 120 rows in 24 ms
const Eigen::Vector3d kOffset{0.3, 0, -0.2};  // the camera in the body frame (T_BS)
const geometry::PinholeCamera kCamera(100, 100, 79.5, 59.5, 160, 120);

Eigen::Vector3d body_p(double t) { return {40 * t, 5 * t * t, 10.2}; }
Eigen::Vector3d body_v(double t) { return {40, 10 * t, 0}; }
Eigen::Matrix3d R_WB(double t) { return geometry::rot_z(0.5 * t); }
geometry::CameraPose pose_at(double t) {
  return {geometry::rot_x(0.3 * t) * geometry::nadir_R_CW(), body_p(t) + R_WB(t) * kOffset};
}
double row_time(double row) { return (row - (kCamera.height() - 1) / 2.0) * kLineDelay; }

datasets::PoseSample sample(std::int64_t t_ns, const Eigen::Vector3d& p, const Eigen::Matrix3d& R) {
  datasets::PoseSample s;
  s.t_ns = t_ns;
  s.p = p;
  s.q_xyzw = geometry::quaternion_xyzw(R);
  return s;
}

// Frames at 0, 0.1, 0.2 and 0.3 s; the body's ground truth at 200 Hz.
datasets::AgentData flight(bool rolling) {
  datasets::AgentData a;
  a.name = "uav1";
  datasets::CameraInfo c;
  c.camera = kCamera;
  c.offset = kOffset;
  c.rolling = rolling;
  c.line_delay_s = rolling ? kLineDelay : 0;
  a.camera = c;
  for (int i = 0; i <= 60; ++i) {
    const double t = 0.005 * i;
    a.groundtruth.push_back(sample(5'000'000LL * i, body_p(t), R_WB(t)));
    a.groundtruth.back().v = body_v(t);
  }
  for (int k = 0; k <= 3; ++k) {
    a.frames.push_back(100'000'000LL * k);
    a.camera_pose.push_back(sample(a.frames.back(), pose_at(0.1 * k).position, pose_at(0.1 * k).R_CW));
  }
  return a;
}

// The plane's depth at every pixel, each row seen from the pose `row_pose(row)`.
template <class RowPose>
cv::Mat ground_depth(const RowPose& row_pose) {
  cv::Mat d(kCamera.height(), kCamera.width(), CV_32F);
  for (int v = 0; v < d.rows; ++v) {
    const geometry::CameraPose p = row_pose(v);
    for (int u = 0; u < d.cols; ++u) {
      const Eigen::Vector2d xn = kCamera.unproject_normalised({u, v});
      const Eigen::Vector3d ray_W = p.R_CW.transpose() * Eigen::Vector3d(xn.x(), xn.y(), 1);
      d.at<float>(v, u) = static_cast<float>(-p.position.z() / ray_W.z());
    }
  }
  return d;
}

// Where p_W lands in the frame at t: on the row v whose own pose projects it onto v.
Eigen::Vector2d rolling_projection(const Eigen::Vector3d& p_W, double t) {
  auto project = [&](double v) { return *kCamera.project(pose_at(t + row_time(v)).to_camera(p_W)); };
  double lo = -0.5, hi = kCamera.height() - 0.5;  // project(v).y - v falls with v
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (project(mid).y() > mid ? lo : hi) = mid;
  }
  return project(0.5 * (lo + hi));
}

TEST(RollingCorrespondence, RowPosesFromTheDatasetFollowTheMotion) {
  const datasets::AgentData a = flight(true);
  const geometry::FramePoses poses = datasets::frame_poses(a, 1);
  ASSERT_TRUE(poses.rolling());
  for (const int row : {0, 37, 59, 119}) {
    const geometry::CameraPose want = pose_at(0.1 + row_time(row)), got = poses.at_row(row);
    EXPECT_NEAR((got.position - want.position).norm(), 0.0, 1e-6) << row;
    EXPECT_NEAR((got.R_CW - want.R_CW).cwiseAbs().maxCoeff(), 0.0, 1e-9) << row;
  }
  // The first frame's early rows lie before the ground truth: carried back at its velocity, off by
  // the sideways acceleration over 12 ms (10 m/s^2 * dt^2 / 2 = 0.7 mm) and the yaw's turn of the offset.
  EXPECT_NEAR((datasets::frame_poses(a, 0).at_row(0).position - pose_at(row_time(0)).position).norm(), 0.0, 2e-3);
  EXPECT_FALSE(datasets::frame_poses(flight(false), 1).rolling());
}

TEST(RollingCorrespondence, AGroundPointLandsWhereItsRowsPoseProjectsIt) {
  const datasets::AgentData reference = flight(false), rolling = flight(true);
  FrameTruth a{kCamera, datasets::frame_poses(reference, 1), ground_depth([](int) { return pose_at(0.1); })};
  for (const int k : {1, 2}) {  // the same instant, and 0.1 s later
    SCOPED_TRACE(k);
    const double t = 0.1 * k;
    const FrameTruth b{kCamera, datasets::frame_poses(rolling, static_cast<std::size_t>(k)),
                       ground_depth([&](int v) { return pose_at(t + row_time(v)); })};
    int found = 0;
    double worst = 0, shear = 0;
    for (int v = 5; v < 120; v += 10)
      for (int u = 5; u < 160; u += 10) {
        const Correspondence c = true_correspondence(a, b, {u, v});
        if (!c.found()) continue;
        ++found;
        EXPECT_NEAR(c.point_W.z(), 0.0, 1e-3);
        worst = std::max(worst, (c.uv_b - rolling_projection(c.point_W, t)).norm());
        shear = std::max(shear, (c.uv_b - *kCamera.project(pose_at(t).to_camera(c.point_W))).norm());
      }
    EXPECT_GT(found, k == 1 ? 150 : 40);
    EXPECT_LT(worst, 1e-3);  // px from the row pose's projection
    EXPECT_GT(shear, 3.0);   // px from the middle row's: what a global-shutter truth would get wrong
  }
}

}  // namespace
}  // namespace wingman::frontend_bench
