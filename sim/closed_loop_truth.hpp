// Ground truth of a closed-loop run (paper section 7.3): the lead flies its own trajectory (eq. 66,
// as in open loop); each UAV's position and yaw are whatever the commanded velocities made of
// them. This class holds the current step's state; the pipeline integrates eq. 53 (control/)
// and writes the result back with set_uav. Queries at any other time than the current one throw,
// which catches a measurement taken from a stale state. Also here: the bounded disturbance
// Delta_g of eq. 58 that the truth flies and the controller never sees.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "sim/scenario.hpp"
#include "sim/truth.hpp"

namespace wingman::sim {

class ClosedLoopTruth : public Truth {
 public:
  // UAVs at their initial positions at rest, yaws from scn.control.uavs.
  explicit ClosedLoopTruth(const Scenario& scn);

  KinematicState lead(double t) const override;
  KinematicState uav(int j, double t) const override;
  double uav_yaw(int j, double t) const override;
  // The lead's box grown by the largest horizontal UAV-lead distance the formation asks for or
  // starts with, plus 10 m for transients.
  Eigen::Vector4d horizontal_extent() const override;

  double time() const { return t_; }
  void set_time(double t) { t_ = t; }
  // State of UAV j at the current time: body position, world velocity (for NEES and plots), yaw.
  void set_uav(int j, const Eigen::Vector3d& position, const Eigen::Vector3d& velocity, double yaw);

 private:
  void check_time(double t) const;
  OpenLoopTruth lead_;  // only its lead() is used
  double t_ = 0;
  std::vector<KinematicState> uavs_;
  std::vector<double> yaw_;
};

// Delta_g of eq. 58 for every UAV, in the coordinates of u = [-vx, -vy, vz, w]: per component a
// sum of two sinusoids, 0.6 sin(a t + p) + 0.4 sin(b t + q) times the bound, frequencies in
// [0.05, 0.5] rad/s and phases drawn from the seed, so |Delta_g_i(t)| <= bound_i always.
class InputDisturbance {
 public:
  InputDisturbance(const Eigen::Vector4d& bound, int num_uavs, std::uint64_t seed);
  Eigen::Vector4d operator()(int j, double t) const;
  const Eigen::Vector4d& bound() const { return bound_; }

 private:
  Eigen::Vector4d bound_;
  std::vector<Eigen::Matrix<double, 4, 4>> params_;  // per UAV, rows a, p, b, q per component
};

}  // namespace wingman::sim
