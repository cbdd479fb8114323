// The IMU a UAV carries in a dataset: what a strapdown gyroscope and accelerometer fixed to the
// body measure along the truth, with Kalibr's noise model (white noise plus bias random walk,
// the model EuRoC's imu0/sensor.yaml states). The estimator does not use it; datasets carry it for
// visual-inertial systems that read them.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <string_view>

#include "sim/scenario.hpp"
#include "sim/truth.hpp"

namespace wingman::sim {

// World frame z up (docs/design.md): gravity points down. 9.81, EuRoC's value.
inline const Eigen::Vector3d kGravity_W{0.0, 0.0, -9.81};

// A body's attitude, angular rate and acceleration at one instant, from the truth's analytic
// derivatives.
struct BodyMotion {
  Eigen::Matrix3d R_WB = Eigen::Matrix3d::Identity();
  Eigen::Vector3d omega_B = Eigen::Vector3d::Zero();  // rad/s, in the body frame
  Eigen::Vector3d a_W = Eigen::Vector3d::Zero();      // m/s^2, in the world frame
};

// UAV j's body: yaw psi (eq. 53) about z, its rate, and the curve's acceleration.
BodyMotion uav_body_motion(const Truth& truth, int j, double t);

// One sample: what was measured and the biases that were in it.
struct ImuReading {
  Eigen::Vector3d w_S = Eigen::Vector3d::Zero(), a_S = Eigen::Vector3d::Zero();
  Eigen::Vector3d b_w = Eigen::Vector3d::Zero(), b_a = Eigen::Vector3d::Zero();
};

// Samples at spec.rate. Discrete form of the continuous model (Kalibr's "IMU noise model"):
// white noise sigma_d = sigma_c / sqrt(dt), bias walk sigma_bd = sigma_bc * sqrt(dt).
class ImuSimulator {
 public:
  // Draws from its own stream (seed, "imu/<name>"), so adding an IMU changes no other noise.
  ImuSimulator(const NoiseSpec::Imu& spec, std::uint64_t seed, std::string_view name);
  // The sample for this motion, then the biases walk one period.
  ImuReading measure(const BodyMotion& m);
  double dt() const { return 1.0 / spec_.rate; }

 private:
  NoiseSpec::Imu spec_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> unit_{0.0, 1.0};
  Eigen::Vector3d b_w_, b_a_;
};

}  // namespace wingman::sim
