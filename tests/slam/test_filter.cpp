// The filter's pieces against their textbook dense forms and known answers.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "geometry/rotation.hpp"
#include "slam/ekf_update.hpp"
#include "slam/estimator.hpp"
#include "slam/inverse_depth.hpp"
#include "slam/landmark_init.hpp"
#include "slam/motion_model.hpp"

using namespace wingman;
using namespace wingman::slam;

namespace {
Eigen::MatrixXd random_spd(int n, std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < A.size(); ++i) A.data()[i] = g(rng);
  return A * A.transpose() / n + 0.1 * Eigen::MatrixXd::Identity(n, n);
}
// A random mean and a random symmetric positive semi-definite P, so that a prediction's every
// block is exercised.
void randomise_state(FilterState& s, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n;
  const Eigen::MatrixXd A = Eigen::MatrixXd::NullaryExpr(s.dim(), s.dim(), [&] { return n(rng); });
  s.P = A * A.transpose();
  s.x = Eigen::VectorXd::NullaryExpr(s.dim(), [&] { return n(rng); });
}
CameraRig nadir_rig() {
  CameraRig r;
  r.R_CW = geometry::nadir_R_CW();
  return r;
}
FilterState two_camera_state_with_landmarks(int n_landmarks, std::mt19937_64& rng) {
  FilterState s(2);
  s.x << 0, 0, 0, 1, 0, 0, -1.5, 0, 15, 1, 0, 0, 1.5, 0, 17, 1, 0, 0;
  std::uniform_real_distribution<double> u(-20, 20);
  for (int i = 0; i < n_landmarks; ++i)
    s.add_landmark(LandmarkKind::Euclidean, Eigen::Vector3d(u(rng), u(rng), 0.1 * u(rng)),
                   Eigen::MatrixXd::Zero(3, s.dim()), Eigen::Matrix3d::Zero());
  s.P = random_spd(s.dim(), rng) * 0.01;
  return s;
}
}  // namespace

TEST(Prediction, EqualsDenseAPAtPlusQ) {
  for (const double sc : {0.0, 0.25}) {
  SCOPED_TRACE("common sigma " + std::to_string(sc));
  std::mt19937_64 rng(3);
  FilterState s = two_camera_state_with_landmarks(4, rng);
  const FilterState before = s;
  const double dt = 0.1, sl = 0.2, su = 0.3;
  predict_constant_velocity(s, dt, sl, su, sc);
  const int n = s.dim();
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(n, n), Q = Eigen::MatrixXd::Zero(n, n);
  // The acceleration noise of agent a is w_a + w_common: G = [W_lead 0 0 W; 0 W_uav1 0 W; ...].
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(n, 12), Qw = Eigen::MatrixXd::Zero(12, 12);
  for (int a = 0; a < 3; ++a) {
    const int p = 6 * a;
    A.block<3, 3>(p, p + 3) = dt * Eigen::Matrix3d::Identity();
    G.block<3, 3>(p + 3, 3 * a) = G.block<3, 3>(p + 3, 9) = dt * Eigen::Matrix3d::Identity();
    Qw.block<3, 3>(3 * a, 3 * a) = std::pow(a == 0 ? sl : su, 2) * Eigen::Matrix3d::Identity();
  }
  Qw.block<3, 3>(9, 9) = sc * sc * Eigen::Matrix3d::Identity();
  Q = G * Qw * G.transpose();
  EXPECT_LT((s.x - A * before.x).norm(), 1e-12);
  EXPECT_LT((s.P - (A * before.P * A.transpose() + Q)).norm(), 1e-12);
  }
}

// The gimbal errors' Gauss-Markov prediction equals the dense F P F^T + Q, and with no
// measurement their variance tends to the stationary sigma^2.
TEST(Prediction, GimbalErrorIsGaussMarkov) {
  FilterState s(2, true);
  randomise_state(s, 3);
  const double dt = 0.1, sigma = 0.04, tau = 5;
  const double phi = std::exp(-dt / tau);
  Eigen::MatrixXd F = Eigen::MatrixXd::Identity(s.dim(), s.dim());
  Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(s.dim(), s.dim());
  for (int j = 0; j < 2; ++j)
    for (int k = 0; k < 2; ++k) {
      F(s.gimbal(j) + k, s.gimbal(j) + k) = phi;
      Q(s.gimbal(j) + k, s.gimbal(j) + k) = (1 - phi * phi) * sigma * sigma;
    }
  const Eigen::VectorXd x_dense = F * s.x;
  const Eigen::MatrixXd P_dense = F * s.P * F.transpose() + Q;
  for (int j = 0; j < 2; ++j) predict_gimbal_error(s, j, dt, sigma, tau);
  EXPECT_LT((s.x - x_dense).norm(), 1e-12);
  EXPECT_LT((s.P - P_dense).norm(), 1e-10);

  for (int k = 0; k < 2000; ++k) predict_gimbal_error(s, 0, dt, sigma, tau);
  EXPECT_NEAR(s.P(s.gimbal(0), s.gimbal(0)), sigma * sigma, 1e-6);
  EXPECT_NEAR(s.P(s.gimbal(0), s.gimbal(0) + 1), 0.0, 1e-6);
  EXPECT_EQ(FilterState(2).gimbal(0), -1);
}

// The shared acceleration's prediction equals the dense F P F^T + Q of the Singer model (every
// agent's position gains dt^2/2 a, its velocity dt a; a is Gauss-Markov), with landmarks and
// gimbal states in the state too; its variance tends to sigma^2 and P stays symmetric.
TEST(Prediction, CommonAccelerationIsSingerForEveryAgent) {
  FilterState s(2, true, true);
  ASSERT_EQ(s.common_acceleration(), s.kinematic_dim() + 4);
  ASSERT_EQ(s.agent_dim(), s.kinematic_dim() + 4 + 3);
  s.add_landmark(LandmarkKind::Euclidean, Eigen::Vector3d(1, 2, 0), Eigen::MatrixXd::Zero(3, s.dim()),
                 Eigen::Matrix3d::Identity());
  randomise_state(s, 4);
  const double dt = 0.1, sigma = 0.05, tau = 60;
  const double phi = std::exp(-dt / tau);
  const int a = s.common_acceleration();
  Eigen::MatrixXd F = Eigen::MatrixXd::Identity(s.dim(), s.dim());
  Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(s.dim(), s.dim());
  for (int agent = 0; agent < 3; ++agent) {
    const int p = 6 * agent;
    F.block<3, 3>(p, a) = 0.5 * dt * dt * Eigen::Matrix3d::Identity();
    F.block<3, 3>(p + 3, a) = dt * Eigen::Matrix3d::Identity();
  }
  F.block<3, 3>(a, a) = phi * Eigen::Matrix3d::Identity();
  Q.block<3, 3>(a, a) = (1 - phi * phi) * sigma * sigma * Eigen::Matrix3d::Identity();
  const Eigen::VectorXd x_dense = F * s.x;
  const Eigen::MatrixXd P_dense = F * s.P * F.transpose() + Q;
  predict_common_acceleration(s, dt, sigma, tau);
  EXPECT_LT((s.x - x_dense).norm(), 1e-12);
  EXPECT_LT((s.P - P_dense).norm(), 1e-10);
  EXPECT_LT((s.P - s.P.transpose()).norm(), 1e-10);

  for (int k = 0; k < 20000; ++k) predict_common_acceleration(s, dt, sigma, tau);
  EXPECT_NEAR(s.P(a, a), sigma * sigma, 1e-6);
  EXPECT_EQ(FilterState(2, true).common_acceleration(), -1);
  FilterState none(1);
  const FilterState before = none;
  predict_common_acceleration(none, dt, sigma, tau);  // no such state: nothing happens
  EXPECT_EQ((none.P - before.P).norm(), 0.0);
}

// The update processes one camera's projections at a time when they share the gimbal's noise,
// and otherwise independent measurements a few dozen rows at a time (here 84 rows: two blocks),
// each block linearised at the prior: the result is the joint Kalman update of eq. 43-45 over all
// of them, with the gimbal noise correlating each camera's projections.
TEST(Update, BlocksInTurnEqualTheDenseJointKalmanUpdate) {
  for (const double orientation_sigma : {0.0, 0.02}) {
  SCOPED_TRACE("orientation sigma " + std::to_string(orientation_sigma));
  std::mt19937_64 rng(5);
  FilterState s = two_camera_state_with_landmarks(40, rng);
  const FilterState before = s;
  CameraRig rig = nadir_rig();
  rig.orientation_sigma = orientation_sigma;
  std::vector<Measurement> ms;
  ms.push_back(gps_measurement(s, Eigen::Vector3d(0.5, -0.3, 0.2), 1.5));
  for (int i = 0; i < 40; ++i) {  // the cameras interleaved: 0, 1, 0, 1, ...
    auto uv = predict_landmark_pixel(s, s.x, s.landmarks()[i], i % 2, rig);
    ASSERT_TRUE(uv);
    ms.push_back(*landmark_measurement(s, s.landmarks()[i], i % 2, rig, *uv + Eigen::Vector2d(2, -1), 3));
  }
  ms.push_back(range_measurement(s, 0, rig, 15.5, 0.5));
  std::vector<const Measurement*> ptrs;
  for (const auto& m : ms) ptrs.push_back(&m);
  ASSERT_TRUE(ekf_update(s, ptrs));

  // Dense reference: eq. 43-45, R with V V^T sigma^2 between any two projections of a camera.
  int rows = 0;
  for (const auto& m : ms) rows += m.dim();
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(rows, before.dim()), R = Eigen::MatrixXd::Zero(rows, rows);
  Eigen::VectorXd y(rows);
  int r = 0;
  for (const auto& m : ms) {
    for (const auto& b : m.blocks) H.block(r, b.col, m.dim(), b.H.cols()) += b.H;
    R.block(r, r, m.dim(), m.dim()) = m.R;
    y.segment(r, m.dim()) = m.innovation();
    int c = 0;
    for (const auto& o : ms) {
      if (m.camera >= 0 && o.camera == m.camera)
        R.block(r, c, m.dim(), o.dim()) += m.orientation_sigma * m.orientation_sigma * m.V * o.V.transpose();
      c += o.dim();
    }
    r += m.dim();
  }
  if (orientation_sigma > 0) {
    EXPECT_GT(R.block(3, 7, 2, 2).norm(), 0.0);  // camera 0's first two projections
  }
  const Eigen::MatrixXd S = H * before.P * H.transpose() + R;
  const Eigen::MatrixXd K = before.P * H.transpose() * S.inverse();
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(before.dim(), before.dim());
  EXPECT_LT((s.x - (before.x + K * y)).norm(), 1e-9);
  EXPECT_LT((s.P - (I - K * H) * before.P).norm(), 1e-9);
  EXPECT_EQ((s.P - s.P.transpose()).norm(), 0.0);
  }
}

// A block whose innovation covariance is not positive definite leaves the whole state as it was,
// the blocks before it included.
TEST(Update, AFailingBlockLeavesTheStateUnchanged) {
  std::mt19937_64 rng(6);
  FilterState s = two_camera_state_with_landmarks(2, rng);
  const FilterState before = s;
  const CameraRig rig = nadir_rig();
  auto uv = predict_landmark_pixel(s, s.x, s.landmarks()[0], 0, rig);
  ASSERT_TRUE(uv);
  const Measurement good = *landmark_measurement(s, s.landmarks()[0], 0, rig, *uv + Eigen::Vector2d(1, 1), 3);
  Measurement bad = gps_measurement(s, Eigen::Vector3d(0.5, -0.3, 0.2), 1.5);
  bad.R = -1e6 * SmallSq::Identity(3, 3);
  ASSERT_FALSE(ekf_update(s, {&good, &bad}));
  EXPECT_EQ((s.x - before.x).norm(), 0.0);
  EXPECT_EQ((s.P - before.P).norm(), 0.0);
}

TEST(Triangulation, RecoversAKnownPoint) {
  const CameraRig rig = nadir_rig();
  const Eigen::Vector3d xa(-1.5, 0, 15), xb(1.5, 0, 17), p(7.3, -12.1, 0.8);
  auto t = triangulate_two_views(rig, xa, *project_point(rig, xa, p), rig, xb, *project_point(rig, xb, p));
  ASSERT_TRUE(t);
  EXPECT_LT((t->point - p).norm(), 1e-9);
  EXPECT_LT(t->reprojection_px, 1e-9);
  EXPECT_NEAR(t->parallax_rad, std::acos((xa - p).normalized().dot((xb - p).normalized())), 1e-12);
}

TEST(InverseDepth, ConversionToXyzIsExactForANoiselessPoint) {
  const CameraRig rig = nadir_rig();
  const Eigen::Vector3d x_c(2, -1, 15), p(9.5, 4.2, 0.6);
  const Eigen::Vector2d uv = *project_point(rig, x_c, p);
  const double depth = (p - x_c).norm();
  const Vector6d y = inverse_depth_from_pixel(rig, x_c, uv, 1.0 / depth);
  EXPECT_LT((inverse_depth_to_point(y) - p).norm(), 1e-10);

  // In the state: the converted landmark has the same position and covariance J P J^T.
  FilterState s(1);
  s.P.setIdentity();
  Eigen::Matrix<double, 6, 6> C = Eigen::Matrix<double, 6, 6>::Identity() * 1e-4;
  C(5, 5) = 1e-6;
  const LandmarkId id = s.add_landmark(LandmarkKind::InverseDepth, y, Eigen::MatrixXd::Zero(6, 12), C);
  Eigen::Matrix<double, 3, 6> J;
  const Eigen::Vector3d q = inverse_depth_to_point(y, &J);
  s.convert_to_euclidean(id, q, J);
  EXPECT_EQ(s.dim(), 15);
  EXPECT_LT((s.x.tail<3>() - p).norm(), 1e-10);
  EXPECT_LT((s.P.bottomRightCorner<3, 3>() - J * C * J.transpose()).norm(), 1e-15);
}

TEST(InverseDepth, LinearityIndexFallsWithParallax) {
  const Eigen::Vector3d x0(0, 0, 15), p(0, 0, 0);
  Vector6d y;
  y << x0, 0, 0, 1.0 / 15;
  // Seen again from the anchor: no parallax, L large; from 10 m away, much smaller.
  EXPECT_GT(linearity_index(y, 0.02, x0), linearity_index(y, 0.02, Eigen::Vector3d(10, 0, 15)));
}

TEST(Landmarks, RemoveKeepsTheOtherBlocks) {
  std::mt19937_64 rng(9);
  FilterState s = two_camera_state_with_landmarks(3, rng);
  const FilterState before = s;
  s.remove_landmark(s.landmarks()[1].id);
  ASSERT_EQ(s.dim(), before.dim() - 3);
  EXPECT_EQ(s.landmarks()[1].offset, 21);
  EXPECT_LT((s.P.topLeftCorner(21, 21) - before.P.topLeftCorner(21, 21)).norm(), 1e-15);
  EXPECT_LT((s.P.block<3, 3>(21, 21) - before.P.block<3, 3>(24, 24)).norm(), 1e-15);
  EXPECT_LT((s.P.block<3, 21>(21, 0) - before.P.block<3, 21>(24, 0)).norm(), 1e-15);
}

namespace {
// Two UAVs over a grid of landmarks initialised cooperatively from exact pixels.
struct Scene {
  std::vector<Eigen::Vector3d> points;
  std::vector<LandmarkId> ids;
  Estimator est;
  Scene(bool ransac)
      : est({nadir_rig(), nadir_rig()}, {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()},
            {{Eigen::Vector3d(-1.5, 0, 15), Eigen::Vector3d::Zero()},
             {Eigen::Vector3d(1.5, 0, 17), Eigen::Vector3d::Zero()}},
            settings(ransac)) {
    const CameraRig rig = nadir_rig();
    for (int i = -2; i <= 2; ++i)
      for (int j = -2; j <= 2; ++j) {
        const Eigen::Vector3d p(6.0 * i, 6.0 * j, 0.3 * ((i + j) % 2));
        auto o = est.initialise_from_matches({{0, 1, *project_point(rig, est.camera_position(0), p),
                                               *project_point(rig, est.camera_position(1), p)}});
        points.push_back(p);
        ids.push_back(*o[0].id);
      }
  }
  // A filter with white process and gimbal noise and the narrow gates these scenes were
  // built for, rather than the shipped scenes' tuning.
  static EstimatorSettings settings(bool ransac) {
    EstimatorSettings s;
    s.process_noise.accel_sigma_common = 0;
    s.measurement_noise.orientation_sigma = 0;
    s.measurement_noise.orientation_time_constant = 0;
    s.gating.one_point_ransac = ransac;
    s.gating.ransac_inlier_px = 4;
    s.initialisation.min_parallax_deg = 3;
    s.initialisation.low_parallax_inverse_depth = false;
    s.initial_sigma.position = 0.3;
    return s;
  }
};
}  // namespace

class OutlierTest : public ::testing::TestWithParam<bool> {};

TEST_P(OutlierTest, AFarOutlierIsRejectedAndInliersAccepted) {
  Scene sc(GetParam());
  ASSERT_EQ(sc.est.num_landmarks(), 25);
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0, 1.0);
  std::vector<Correspondence> cands;
  const CameraRig rig = nadir_rig();
  for (size_t i = 0; i < sc.points.size(); ++i) {
    Eigen::Vector2d uv = *project_point(rig, sc.est.camera_position(0), sc.points[i]);
    uv += Eigen::Vector2d(noise(rng), noise(rng));
    if (i == 7) uv += Eigen::Vector2d(60, -45);  // a mismatch 75 px away
    cands.push_back({0, sc.ids[i], uv});
  }
  const auto r = sc.est.update_visual(cands);
  EXPECT_FALSE(r.accepted[7]);
  int accepted = 0;
  for (bool a : r.accepted) accepted += a;
  EXPECT_EQ(accepted, 24);
}

INSTANTIATE_TEST_SUITE_P(GateAndRansac, OutlierTest, ::testing::Bool());

TEST(Estimator, CooperativeInitialisationCarriesCrossCovariance) {
  Scene sc(true);
  const auto& s = sc.est.state();
  const auto* lm = s.find(sc.ids[0]);
  // Correlated with both cameras (eq. 52), and its own covariance positive definite.
  const double c0 = s.P.block(lm->offset, FilterState::cam_pos(0), 3, 3).norm();
  const double c1 = s.P.block(lm->offset, FilterState::cam_pos(1), 3, 3).norm();
  EXPECT_GT(c0, 1e-3);
  EXPECT_GT(c1, 1e-3);
  Eigen::LLT<Eigen::MatrixXd> llt(s.P);
  EXPECT_EQ(llt.info(), Eigen::Success);
}

TEST(Estimator, MapCapEvictsLandmarksOutOfView) {
  EstimatorSettings cfg = Scene::settings(true);
  cfg.map.max_landmarks = 5;
  Estimator est({nadir_rig(), nadir_rig()}, {}, {{Eigen::Vector3d(-1.5, 0, 15), Eigen::Vector3d::Zero()}, {Eigen::Vector3d(1.5, 0, 17), Eigen::Vector3d::Zero()}}, cfg);
  const CameraRig rig = nadir_rig();
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d p(3.0 * i - 10, 2.0, 0);
    est.initialise_from_matches({{0, 1, *project_point(rig, est.camera_position(0), p),
                                  *project_point(rig, est.camera_position(1), p)}});
  }
  // No camera expected any landmark this step, so the oldest were evicted to keep the cap.
  EXPECT_EQ(est.num_landmarks(), 5);
  EXPECT_EQ(est.end_step().size(), 3u);
}

// A wrong cooperative pair along the epipolar line triangulates just under the cameras (the
// rendered paper scene's were 2-4 m under them); min_depth_m turns such a point away and keeps
// a ground point 15 m down.
TEST(Estimator, MinDepthRejectsAPointJustUnderTheCameras) {
  const CameraRig rig = nadir_rig();
  auto run = [&](double min_depth, const Eigen::Vector3d& p) {
    EstimatorSettings cfg = Scene::settings(true);
    cfg.initialisation.min_depth_m = min_depth;
    Estimator est({rig, rig}, {}, {{Eigen::Vector3d(-1.5, 0, 15), Eigen::Vector3d::Zero()}, {Eigen::Vector3d(1.5, 0, 17), Eigen::Vector3d::Zero()}}, cfg);
    const auto o = est.initialise_from_matches({{0, 1, *project_point(rig, est.camera_position(0), p),
                                                 *project_point(rig, est.camera_position(1), p)}});
    return std::make_pair(o[0], est.num_landmarks());
  };
  const Eigen::Vector3d near(0.5, 1.0, 12.0), ground(0.5, 1.0, 0.0);  // 3 m and 15 m under camera 0
  const auto [near_off, n_off] = run(0.0, near);
  EXPECT_TRUE(near_off.id) << near_off.rejected_because;
  EXPECT_EQ(n_off, 1);
  const auto [near_on, n_on] = run(5.0, near);
  EXPECT_FALSE(near_on.id);
  EXPECT_EQ(near_on.rejected_because, kTooClose);
  EXPECT_EQ(n_on, 0);
  const auto [ground_on, n_ground] = run(5.0, ground);
  EXPECT_TRUE(ground_on.id) << ground_on.rejected_because;
  EXPECT_EQ(n_ground, 1);
}

namespace {
// Two nadir cameras 3.6 m apart and a ground point far to the side: 3.3 degrees of parallax.
struct LowParallaxPair {
  Eigen::Vector3d p{45.0, 20.0, 0.0};
  static EstimatorSettings settings(bool inverse_depth) {
    EstimatorSettings s = Scene::settings(true);
    s.initialisation.min_parallax_deg = 8;
    s.initialisation.low_parallax_inverse_depth = inverse_depth;
    return s;
  }
  static Estimator estimator(bool inverse_depth) {
    return Estimator({nadir_rig(), nadir_rig()}, {},
                     {{Eigen::Vector3d(-1.5, 0, 15), Eigen::Vector3d::Zero()},
                      {Eigen::Vector3d(1.5, 0, 17), Eigen::Vector3d::Zero()}},
                     settings(inverse_depth));
  }
  CrossMatch match(const Estimator& est, const Eigen::Vector2d& shift_b = Eigen::Vector2d::Zero()) const {
    const CameraRig rig = nadir_rig();
    return {0, 1, *project_point(rig, est.camera_position(0), p),
            *project_point(rig, est.camera_position(1), p) + shift_b};
  }
};
}  // namespace

TEST(CooperativeInverseDepth, LowParallaxPairIsRejectedByDefault) {
  LowParallaxPair pair;
  Estimator est = LowParallaxPair::estimator(false);
  const auto o = est.initialise_from_matches({pair.match(est)});
  EXPECT_FALSE(o[0].id);
  EXPECT_EQ(o[0].rejected_because, kLowParallax);
  EXPECT_EQ(est.num_landmarks(), 0);
}

TEST(CooperativeInverseDepth, SecondViewFixesTheDepth) {
  LowParallaxPair pair;
  Estimator est = LowParallaxPair::estimator(true);
  const Eigen::Vector3d x_a = est.camera_position(0);
  const auto o = est.initialise_from_matches({pair.match(est)});
  ASSERT_TRUE(o[0].id) << o[0].rejected_because;
  const LandmarkSlot* lm = est.state().find(*o[0].id);
  ASSERT_EQ(lm->kind, LandmarkKind::InverseDepth);
  // The prior alone puts it 20 m from the anchor (rho 0.05); the true distance is 52.8 m.
  // With noiseless pixels the second view leaves only the prior's pull: a few per cent.
  const double d_true = (pair.p - x_a).norm();
  const double d_est = 1.0 / est.state().x(lm->offset + 5);
  EXPECT_NEAR(d_est, d_true, 0.04 * d_true);
  EXPECT_LT((*est.landmark_position(*o[0].id) - pair.p).norm(), 0.04 * d_true);
  // Its inverse depth is now known far better than the prior's 0.04 1/m.
  EXPECT_LT(std::sqrt(est.state().P(lm->offset + 5, lm->offset + 5)), 0.01);
  const Eigen::MatrixXd& P = est.state().P;
  EXPECT_LT((P - P.transpose()).norm(), 1e-12);
  // Positive semi-definite: the anchor is a copy of the camera position at this instant, so P is
  // singular until either moves.
  const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(P).eigenvalues();
  EXPECT_GT(ev.minCoeff(), -1e-12 * ev.maxCoeff());
}

TEST(CooperativeInverseDepth, LinearisingAtTheTriangulationBeatsThePrior) {
  // Without the iterated linearisation the second pixel is linearised at rho = 0.05, 20 px and
  // more from where it is; the triangulated inverse depth puts the linearisation near the truth.
  LowParallaxPair pair;
  pair.p = Eigen::Vector3d(60.0, 35.0, 0.0);
  Estimator est = LowParallaxPair::estimator(true);
  const auto o = est.initialise_from_matches({pair.match(est)});
  ASSERT_TRUE(o[0].id) << o[0].rejected_because;
  const double d_true = (pair.p - est.camera_position(0)).norm();
  const LandmarkSlot* lm = est.state().find(*o[0].id);
  EXPECT_NEAR(1.0 / est.state().x(lm->offset + 5), d_true, 0.05 * d_true);
}

TEST(CooperativeInverseDepth, PixelOffTheEpipolarLineIsRejected) {
  LowParallaxPair pair;
  Estimator est = LowParallaxPair::estimator(true);
  const int dim = est.state().dim();
  // 40 px across the epipolar line (the baseline is along x, so the line runs along u).
  const auto o = est.initialise_from_matches({pair.match(est, Eigen::Vector2d(0, 40))});
  EXPECT_FALSE(o[0].id);
  EXPECT_EQ(o[0].rejected_because, "second view incompatible");
  EXPECT_EQ(est.state().dim(), dim);
  EXPECT_EQ(est.num_landmarks(), 0);
}

// A camera's pixel offsets for a landmark are stated when its first compatible observation
// arrives. Until then they are zero-mean noise independent of everything, so the posterior is the
// one a filter that carried them from the start would reach, and an incompatible observation
// states nothing.
TEST(Update, OffsetsStatedAtFirstObservationGiveTheSamePosteriorAsOffsetsCarriedFromTheStart) {
  std::mt19937_64 rng(11);
  FilterState s(3);
  s.x.head(s.kinematic_dim()) << 0, 0, 0, 1, 0, 0, -3, 0, 15, 1, 0, 0, 0, 0, 16, 1, 0, 0, 3, 0, 15, 1, 0, 0;
  std::uniform_real_distribution<double> u(-6, 6);
  for (int i = 0; i < 12; ++i) {
    Eigen::VectorXd v = Eigen::VectorXd::Zero(5);
    v.head<3>() << u(rng), u(rng), 0.05 * u(rng);
    s.add_landmark(LandmarkKind::Euclidean, v, Eigen::MatrixXd::Zero(5, s.dim()),
                   Eigen::MatrixXd::Identity(5, 5), {0, 0b10, 0.75});
  }
  s.P = random_spd(s.dim(), rng) * 0.01;
  const std::vector<CameraRig> cams(3, nadir_rig());
  std::vector<Correspondence> cands;
  std::normal_distribution<double> noise(0, 0.5);
  for (const auto& lm : s.landmarks())
    for (int cam : {1, 2}) {
      auto uv = predict_landmark_pixel(s, s.x, lm, cam, cams[cam]);
      ASSERT_TRUE(uv);
      cands.push_back({cam, lm.id, *uv + Eigen::Vector2d(noise(rng), noise(rng))});
    }
  cands[5].uv += Eigen::Vector2d(80, 60);  // camera 2 on landmark 2: far off, gated out

  // Carried from the start: every landmark's camera-2 offsets are states before the update.
  FilterState carried = s;
  std::vector<std::pair<LandmarkId, int>> all;
  for (const auto& lm : s.landmarks()) all.emplace_back(lm.id, 2);
  carried.state_pixel_offsets(all);
  // The prediction the frontend searches around carries the unstated offsets as noise.
  for (const auto& lm : s.landmarks()) {
    const auto m = landmark_measurement(s, lm, 2, cams[2], Eigen::Vector2d::Zero(), 1.0);
    const auto mc = landmark_measurement(carried, *carried.find(lm.id), 2, cams[2], Eigen::Vector2d::Zero(), 1.0);
    EXPECT_LT((innovation_covariance(s, *m) - innovation_covariance(carried, *mc)).norm(), 1e-12);
  }

  GatingSettings gating;
  std::mt19937_64 r1(5), r2(5);
  FilterState late = s;
  const auto a = update_with_correspondences(late, cams, cands, gating, 1.0, r1);
  const auto b = update_with_correspondences(carried, cams, cands, gating, 1.0, r2);
  EXPECT_EQ(a.accepted, b.accepted);
  EXPECT_FALSE(a.accepted[5]);
  EXPECT_EQ(late.dim(), s.dim() + 2 * 11);  // the gated-out pair was not stated
  EXPECT_EQ(late.find(s.landmarks()[2].id)->pixel_offset(2), -1);
  // Compare on the late filter's layout: the carried filter's entries at the same slots.
  std::vector<int> at;
  for (int i = 0; i < s.agent_dim(); ++i) at.push_back(i);
  for (const auto& lm : late.landmarks()) {
    const LandmarkSlot& c = *carried.find(lm.id);
    for (int i = 0; i < 3; ++i) at.push_back(c.offset + i);
    for (int cam : {1, 2})
      if (lm.pixel_offset(cam) >= 0) at.insert(at.end(), {c.pixel_offset(cam), c.pixel_offset(cam) + 1});
  }
  ASSERT_EQ(static_cast<int>(at.size()), late.dim());
  const Eigen::VectorXd xc = carried.x(at);
  const Eigen::MatrixXd Pc = carried.P(at, at);
  EXPECT_LT((late.x - xc).norm(), 1e-9 * xc.norm());
  EXPECT_LT((late.P - Pc).norm(), 1e-9 * Pc.norm());
}
