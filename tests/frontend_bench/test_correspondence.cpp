// True correspondences from depth and poses (frontend_bench/correspondence.hpp) on hand-made frames.
#include <gtest/gtest.h>

#include <random>

#include "frontend_bench/correspondence.hpp"
#include "geometry/rotation.hpp"
#include "frontend_bench/match_test_support.hpp"

namespace wingman::frontend_bench {
namespace {

using test::nadir_frame;

TEST(TrueCorrespondence, PlaneSeenFromTwoPosesShiftsByFocalTimesBaselineOverDepth) {
  const FrameTruth a = nadir_frame({0, 0, 10}), b = nadir_frame({2, 0, 10});
  const Correspondence c = true_correspondence(a, b, {60, 40});
  ASSERT_TRUE(c.found()) << to_string(c.status);
  EXPECT_NEAR(c.uv_b.x(), 50.0, 1e-9);  // 60 - 50 px * 2 m / 10 m
  EXPECT_NEAR(c.uv_b.y(), 40.0, 1e-9);
  EXPECT_NEAR(c.depth_b, 10.0, 1e-12);
  // The world point: (u - cx) z / f along x, and y flipped by the nadir camera.
  EXPECT_NEAR(c.point_W.x(), 2.1, 1e-12);
  EXPECT_NEAR(c.point_W.y(), 1.9, 1e-12);
  EXPECT_NEAR(c.point_W.z(), 0.0, 1e-12);
}

TEST(TrueCorrespondence, HigherCameraSeesThePointNearerThePrincipalPoint) {
  FrameTruth a = nadir_frame({0, 0, 10}), b = nadir_frame({0, 0, 20});
  const Correspondence c = true_correspondence(a, b, {69.5, 29.5});  // 20 px right, 20 px up
  ASSERT_TRUE(c.found());
  EXPECT_NEAR(c.uv_b.x(), 59.5, 1e-9);
  EXPECT_NEAR(c.uv_b.y(), 39.5, 1e-9);
  EXPECT_NEAR(c.depth_b, 20.0, 1e-12);
}

TEST(TrueCorrespondence, OccluderNearerInBHidesThePoint) {
  const FrameTruth a = nadir_frame({0, 0, 10});
  FrameTruth b = nadir_frame({2, 0, 10});
  b.depth(cv::Rect(45, 35, 10, 10)).setTo(6.0);  // a box 4 m tall around B's pixel (50, 40)
  EXPECT_EQ(true_correspondence(a, b, {60, 40}).status, CorrespondenceStatus::Occluded);
  // Beside the box the plane is seen.
  EXPECT_TRUE(true_correspondence(a, b, {70, 40}).found());
}

TEST(TrueCorrespondence, DepthWithinToleranceIsVisibleBeyondItOccluded) {
  const FrameTruth a = nadir_frame({0, 0, 10});
  FrameTruth b = nadir_frame({2, 0, 10});
  CorrespondenceOptions o;  // 0.10 m + 2 % of 10 m = 0.30 m
  b.depth.at<float>(40, 50) = 9.75f;
  EXPECT_TRUE(true_correspondence(a, b, {60, 40}, o).found());
  b.depth.at<float>(40, 50) = 9.65f;
  EXPECT_EQ(true_correspondence(a, b, {60, 40}, o).status, CorrespondenceStatus::Occluded);
}

TEST(TrueCorrespondence, NoSurfaceOutsideImageAndBehindCameraHaveNoCorrespondence) {
  FrameTruth a = nadir_frame({0, 0, 10});
  const FrameTruth b = nadir_frame({2, 0, 10});
  EXPECT_EQ(true_correspondence(a, b, {5, 40}).status, CorrespondenceStatus::OutsideImage);  // u_b = -5
  a.depth.at<float>(40, 60) = 0;  // sky
  EXPECT_EQ(true_correspondence(a, b, {60, 40}).status, CorrespondenceStatus::NoDepth);
  EXPECT_EQ(true_correspondence(a, b, {60.3, 39.8}).status, CorrespondenceStatus::NoDepth);  // nearest pixel
  FrameTruth up = nadir_frame({2, 0, 10});
  up.pose = geometry::CameraPose{Eigen::Matrix3d::Identity(), {2, 0, 10}};  // optical axis up, away from the ground
  EXPECT_EQ(true_correspondence(nadir_frame({0, 0, 10}), up, {60, 40}).status,
            CorrespondenceStatus::BehindCamera);
  // No surface in B at the projection: nothing is seen there.
  FrameTruth sky_b = nadir_frame({2, 0, 10});
  sky_b.depth.setTo(0);
  EXPECT_EQ(true_correspondence(nadir_frame({0, 0, 10}), sky_b, {60, 40}).status,
            CorrespondenceStatus::Occluded);
}

TEST(TrueCorrespondence, RoundTripThroughDistortedYawedCamerasReturnsThePixel) {
  const geometry::Distortion dist{-0.2, 0.05, 0.001, -0.002, 0.01};
  const FrameTruth a = nadir_frame({0, 0, 10}, dist), b = nadir_frame({1.2, -0.7, 10}, dist, 0.3);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> px(20, 79);
  int found = 0;
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector2d uv(px(rng), px(rng));
    const Correspondence ab = true_correspondence(a, b, uv);
    if (!ab.found()) continue;
    ++found;
    const Correspondence ba = true_correspondence(b, a, ab.uv_b);
    ASSERT_TRUE(ba.found());
    EXPECT_NEAR((ba.uv_b - uv).norm(), 0.0, 1e-6) << uv.transpose();
    // The distortion is applied: the undistorted projection differs.
    const Eigen::Vector3d p_B = b.pose.centre().to_camera(ab.point_W);
    const Eigen::Vector2d pinhole(50 * p_B.x() / p_B.z() + 49.5, 50 * p_B.y() / p_B.z() + 49.5);
    if ((pinhole - Eigen::Vector2d(49.5, 49.5)).norm() > 30) {
      EXPECT_GT((pinhole - ab.uv_b).norm(), 0.5);
    }
  }
  EXPECT_GT(found, 120);
}

}  // namespace
}  // namespace wingman::frontend_bench
