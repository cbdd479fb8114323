// Ground-truth motion of the open-loop runs: the lead follows the lemniscate of paper eq. 66 and
// every UAV the same curve shifted by its initial offset (DESIGN.md §3); the cameras carry the
// gimbal error e_r(t) = A sin(w t) about their x and y axes, which the filter never sees.
#pragma once

#include <Eigen/Core>
#include <utility>

#include "sim/scenario.hpp"

namespace wingman::sim {

struct KinematicState {
  Eigen::Vector3d position = Eigen::Vector3d::Zero(), velocity = Eigen::Vector3d::Zero();
};

// eq. 66 and its time derivative, unshifted.
KinematicState lemniscate(const LeadTrajectorySpec& spec, double t);

class OpenLoopTruth {
 public:
  explicit OpenLoopTruth(const Scenario& scn);
  KinematicState lead(double t) const;
  KinematicState uav(int j, double t) const;     // the UAV's body position
  KinematicState camera(int j, double t) const;  // body plus the offset d (eq. 59)
  // The camera's true orientation: commanded nadir R_CW with the gimbal error applied.
  Eigen::Matrix3d camera_R_CW(double t) const;
  Eigen::Matrix3d commanded_R_CW() const;
  // Horizontal bounding box [xmin, ymin, xmax, ymax] of every agent over the run.
  Eigen::Vector4d horizontal_extent() const;

 private:
  const Scenario& scn_;
  Eigen::Vector3d origin_;  // the curve's value at t = 0
};

}  // namespace wingman::sim
