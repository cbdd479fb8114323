// Every analytic Jacobian of slam/ against central differences.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "../numdiff.hpp"
#include "geometry/rotation.hpp"
#include "slam/inverse_depth.hpp"
#include "slam/landmark_init.hpp"
#include "slam/measurement_models.hpp"

using namespace wingman;
using namespace wingman::slam;
using wingman::testing::numerical_jacobian;

namespace {
CameraRig tilted_rig(bool distorted) {
  CameraRig r;
  r.model = distorted ? geometry::PinholeCamera(200.1, 200.1, 500, 500, 1000, 1000,
                                                {-0.1, 0.02, 0.001, -0.001, 0})
                      : geometry::PinholeCamera();
  r.R_CW = geometry::gimbal_error(0.03) * geometry::nadir_R_CW();
  return r;
}
constexpr double kTol = 1e-5;
}  // namespace

class JacobianTest : public ::testing::TestWithParam<bool> {};

TEST_P(JacobianTest, LandmarkProjectionEq3And4) {
  const CameraRig rig = tilted_rig(GetParam());
  const Eigen::Vector3d x_c(1, 2, 15), x_a(4, -3, 0.5);
  Eigen::Matrix<double, 2, 3> J_xc, J_xa;
  ASSERT_TRUE(project_point(rig, x_c, x_a, &J_xc, &J_xa));
  auto f_c = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return *project_point(rig, v, x_a); };
  auto f_a = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return *project_point(rig, x_c, v); };
  EXPECT_LT((J_xc - numerical_jacobian(f_c, x_c)).norm(), kTol);
  EXPECT_LT((J_xa - numerical_jacobian(f_a, x_a)).norm(), kTol);
}

TEST_P(JacobianTest, InverseDepthProjection) {
  const CameraRig rig = tilted_rig(GetParam());
  const Eigen::Vector3d x_c(1, 2, 15);
  Vector6d y;
  y << 0.5, 1.5, 14.0, 0.2, -0.15, 0.07;
  Eigen::Matrix<double, 2, 3> J_xc;
  Eigen::Matrix<double, 2, 6> J_y;
  ASSERT_TRUE(project_inverse_depth(rig, x_c, y, &J_xc, &J_y));
  auto f_c = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return *project_inverse_depth(rig, v, y); };
  auto f_y = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
    return *project_inverse_depth(rig, x_c, Vector6d(v));
  };
  EXPECT_LT((J_xc - numerical_jacobian(f_c, x_c)).norm(), kTol);
  EXPECT_LT((J_y - numerical_jacobian(f_y, y)).norm(), kTol);
}

TEST_P(JacobianTest, TriangulationEq52) {
  const CameraRig rig = tilted_rig(GetParam());
  const Eigen::Vector3d xa(-1.5, 0, 15), xb(1.5, 0.3, 17), p(3, -4, 0.7);
  const Eigen::Vector2d ua = *project_point(rig, xa, p) + Eigen::Vector2d(1.2, -0.7);
  const Eigen::Vector2d ub = *project_point(rig, xb, p) + Eigen::Vector2d(-0.4, 2.1);
  auto t = triangulate_two_views(rig, xa, ua, rig, xb, ub);
  ASSERT_TRUE(t);
  Eigen::VectorXd params(10);
  params << xa, xb, ua, ub;
  auto f = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
    return triangulate_two_views(rig, v.segment<3>(0), v.segment<2>(6), rig, v.segment<3>(3),
                                 v.segment<2>(8))
        ->point;
  };
  EXPECT_LT((t->J - numerical_jacobian(f, params)).norm(), 1e-5 * t->J.norm());
}

TEST_P(JacobianTest, InverseDepthFromPixel) {
  const CameraRig rig = tilted_rig(GetParam());
  const Eigen::Vector3d x_c(1, 2, 15);
  const Eigen::Vector2d uv(620, 310);
  Eigen::Matrix<double, 6, 5> J;
  inverse_depth_from_pixel(rig, x_c, uv, 0.05, &J);
  Eigen::VectorXd params(5);
  params << x_c, uv;
  auto f = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
    return inverse_depth_from_pixel(rig, v.head<3>(), v.tail<2>(), 0.05);
  };
  EXPECT_LT((J - numerical_jacobian(f, params)).norm(), kTol);
}

INSTANTIATE_TEST_SUITE_P(WithAndWithoutDistortion, JacobianTest, ::testing::Bool());

TEST(Jacobians, InverseDepthToPointAndAngles) {
  Vector6d y;
  y << 0.5, 1.5, 14.0, 0.3, -0.2, 0.08;
  Eigen::Matrix<double, 3, 6> J;
  inverse_depth_to_point(y, &J);
  auto f = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return inverse_depth_to_point(Vector6d(v)); };
  EXPECT_LT((J - numerical_jacobian(f, y)).norm(), kTol);

  const Eigen::Vector3d ray(0.3, -0.2, -1.0);
  Eigen::Matrix<double, 2, 3> Ja;
  inverse_depth_angles(ray, &Ja);
  auto g = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return inverse_depth_angles(v); };
  EXPECT_LT((Ja - numerical_jacobian(g, ray)).norm(), kTol);
  // The angles give back the ray's direction.
  const Eigen::Vector2d a = inverse_depth_angles(ray);
  EXPECT_LT((inverse_depth_direction(a(0), a(1)) - ray.normalized()).norm(), 1e-12);
}

TEST(Jacobians, RangeEq9) {
  const Eigen::Vector3d xh(1, 2, 0.5), xq(-0.5, 2.5, 15);
  Eigen::Matrix<double, 1, 3> Jh, Jq;
  range_model(xh, xq, &Jh, &Jq);
  auto fh = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
    return Eigen::VectorXd::Constant(1, range_model(v, xq));
  };
  auto fq = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
    return Eigen::VectorXd::Constant(1, range_model(xh, v));
  };
  EXPECT_LT((Jh - numerical_jacobian(fh, xh)).norm(), kTol);
  EXPECT_LT((Jq - numerical_jacobian(fq, xq)).norm(), kTol);
}

// The builders' block Jacobians, assembled into a dense H, against differentiation of h(x) over
// the whole state: checks the block placement too, with and without estimated gimbal errors.
class BuilderTest : public ::testing::TestWithParam<bool> {
 protected:
  // Lead and two UAVs moving along x, P = I; nonzero gimbal errors when the state holds them.
  static FilterState two_uav_state(bool gimbal_states) {
    FilterState s(2, gimbal_states);
    s.x.head<18>() << 0.3, -0.2, 0.1, 1, 0, 0,  //
        -1.4, 0.1, 15.2, 1, 0, 0,                //
        1.6, -0.1, 16.9, 1, 0, 0;
    if (gimbal_states) s.x.segment<4>(s.gimbal(0)) << 0.03, -0.02, -0.01, 0.04;
    s.P.setIdentity();
    return s;
  }
  // Camera 0's and camera 1's pixels of X as the filter predicts them: rays that meet, as real
  // matches nearly do. (Least-squares triangulation of rays that miss each other weighs them
  // algebraically, and there a rotation and the equivalent pixel shift agree only to first order.)
  static std::pair<Eigen::Vector2d, Eigen::Vector2d> predicted_pair(const FilterState& s, const CameraRig& rig,
                                                                   const Eigen::Vector3d& X) {
    return {*project_point(estimated_rig(s.x, s.gimbal(0), rig), s.x.segment<3>(FilterState::cam_pos(0)), X),
            *project_point(estimated_rig(s.x, s.gimbal(1), rig), s.x.segment<3>(FilterState::cam_pos(1)), X)};
  }
  // Cooperative initialisation that accepts any pair, so the tests see the covariance of each.
  static InitialisationSettings accept_any_pair() {
    InitialisationSettings c;
    c.min_parallax_deg = 0;
    c.max_reprojection_px = 1e9;
    return c;
  }
};

TEST_P(BuilderTest, MeasurementBuildersPlaceTheirBlocks) {
  FilterState s = two_uav_state(GetParam());
  const CameraRig rig = tilted_rig(true);
  s.add_landmark(LandmarkKind::Euclidean, Eigen::Vector3d(3, -2, 0.4), Eigen::MatrixXd::Zero(3, s.dim()),
                 Eigen::Matrix3d::Identity());
  Vector6d y;
  y << 1.6, -0.1, 16.9, 0.1, 0.05, 0.06;
  s.add_landmark(LandmarkKind::InverseDepth, y, Eigen::MatrixXd::Zero(6, s.dim()),
                 Eigen::Matrix<double, 6, 6>::Identity());
  // A landmark anchored in camera 0 with camera 1's pixel offset after its point.
  Eigen::VectorXd with_offset(5);
  with_offset << -2, 1.5, 0.2, 0.7, -0.4;
  s.add_landmark(LandmarkKind::Euclidean, with_offset, Eigen::MatrixXd::Zero(5, s.dim()),
                 Eigen::MatrixXd::Identity(5, 5), {0, 0b10, 0.75});

  auto dense = [&](const Measurement& m) {
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(m.dim(), s.dim());
    for (const auto& b : m.blocks) H.middleCols(b.col, b.H.cols()) += b.H;
    return H;
  };
  using Builder = std::function<Measurement(const FilterState&)>;
  const std::vector<Builder> builders = {
      [&](const FilterState& st) { return *landmark_measurement(st, st.landmarks()[0], 1, rig, {0, 0}, 3); },
      [&](const FilterState& st) { return *landmark_measurement(st, st.landmarks()[1], 0, rig, {0, 0}, 3); },
      [&](const FilterState& st) { return *landmark_measurement(st, st.landmarks()[2], 1, rig, {0, 0}, 3); },
      [&](const FilterState& st) { return *landmark_measurement(st, st.landmarks()[2], 0, rig, {0, 0}, 3); },
      [&](const FilterState& st) { return *lead_projection_measurement(st, 0, rig, {0, 0}, 3); },
      [&](const FilterState& st) { return gps_measurement(st, Eigen::Vector3d::Zero(), 1.5); },
      [&](const FilterState& st) { return altimeter_measurement(st, 1, rig, 0, 0.5); },
      [&](const FilterState& st) { return range_measurement(st, 0, rig, 0, 0.5); },
  };
  for (size_t i = 0; i < builders.size(); ++i) {
    const Measurement m = builders[i](s);
    auto h = [&](const Eigen::VectorXd& x) -> Eigen::VectorXd {
      FilterState t = s;
      t.x = x;
      return builders[i](t).h;
    };
    EXPECT_LT((dense(m) - numerical_jacobian(h, s.x)).norm(), kTol) << "builder " << i;
    if (i < 4) {  // the landmark builders predict what the frontend is told to search around
      const auto& lm = s.landmarks()[i == 0 ? 0 : i == 1 ? 1 : 2];
      const int cam = (i == 0 || i == 2) ? 1 : 0;
      EXPECT_LT((*predict_landmark_pixel(s, s.x, lm, cam, rig) - m.h).norm(), 1e-9) << "builder " << i;
    }
    // An estimated gimbal error is a state, not noise: nothing left to marginalise.
    if (GetParam()) {
      EXPECT_EQ(m.camera, -1) << "builder " << i;
    }
  }
}

// eq. 52 with estimated gimbal errors: with P = I, a new landmark's cross-covariance with the
// state is its Jacobian with respect to the state, which must match re-initialising the landmark
// from perturbed states (camera positions and gimbal angles alike).
TEST_P(BuilderTest, NewLandmarkCrossCovarianceIsItsStateJacobian) {
  FilterState s = two_uav_state(GetParam());
  const CameraRig rig = tilted_rig(true);
  const auto [uv_a, uv_b] = predicted_pair(s, rig, Eigen::Vector3d(3, -2, 0.4));
  const Eigen::Vector2d uv_c(420.5, 610.1);
  const InitialisationSettings coop = accept_any_pair();
  const MeasurementNoiseSettings noise;

  using Init = std::function<Eigen::VectorXd(FilterState&)>;
  const std::vector<std::pair<const char*, Init>> inits = {
      {"cooperative",
       [&](FilterState& st) {
         auto r = initialise_cooperative(st, 0, rig, uv_a, 1, rig, uv_b, coop, noise);
         EXPECT_TRUE(r.id.has_value()) << r.rejected_because;
         return Eigen::VectorXd(st.x.tail(3));
       }},
      {"inverse depth",
       [&](FilterState& st) {
         auto r = initialise_inverse_depth(st, 1, rig, uv_c, coop, noise);
         EXPECT_TRUE(r.id.has_value()) << r.rejected_because;
         return Eigen::VectorXd(st.x.tail(6));
       }},
  };
  for (const auto& [name, init] : inits) {
    FilterState t = s;
    const Eigen::VectorXd value = init(t);
    const int d = static_cast<int>(value.size());
    const Eigen::MatrixXd cross = t.P.block(s.dim(), 0, d, s.dim());
    auto f = [&](const Eigen::VectorXd& x) -> Eigen::VectorXd {
      FilterState u = s;
      u.x = x;
      return init(u);
    };
    EXPECT_LT((cross - numerical_jacobian(f, s.x)).norm(), kTol) << name;
  }
}

INSTANTIATE_TEST_SUITE_P(WithAndWithoutGimbalStates, BuilderTest, ::testing::Bool());

// Cooperative initialisation with pixel offsets: camera b's pixel is taken with its offset o_b,
// so the point and o_b start correlated by -sigma^2 d point / d uv_b, the point's covariance
// grows by sigma^2 J J^T, and the offsets do not depend on the state.
TEST_P(BuilderTest, CooperativeLandmarkWithPixelOffsetsCarriesTheirCovariance) {
  const FilterState s = two_uav_state(GetParam());
  const CameraRig rig = tilted_rig(true);
  const auto [uv_a, uv_b] = predicted_pair(s, rig, Eigen::Vector3d(3, -2, 0.4));
  const InitialisationSettings coop = accept_any_pair();
  MeasurementNoiseSettings noise;
  FilterState plain = s;
  ASSERT_TRUE(initialise_cooperative(plain, 0, rig, uv_a, 1, rig, uv_b, coop, noise).id);
  noise.pixel_offset_sigma = 0.75;
  FilterState t = s;
  ASSERT_TRUE(initialise_cooperative(t, 0, rig, uv_a, 1, rig, uv_b, coop, noise).id);
  const LandmarkSlot& lm = t.landmarks().back();
  ASSERT_EQ(lm.dim(), 5);
  ASSERT_EQ(lm.offsets.anchor_cam, 0);
  EXPECT_EQ(lm.pixel_offset(0), -1);
  const int o = lm.pixel_offset(1);
  ASSERT_EQ(o, lm.offset + 3);
  EXPECT_LT((t.x.segment<3>(lm.offset) - plain.x.tail<3>()).norm(), 1e-12);
  EXPECT_EQ(t.x.segment<2>(o), Eigen::Vector2d::Zero());

  // d point / d uv_b by re-triangulating from shifted pixels.
  auto point_from = [&](const Eigen::VectorXd& uv) -> Eigen::VectorXd {
    FilterState u = s;
    MeasurementNoiseSettings white = noise;
    white.pixel_offset_sigma = 0;
    EXPECT_TRUE(initialise_cooperative(u, 0, rig, uv_a, 1, rig, uv, coop, white).id);
    return u.x.tail<3>();
  };
  const Eigen::MatrixXd Jb = numerical_jacobian(point_from, Eigen::VectorXd(uv_b));
  const double var = 0.75 * 0.75;
  const int n = s.dim(), p = lm.offset;
  EXPECT_LT((t.P.block(p, 0, 3, n) - plain.P.block(n, 0, 3, n)).norm(), 1e-9);  // cross with the state
  EXPECT_LT(t.P.block(o, 0, 2, n).norm(), 1e-12);
  EXPECT_LT((t.P.block<2, 2>(o, o) - var * Eigen::Matrix2d::Identity()).norm(), 1e-12);
  EXPECT_LT((t.P.block(p, o, 3, 2) + var * Jb).norm(), 1e-4 * var * Jb.norm());
  EXPECT_LT((t.P.block(p, p, 3, 3) - plain.P.block(n, n, 3, 3) - var * Jb * Jb.transpose()).norm(),
            1e-4 * var * (Jb * Jb.transpose()).norm());
  // Still a covariance.
  const Eigen::MatrixXd Pn = t.P;
  EXPECT_LT((Pn - Pn.transpose()).norm(), 1e-12);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Pn).eigenvalues().minCoeff(), 0.0);
}
