// Ground-truth labels: correct correspondences are inliers; a wrong pixel, an occluded point and a
// wrong pixel pair are outliers; depth in metres (float) and millimetres (uint16) agree.
#include <gtest/gtest.h>

#include "vision/labelling.hpp"
#include "vision_test_support.hpp"

using namespace wingman::vision;
using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {
struct Scene {
  test::PlaneScene plane;
  CameraView a = test::view_at({0, 0, 15}), b = test::view_at({2, 1, 16}, 0.2);
  cv::Mat da = plane.depth(a), db = plane.depth(b);
  Scene() {
    // A 5 m tall box seen in b around pixel (100, 100): nearer than the ground there.
    db(cv::Rect(80, 80, 40, 40)).setTo(11.0f);
  }
};
}  // namespace

TEST(Labelling, CorrectObservationIsAnInlierAndWrongOnesAreOutliers) {
  const Scene s;
  const Vector3d p(1.0, -2.0, 0.0);
  const Vector2d uv = *s.b.camera.project(s.b.pose.to_camera(p));
  const auto ok = label_landmark_observation(p, uv + Vector2d(1, -1), s.b.camera, s.b.pose, s.db);
  EXPECT_EQ(ok.label, Label::Inlier);
  EXPECT_NEAR(ok.reprojection_px, std::sqrt(2.0), 1e-9);
  ASSERT_TRUE(ok.true_uv);
  EXPECT_LT((*ok.true_uv - uv).norm(), 1e-9);
  EXPECT_TRUE(ok.depth_consistent);

  const auto off = label_landmark_observation(p, uv + Vector2d(6, 8), s.b.camera, s.b.pose, s.db);
  EXPECT_EQ(off.label, Label::Outlier);
  EXPECT_NEAR(off.reprojection_px, 10.0, 1e-9);

  // A ground point whose true projection lies on the box: occluded.
  const Vector3d hidden = *test::PlaneScene::ground_point(s.b, {100, 100});
  const auto occ = label_landmark_observation(hidden, {100, 100}, s.b.camera, s.b.pose, s.db);
  EXPECT_EQ(occ.label, Label::Outlier);
  EXPECT_FALSE(occ.depth_consistent);
  // Without a depth image only the pixel distance counts.
  EXPECT_EQ(label_landmark_observation(hidden, {100, 100}, s.b.camera, s.b.pose, cv::Mat()).label, Label::Inlier);
  // Behind the camera.
  const auto behind = label_landmark_observation({0, 0, 30}, uv, s.b.camera, s.b.pose, s.db);
  EXPECT_EQ(behind.label, Label::Outlier);
  EXPECT_FALSE(behind.true_uv);
}

TEST(Labelling, PixelPairsAreLabelledThroughTheDepthOfTheFirstCamera) {
  const Scene s;
  const Vector2d ua(400, 300);
  const Vector3d p = *test::PlaneScene::ground_point(s.a, ua);
  const Vector2d ub = *s.b.camera.project(s.b.pose.to_camera(p));
  EXPECT_EQ(label_pixel_pair(ua, s.a.camera, s.a.pose, s.da, ub, s.b.camera, s.b.pose, s.db).label, Label::Inlier);
  const auto wrong = label_pixel_pair(ua, s.a.camera, s.a.pose, s.da, ub + Vector2d(4, 0), s.b.camera, s.b.pose, s.db);
  EXPECT_EQ(wrong.label, Label::Outlier);
  EXPECT_NEAR(wrong.reprojection_px, 4.0, 0.05);  // depth sampled at the nearest pixel centre
  ASSERT_TRUE(wrong.true_uv);  // b's true projection of a's pixel, whatever b's pixel was
  EXPECT_LT((*wrong.true_uv - ub).norm(), 0.05);

  // Millimetre depth gives the same answer.
  cv::Mat mm_a, mm_b;
  s.da.convertTo(mm_a, CV_16U, 1000.0);
  s.db.convertTo(mm_b, CV_16U, 1000.0);
  EXPECT_EQ(label_pixel_pair(ua, s.a.camera, s.a.pose, mm_a, ub, s.b.camera, s.b.pose, mm_b).label, Label::Inlier);
  EXPECT_THROW(label_pixel_pair(ua, s.a.camera, s.a.pose, cv::Mat(), ub, s.b.camera, s.b.pose, s.db),
               std::invalid_argument);
  const auto bp = back_project(ua, s.a.camera, s.a.pose, s.da);
  ASSERT_TRUE(bp);
  EXPECT_LT((*bp - p).norm(), 0.01);
}

// Under a rolling shutter a point's true projection is the one its own row's pose gives: the label
// follows the moving camera row by row, and back-projection uses the pixel's row.
TEST(Labelling, RollingShutterLabelsUseThePoseOfThePointsRow) {
  const Scene s;
  const auto& cam = s.a.camera;
  std::vector<wingman::geometry::CameraPose> rows;
  for (int r = 0; r < cam.height(); ++r) {
    wingman::geometry::CameraPose p = s.a.pose;
    p.position.x() += 0.02 * (r - (cam.height() - 1) / 2.0);  // 2 cm per row
    rows.push_back(p);
  }
  const wingman::geometry::FramePoses poses(s.a.pose, rows);
  const Vector3d p(3.0, 2.0, 0.0);
  const Vector2d centre_uv = *cam.project(s.a.pose.to_camera(p));
  const Vector2d row_uv = *cam.project(poses.to_camera(cam, p));
  ASSERT_GT((row_uv - centre_uv).norm(), 1.0);  // the shutter moves it
  const auto l = label_landmark_observation(p, row_uv, cam, poses, cv::Mat());
  EXPECT_EQ(l.label, Label::Inlier);
  EXPECT_LT(l.reprojection_px, 1e-6);
  EXPECT_EQ(label_landmark_observation(p, centre_uv, cam, poses, cv::Mat()).reprojection_px,
            (row_uv - centre_uv).norm());
  const cv::Mat depth(cam.height(), cam.width(), CV_32F, cv::Scalar(15.0f));
  const auto back = back_project(row_uv, cam, poses, depth);
  ASSERT_TRUE(back);
  EXPECT_LT((*back - p).norm(), 0.03);  // depth is sampled at the nearest pixel centre
}
