#include <gtest/gtest.h>

#include <vector>

#include <Eigen/Dense>

#include "../numdiff.hpp"
#include "geometry/camera.hpp"
#include "geometry/chi2.hpp"
#include "geometry/rotation.hpp"

using namespace wingman::geometry;

TEST(Camera, PaperCameraProjectsThePrincipalRayToTheCentre) {
  PinholeCamera cam;  // paper defaults
  auto uv = cam.project({0, 0, 15});
  ASSERT_TRUE(uv);
  EXPECT_DOUBLE_EQ(uv->x(), 500.0);
  EXPECT_DOUBLE_EQ(uv->y(), 500.0);
  auto uv2 = cam.project({1.5, -3, 15});
  EXPECT_NEAR(uv2->x(), 200.1 * 0.1 + 500, 1e-12);
  EXPECT_NEAR(uv2->y(), 200.1 * -0.2 + 500, 1e-12);
  EXPECT_FALSE(cam.project({0, 0, -1}));
}

TEST(Camera, ProjectionJacobianMatchesNumericalWithDistortion) {
  PinholeCamera cam(210, 205, 480, 510, 1000, 1000, {-0.2, 0.05, 0.001, -0.002, 0.01});
  const Eigen::Vector3d p(2.0, -1.5, 12.0);
  Eigen::Matrix<double, 2, 3> J;
  cam.project(p, &J);
  auto f = [&](const Eigen::VectorXd& x) -> Eigen::VectorXd { return *cam.project(x); };
  EXPECT_LT((J - wingman::testing::numerical_jacobian(f, p)).norm(), 1e-6);
}

TEST(Camera, UndistortionInvertsDistortion) {
  PinholeCamera cam(200.1, 200.1, 500, 500, 1000, 1000, {-0.25, 0.07, 0.001, 0.0005, 0});
  const Eigen::Vector2d xn(0.8, -0.6);
  const Eigen::Vector2d uv = cam.distort_normalised(xn);
  EXPECT_LT((cam.unproject_normalised(uv) - xn).norm(), 1e-10);
}

TEST(Rotation, NadirAndGimbalErrorAreRotations) {
  for (const Eigen::Matrix3d& R : std::vector<Eigen::Matrix3d>{nadir_R_CW(), gimbal_error(0.04) * nadir_R_CW()}) {
    EXPECT_LT((R * R.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
  }
  // A nadir camera sees the ground below along +z of the camera.
  EXPECT_NEAR((nadir_R_CW() * Eigen::Vector3d(0, 0, -15)).z(), 15.0, 1e-12);
}

TEST(Chi2, QuantilesMatchTables) {
  EXPECT_NEAR(chi2_quantile(0.95, 1), 3.841459, 1e-5);
  EXPECT_NEAR(chi2_quantile(0.99, 2), 9.210340, 1e-5);
  EXPECT_NEAR(chi2_quantile(0.975, 18), 31.52638, 1e-4);
  EXPECT_NEAR(chi2_quantile(0.025, 18), 8.230746, 1e-4);
  EXPECT_NEAR(chi2_cdf(chi2_quantile(0.3, 900), 900), 0.3, 1e-9);
}
