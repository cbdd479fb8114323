// The IMU of the datasets: the truth's accelerations are its velocities' derivatives, the
// simulated sensor measures specific force and angular rate in the body frame, and its noise has
// the densities and random walks its settings state.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

#include "geometry/rotation.hpp"
#include "sim/imu.hpp"
#include "sim/scenario.hpp"
#include "sim/truth.hpp"

using namespace wingman::sim;

namespace {

NoiseSpec::Imu noiseless() {
  NoiseSpec::Imu s;
  s.gyroscope_noise_density = s.gyroscope_random_walk = 0;
  s.accelerometer_noise_density = s.accelerometer_random_walk = 0;
  s.gyroscope_initial_bias_sigma = s.accelerometer_initial_bias_sigma = 0;
  return s;
}

double stddev(const std::vector<double>& v) {
  double mean = 0, sq = 0;
  for (double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  for (double x : v) sq += (x - mean) * (x - mean);
  return std::sqrt(sq / static_cast<double>(v.size() - 1));
}

}  // namespace

TEST(Imu, LemniscateAccelerationIsItsVelocityDerivative) {
  LeadTrajectorySpec spec;
  spec.z_amplitude = 2.0;  // the vertical term too
  spec.z_omega = 0.2;
  for (double t : {0.0, 13.7, 70.0, 151.2}) {
    const double h = 1e-4;
    const Eigen::Vector3d num = (lemniscate(spec, t + h).velocity - lemniscate(spec, t - h).velocity) / (2 * h);
    EXPECT_LT((num - lemniscate(spec, t).acceleration).norm(), 1e-8) << "t = " << t;
    EXPECT_GT(lemniscate(spec, t).acceleration.norm(), 1e-3) << "t = " << t;
  }
}

TEST(Imu, OpenLoopAccelerationIncludesTheMotionNoiseOfEachStep) {
  Scenario scn = parse_scenarios("duration: 20\nseed: 3\nnoise: {motion: {accel_sigma_uav: 0.5}}\n", "inline.yaml").front();
  const OpenLoopTruth truth(scn);
  for (double t : {0.05, 3.02, 11.57}) {  // inside steps: the velocity is linear there
    const double h = 1e-3;
    const Eigen::Vector3d num = (truth.uav(0, t + h).velocity - truth.uav(0, t - h).velocity) / (2 * h);
    EXPECT_LT((num - truth.uav(0, t).acceleration).norm(), 1e-6) << "t = " << t;
    EXPECT_GT((truth.uav(0, t).acceleration - truth.lead(t).acceleration).norm(), 0.01) << "t = " << t;
  }
}

TEST(Imu, NoiselessImuMeasuresSpecificForceAndRateInTheBodyFrame) {
  ImuSimulator imu(noiseless(), 1, "uav1");
  BodyMotion m;
  m.R_WB = wingman::geometry::rot_z(0.7);
  m.omega_B = {0.01, -0.02, 0.3};
  m.a_W = {1.0, -2.0, 0.5};
  const ImuReading r = imu.measure(m);
  // a_S = R_WB^T (a_W - g), g = (0, 0, -9.81): at rest an accelerometer reads +9.81 up.
  const Eigen::Vector3d f_W(1.0, -2.0, 0.5 + 9.81);
  EXPECT_LT((r.a_S - m.R_WB.transpose() * f_W).norm(), 1e-12);
  EXPECT_NEAR(r.a_S.z(), 10.31, 1e-12);
  EXPECT_NEAR(r.a_S.x(), std::cos(0.7) * 1.0 + std::sin(0.7) * -2.0, 1e-12);
  EXPECT_LT((r.w_S - m.omega_B).norm(), 1e-15);
  EXPECT_EQ(r.b_w.norm(), 0.0);
  EXPECT_EQ(r.b_a.norm(), 0.0);
}

TEST(Imu, NoiseHasTheStatedDensitiesAndBiasesWalkAtTheStatedRate) {
  NoiseSpec::Imu spec;  // EuRoC's ADIS16448 figures, 200 Hz
  ImuSimulator imu(spec, 5, "uav1");
  std::vector<double> gyro, accel, gyro_walk, accel_walk;
  ImuReading last;
  const int n = 40000;
  for (int i = 0; i < n; ++i) {
    const ImuReading r = imu.measure(BodyMotion{});
    gyro.push_back(r.w_S.x() - r.b_w.x());
    accel.push_back(r.a_S.y() - r.b_a.y());
    if (i > 0) {
      gyro_walk.push_back(r.b_w.z() - last.b_w.z());
      accel_walk.push_back(r.b_a.x() - last.b_a.x());
    }
    last = r;
  }
  const double dt = 1.0 / spec.rate;
  // Discrete white noise: sigma_c / sqrt(dt); bias increments sigma_bc * sqrt(dt). 40000 draws:
  // the sample deviation is within 2% of the true one at about 6 sigma.
  EXPECT_NEAR(stddev(gyro) / (spec.gyroscope_noise_density / std::sqrt(dt)), 1.0, 0.02);
  EXPECT_NEAR(stddev(accel) / (spec.accelerometer_noise_density / std::sqrt(dt)), 1.0, 0.02);
  EXPECT_NEAR(stddev(gyro_walk) / (spec.gyroscope_random_walk * std::sqrt(dt)), 1.0, 0.02);
  EXPECT_NEAR(stddev(accel_walk) / (spec.accelerometer_random_walk * std::sqrt(dt)), 1.0, 0.02);
}

TEST(Imu, EachUavHasItsOwnStreamAndTheSameSeedRepeats) {
  const NoiseSpec::Imu spec;
  ImuSimulator a(spec, 9, "uav1"), b(spec, 9, "uav1"), c(spec, 9, "uav2");
  const ImuReading ra = a.measure({}), rb = b.measure({}), rc = c.measure({});
  EXPECT_EQ(ra.a_S, rb.a_S);
  EXPECT_EQ(ra.b_w, rb.b_w);
  EXPECT_NE(ra.a_S, rc.a_S);
}
