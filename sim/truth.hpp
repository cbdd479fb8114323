// Ground-truth motion of the open-loop runs: the lead follows its curve (the lemniscate of paper
// eq. 66, a line, waypoints or a file) and every UAV keeps its initial offset from it, in the
// world frame or turning with the lead's heading (docs/design.md, frames and conventions), each
// agent plus the random acceleration of noise.motion when the scenario asks for it; the cameras carry the
// gimbal error e_r(t) = A sin(w t) about their x and y axes (or with a phase per camera and
// axis, noise.gimbal_random_phase), which the filter never sees.
// Truth is the interface the synthetic source reads; closed_loop_truth.hpp is the other one.
#pragma once

#include <Eigen/Core>
#include <utility>
#include <vector>

#include "sim/scenario.hpp"

namespace wingman::sim {

// eq. 66 and its first three time derivatives, unshifted (the third by central differences of
// the analytic second).
KinematicState lemniscate(const LeadTrajectorySpec& spec, double t);
// The curve the scenario names (lemniscate, line, or the spline of waypoints or a file), unshifted.
KinematicState nominal_motion(const LeadTrajectorySpec& spec, double t);

// The direction of travel of a curve about world z, and its first two time derivatives.
struct Turn {
  double heading = 0, rate = 0, acceleration = 0;
};
// At a standstill: the heading the curve leaves with (or, at its end, arrived with), turning at 0.
Turn curve_turn(const LeadTrajectorySpec& spec, double t);

// What the synthetic measurements are made from: the lead, the UAVs and their cameras. The
// open-loop truth knows every instant in advance; the closed-loop one only the current step.
class Truth {
 public:
  explicit Truth(const Scenario& scn);
  virtual ~Truth() = default;
  virtual KinematicState lead(double t) const = 0;
  virtual KinematicState uav(int j, double t) const = 0;  // the UAV's body position
  virtual double uav_yaw(int j, double t) const = 0;      // psi of eq. 53
  // Horizontal bounding box [xmin, ymin, xmax, ymax] of every agent over the run.
  virtual Eigen::Vector4d horizontal_extent() const = 0;
  KinematicState camera(int j, double t) const;  // body plus the offset d (eq. 59)
  // Camera j's true orientation: commanded nadir R_CW with the gimbal error applied. The
  // gimbal holds it whatever the UAV's yaw.
  Eigen::Matrix3d camera_R_CW(int j, double t) const;
  Eigen::Matrix3d commanded_R_CW() const;
  const Scenario& scenario() const { return scn_; }

 protected:
  const Scenario& scn_;

 private:
  std::vector<Eigen::Vector2d> gimbal_phase_;  // per camera, about x and y
};

class OpenLoopTruth : public Truth {
 public:
  explicit OpenLoopTruth(const Scenario& scn);
  KinematicState lead(double t) const override;
  KinematicState uav(int j, double t) const override;
  double uav_yaw(int, double) const override { return 0.0; }  // the open-loop UAVs do not turn
  Eigen::Vector4d horizontal_extent() const override;

 private:
  // Agent a (0: lead, 1 + j: UAV j): the curve shifted to start at `start`, plus its deviation.
  KinematicState agent(std::size_t a, const Eigen::Vector3d& start, double t) const;
  // UAV j's offset from the lead at t in the heading frame, and its derivatives.
  KinematicState formation_offset(int j, double t) const;

  Eigen::Vector3d origin_;  // the curve's value at t = 0
  double heading0_ = 0;     // the curve's heading at t = 0
  // Per agent, per step k = 0..num_steps: the integrated noise.motion acceleration; empty when
  // the scenario has none.
  std::vector<std::vector<KinematicState>> wander_;
};

}  // namespace wingman::sim
