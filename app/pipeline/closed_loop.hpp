// Section 6 and 7.3 in the loop: the estimator's positions and the AHRS yaw feed one sliding-mode
// controller per UAV; its command, plus Delta_g (eq. 58), drives eq. 53 until the next step (zero-
// order hold, Fig. 7), and the truth follows.
#pragma once

#include <vector>

#include "app/pipeline/loop.hpp"
#include "app/config/run_config.hpp"
#include "control/formation.hpp"
#include "control/sliding_mode.hpp"
#include "sim/closed_loop_truth.hpp"
#include "sim/synthetic_source.hpp"

namespace wingman::app {

class ClosedLoopFlight {
 public:
  // Throws std::invalid_argument when a UAV has no control entry.
  ClosedLoopFlight(const RunConfig& cfg, sim::ClosedLoopTruth& truth, sim::SyntheticSource& ahrs);
  // advance: integrate eq. 53 over the last step; control: new commands from the estimate.
  LoopHooks hooks();
  // The closed-loop part of the record.
  void finish(eval::RunRecord& rec) const;

 private:
  void advance(double t);
  void control(int k, double t, const slam::Estimator& est, eval::StepRecord& st);

  const RunConfig& cfg_;
  sim::ClosedLoopTruth& truth_;
  sim::SyntheticSource& ahrs_;
  sim::InputDisturbance disturbance_;
  std::vector<control::FormationController> ctrl_;
  std::vector<control::UavPose> pose_;
  std::vector<control::BodyVelocity> cmd_;
};

}  // namespace wingman::app
