#include "sim/imu.hpp"

#include <cmath>
#include <string>

#include "geometry/rotation.hpp"
#include "sim/rng.hpp"

namespace wingman::sim {

BodyMotion uav_body_motion(const Truth& truth, int j, double t) {
  BodyMotion m;
  const double psi = truth.uav_yaw(j, t);
  m.R_WB = geometry::rot_z(psi);
  // psi is a smooth function of time (0 in the open loop); a central difference of it is exact
  // to O(h^2), unlike differencing sampled positions.
  constexpr double h = 1e-4;
  m.omega_B = {0.0, 0.0, (truth.uav_yaw(j, t + h) - truth.uav_yaw(j, t - h)) / (2 * h)};
  m.a_W = truth.uav(j, t).acceleration;
  return m;
}

ImuSimulator::ImuSimulator(const NoiseSpec::Imu& spec, std::uint64_t seed, std::string_view name)
    : spec_(spec), rng_(make_stream(seed, "imu/" + std::string(name))) {
  b_w_ = gaussian3(rng_, unit_, spec_.gyroscope_initial_bias_sigma);
  b_a_ = gaussian3(rng_, unit_, spec_.accelerometer_initial_bias_sigma);
}

ImuReading ImuSimulator::measure(const BodyMotion& m) {
  const double dt = 1.0 / spec_.rate;
  ImuReading r;
  r.b_w = b_w_;
  r.b_a = b_a_;
  // Specific force: what the accelerometer feels, acceleration minus gravity, in the body frame.
  const Eigen::Vector3d f_B = m.R_WB.transpose() * (m.a_W - kGravity_W);
  r.w_S = m.omega_B + b_w_ + gaussian3(rng_, unit_, spec_.gyroscope_noise_density / std::sqrt(dt));
  r.a_S = f_B + b_a_ + gaussian3(rng_, unit_, spec_.accelerometer_noise_density / std::sqrt(dt));
  b_w_ += gaussian3(rng_, unit_, spec_.gyroscope_random_walk * std::sqrt(dt));
  b_a_ += gaussian3(rng_, unit_, spec_.accelerometer_random_walk * std::sqrt(dt));
  return r;
}

}  // namespace wingman::sim
