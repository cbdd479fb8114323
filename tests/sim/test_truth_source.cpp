// Truth trajectories and the synthetic measurement source.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "geometry/rotation.hpp"
#include "sim/scenario.hpp"
#include "sim/synthetic_source.hpp"
#include "sim/truth.hpp"

using namespace wingman::sim;

namespace {
Scenario paper_scenario() {
  return parse_scenarios("duration: 60\nseed: 4\n", "inline.yaml").front();
}

// Binds every point that cameras 0 and 1 both see at t = 0 to a new landmark id; returns the ids.
std::vector<std::int64_t> bind_all_seen_by_both(SyntheticSource& src) {
  std::int64_t next_id = 0;
  std::vector<std::int64_t> ids;
  for (const auto& pp : src.cross_matches(0, 1, 0.0, 10000)) {
    src.bind(next_id, pp.point);
    ids.push_back(next_id++);
  }
  return ids;
}
}  // namespace

TEST(Truth, LemniscateVelocityIsItsDerivative) {
  const LeadTrajectorySpec spec;
  for (double t : {0.0, 13.7, 70.0, 151.2}) {
    const double h = 1e-4;
    const Eigen::Vector3d num = (lemniscate(spec, t + h).position - lemniscate(spec, t - h).position) / (2 * h);
    EXPECT_LT((num - lemniscate(spec, t).velocity).norm(), 1e-7) << "t = " << t;
  }
}

TEST(Truth, AgentsStartAtTheirInitialPositionsAndShareTheCurve) {
  const Scenario scn = paper_scenario();
  const OpenLoopTruth truth(scn);
  EXPECT_LT((truth.lead(0).position - Eigen::Vector3d(0, 0, 0)).norm(), 1e-12);
  EXPECT_LT((truth.uav(0, 0).position - Eigen::Vector3d(-1.5, 0, 15)).norm(), 1e-12);
  EXPECT_LT((truth.uav(1, 0).position - Eigen::Vector3d(1.5, 0, 17)).norm(), 1e-12);
  // Open loop: the formation offset is constant.
  EXPECT_LT((truth.uav(0, 42.0).position - truth.lead(42.0).position - Eigen::Vector3d(-1.5, 0, 15)).norm(), 1e-9);
  const Eigen::Matrix3d R = truth.camera_R_CW(0, 5.0);
  EXPECT_LT((R * R.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_GT((R - truth.commanded_R_CW()).norm(), 1e-3);  // the gimbal error is there
}

TEST(Truth, GimbalErrorIsThePapersSinusoidByDefault) {
  const Scenario scn = paper_scenario();
  const OpenLoopTruth truth(scn);
  for (double t : {0.0, 3.7, 12.0}) {
    const double e = scn.noise.gimbal_amplitude * std::sin(scn.noise.gimbal_omega * t);
    const Eigen::Matrix3d expected = wingman::geometry::gimbal_error(e) * truth.commanded_R_CW();
    for (int j = 0; j < 2; ++j) EXPECT_LT((truth.camera_R_CW(j, t) - expected).norm(), 1e-12);
  }
}

TEST(Truth, RandomGimbalPhaseDiffersPerCameraAndSeedAndKeepsTheAmplitude) {
  Scenario scn = paper_scenario();
  scn.noise.gimbal_random_phase = true;
  const OpenLoopTruth a(scn);
  Scenario other_seed = scn;
  other_seed.seed = scn.seed + 1;
  const OpenLoopTruth b(other_seed);
  const OpenLoopTruth a_again(scn);
  const double t = 4.0;
  EXPECT_GT((a.camera_R_CW(0, t) - a.camera_R_CW(1, t)).norm(), 1e-4);  // cameras independent
  EXPECT_GT((a.camera_R_CW(0, t) - b.camera_R_CW(0, t)).norm(), 1e-4);  // seeds independent
  EXPECT_LT((a.camera_R_CW(0, t) - a_again.camera_R_CW(0, t)).norm(), 1e-15);  // reproducible
  // The error stays a rotation within the amplitude about each axis.
  double max_angle = 0;
  for (double tt = 0; tt < 30; tt += 0.1) {
    const Eigen::Matrix3d E = a.camera_R_CW(1, tt) * a.commanded_R_CW().transpose();
    EXPECT_LT((E * E.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    max_angle = std::max(max_angle, Eigen::AngleAxisd(E).angle());
  }
  EXPECT_LE(max_angle, std::sqrt(2.0) * scn.noise.gimbal_amplitude + 1e-9);
  EXPECT_GT(max_angle, 0.8 * scn.noise.gimbal_amplitude);
}

TEST(Truth, LineTrajectoryMovesAtItsVelocity) {
  Scenario scn = paper_scenario();
  scn.lead.trajectory.type = "line";
  scn.lead.trajectory.velocity = {1.5, -0.5, 0.1};
  const OpenLoopTruth truth(scn);
  EXPECT_LT((truth.lead(10).position - Eigen::Vector3d(15, -5, 1)).norm(), 1e-12);
  EXPECT_LT((truth.uav(1, 10).velocity - scn.lead.trajectory.velocity).norm(), 1e-12);
}

// noise.motion: every agent's deviation from its curve follows the filter's discrete model
// (p += v dt, v += a dt) with a = a_common + a_agent, so increments have the model's covariance.
TEST(Truth, MotionNoiseFollowsTheFiltersProcessModel) {
  Scenario scn = parse_scenarios("duration: 400\nseed: 9\n", "inline.yaml").front();
  scn.noise.motion = {0.02, 0.04, 0.03};  // lead, uav, common
  const OpenLoopTruth truth(scn), again(scn);
  const Scenario paper = paper_scenario();  // Truth keeps a reference: the scenario must outlive it
  const OpenLoopTruth nominal(paper);
  const double dt = scn.dt();
  const int n = scn.num_steps();
  double var_lead = 0, var_uav = 0, cov_uavs = 0, cov_lead_uav = 0;
  for (int k = 0; k < n; ++k) {
    const double t = k * dt, t1 = (k + 1) * dt;
    auto dev = [&](const KinematicState& s, double tt) {
      return KinematicState{s.position - lemniscate(scn.lead.trajectory, tt).position,
                            s.velocity - lemniscate(scn.lead.trajectory, tt).velocity};
    };
    const KinematicState l0 = dev(truth.lead(t), t), l1 = dev(truth.lead(t1), t1);
    const KinematicState u0 = dev(truth.uav(0, t), t), u1 = dev(truth.uav(0, t1), t1);
    const KinematicState w0 = dev(truth.uav(1, t), t), w1 = dev(truth.uav(1, t1), t1);
    // Positions integrate the previous velocity exactly.
    ASSERT_LT((l1.position - l0.position - l0.velocity * dt).norm(), 1e-9) << k;
    ASSERT_LT((w1.position - w0.position - w0.velocity * dt).norm(), 1e-9) << k;
    const Eigen::Vector3d al = (l1.velocity - l0.velocity) / dt, au = (u1.velocity - u0.velocity) / dt,
                          aw = (w1.velocity - w0.velocity) / dt;
    var_lead += al.squaredNorm() / 3;
    var_uav += au.squaredNorm() / 3;
    cov_uavs += au.dot(aw) / 3;
    cov_lead_uav += al.dot(au) / 3;
  }
  // 4000 steps x 3 axes: the sample variances are within about 3 % (1 sigma) of the truth.
  EXPECT_NEAR(var_lead / n, 0.02 * 0.02 + 0.03 * 0.03, 0.15 * (0.02 * 0.02 + 0.03 * 0.03));
  EXPECT_NEAR(var_uav / n, 0.04 * 0.04 + 0.03 * 0.03, 0.15 * (0.04 * 0.04 + 0.03 * 0.03));
  EXPECT_NEAR(cov_uavs / n, 0.03 * 0.03, 0.25 * 0.03 * 0.03);
  EXPECT_NEAR(cov_lead_uav / n, 0.03 * 0.03, 0.25 * 0.03 * 0.03);
  // Reproducible from the seed, and starting on the curve.
  EXPECT_EQ((truth.uav(1, 123.4).position - again.uav(1, 123.4).position).norm(), 0.0);
  EXPECT_LT((truth.uav(0, 0).position - nominal.uav(0, 0).position).norm(), 1e-12);
  EXPECT_GT((truth.uav(0, 300).position - truth.lead(300).position - Eigen::Vector3d(-1.5, 0, 15)).norm(), 0.1);
}

TEST(SyntheticSource, FieldDensityAndReproducibility) {
  const Scenario scn = paper_scenario();
  const OpenLoopTruth truth(scn);
  const auto a = make_landmark_field(scn, truth), b = make_landmark_field(scn, truth);
  const Eigen::Vector4d box = truth.horizontal_extent();
  const double m = scn.field.margin;
  const double area = (box(2) - box(0) + 2 * m) * (box(3) - box(1) + 2 * m);
  EXPECT_NEAR(static_cast<double>(a.size()), scn.field.density * area, 1.0);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.front(), b.front());
  for (const auto& p : a) EXPECT_LE(std::abs(p.z() - scn.field.ground_height), scn.field.height_spread / 2);
}

TEST(SyntheticSource, OutliersAreFivePercentWithinFifteenPixels) {
  const Scenario scn = paper_scenario();
  const OpenLoopTruth truth(scn);
  SyntheticSource src(scn, truth);
  // Bind every point in view and observe them over many frames.
  long total = 0, outliers = 0;
  const std::vector<std::int64_t> ids = bind_all_seen_by_both(src);
  ASSERT_GT(ids.size(), 50u);
  for (int k = 0; k < 200; ++k) {
    for (const auto& o : src.observe_landmarks(0, 0.0, ids)) {
      ++total;
      const double e = (o.uv - o.true_uv).norm();
      if (o.injected_outlier) {
        ++outliers;
        EXPECT_LE(e, scn.noise.outlier_max_px + 1e-9);
      }
    }
  }
  EXPECT_NEAR(static_cast<double>(outliers) / total, scn.noise.outlier_fraction, 0.005);
  EXPECT_EQ(src.injected_outliers(0), outliers);
}

TEST(SyntheticSource, PixelBiasIsConstantPerCameraAndPointAndOffByDefault) {
  Scenario scn = parse_scenarios("duration: 60\nseed: 4\nnoise: {pixel_sigma: 0.5, pixel_bias_sigma: 0.8, "
                                 "outlier_fraction: 0, cooperative_outlier_fraction: 0}\n",
                                 "inline.yaml").front();
  EXPECT_DOUBLE_EQ(scn.noise.pixel_bias_sigma, 0.8);
  const OpenLoopTruth truth(scn);
  SyntheticSource src(scn, truth);
  const std::vector<std::int64_t> ids = bind_all_seen_by_both(src);
  ASSERT_GT(ids.size(), 50u);
  // Per point and camera: the mean error over 400 frames is the point's offset (white part
  // averaged down to 0.5 / 20 px), the same whenever it is drawn, and differs between cameras.
  std::vector<Eigen::Vector2d> mean0(ids.size(), Eigen::Vector2d::Zero()), mean1 = mean0;
  constexpr int kFrames = 400;
  for (int k = 0; k < kFrames; ++k) {
    for (const auto& o : src.observe_landmarks(0, 0.0, ids)) mean0[o.landmark] += (o.uv - o.true_uv) / kFrames;
    for (const auto& o : src.observe_landmarks(1, 0.0, ids)) mean1[o.landmark] += (o.uv - o.true_uv) / kFrames;
  }
  double ss0 = 0, ss_diff = 0;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const std::size_t p = *src.point_of(ids[i]);
    EXPECT_LT((mean0[i] - src.pixel_bias(0, p)).norm(), 0.15) << "point " << p;
    EXPECT_LT((mean1[i] - src.pixel_bias(1, p)).norm(), 0.15) << "point " << p;
    ss0 += mean0[i].squaredNorm();
    ss_diff += (mean0[i] - mean1[i]).squaredNorm();
  }
  const double n = static_cast<double>(ids.size());
  EXPECT_NEAR(std::sqrt(ss0 / (2 * n)), 0.8, 0.2);              // per axis
  EXPECT_NEAR(std::sqrt(ss_diff / (2 * n)), 0.8 * std::sqrt(2.0), 0.3);  // independent per camera

  // Default 0: no offset, and the white noise draws exactly what it drew before.
  const Scenario plain = paper_scenario();
  EXPECT_DOUBLE_EQ(plain.noise.pixel_bias_sigma, 0.0);
  SyntheticSource a(plain, truth);
  EXPECT_EQ(a.pixel_bias(0, 7), Eigen::Vector2d::Zero());
}
