#include "app/pipeline/closed_loop.hpp"

#include <algorithm>
#include <stdexcept>

namespace wingman::app {

namespace {
constexpr int kSubsteps = 10;  // Delta_g varies within a step; the command does not (ZOH)
}

ClosedLoopFlight::ClosedLoopFlight(const RunConfig& cfg, sim::ClosedLoopTruth& truth,
                                   sim::SyntheticSource& ahrs)
    : cfg_(cfg),
      truth_(truth),
      ahrs_(ahrs),
      disturbance_(cfg.control.disturbance_bound, static_cast<int>(cfg.uavs.size()),
                   cfg.control.disturbance_seed.value_or(cfg.seed)),
      cmd_(cfg.uavs.size()) {
  for (const auto& uav : cfg.uavs) {
    const auto it = std::find_if(cfg.control.uavs.begin(), cfg.control.uavs.end(),
                                 [&](const sim::UavControlSpec& c) { return c.uav == uav.name; });
    if (it == cfg.control.uavs.end()) throw std::invalid_argument("no control entry for " + uav.name);
    ctrl_.emplace_back(control::DesiredFormation{it->lambda_d, it->yaw_d}, cfg.controller, uav.camera.offset);
    pose_.push_back({uav.initial_position, it->initial_yaw});
  }
}

LoopHooks ClosedLoopFlight::hooks() {
  LoopHooks h;
  h.advance = [this](int, double t) { advance(t); };
  h.control = [this](int k, double t, const slam::Estimator& est, eval::StepRecord& st) { control(k, t, est, st); };
  return h;
}

void ClosedLoopFlight::advance(double t) {
  const double dt = cfg_.dt(), h = dt / kSubsteps;
  for (std::size_t j = 0; j < pose_.size(); ++j) {
    control::UavPose q = pose_[j];
    const double t0 = t - dt;
    for (int i = 0; i < kSubsteps; ++i) {
      const Eigen::Vector4d u =
          control::input_vector(cmd_[j]) + disturbance_(static_cast<int>(j), t0 + (i + 0.5) * h);
      q = control::propagate(q, control::body_velocity(u), h);
    }
    const Eigen::Vector3d v = (q.position - pose_[j].position) / dt;
    pose_[j] = q;
    truth_.set_uav(static_cast<int>(j), q.position, v, q.yaw);
  }
  truth_.set_time(t);
}

void ClosedLoopFlight::control(int k, double t, const slam::Estimator& est, eval::StepRecord& st) {
  const auto lead = truth_.lead(t);
  for (std::size_t j = 0; j < pose_.size(); ++j) {
    const int cam = static_cast<int>(j);
    control::ControllerInput in;
    in.lead_position = est.lead_position();
    in.lead_velocity = est.lead_velocity();
    in.camera_position = est.camera_position(cam);
    in.yaw = ahrs_.ahrs_yaw(cam, t);
    const auto out = ctrl_[j].update(in, k == 0 ? 0.0 : cfg_.dt());
    cmd_[j] = out.command;
    eval::FormationStep f;
    f.position_true = pose_[j].position;
    f.yaw_true = pose_[j].yaw;
    f.yaw_ahrs = in.yaw;
    f.lambda_est = out.lambda;
    f.lambda_d_est = out.lambda_d;
    f.surface = out.surface;
    f.command = {cmd_[j].vx, cmd_[j].vy, cmd_[j].vz, cmd_[j].omega};
    f.limited = out.limited;
    f.lambda_true = control::formation_variables(lead.position, pose_[j]);
    // The formation the truth asked for: the same lambda_d with psi_d from the true lead
    // (the controller's held psi_d while the bearing is undefined near the origin).
    f.lambda_d_true = out.lambda_d;
    const auto& d = ctrl_[j].desired();
    if (d.yaw)
      f.lambda_d_true(3) = *d.yaw;
    else if (lead.position.head<2>().norm() >= cfg_.controller.lead_bearing_min_range)
      f.lambda_d_true(3) = control::FormationController::lead_bearing(lead.position, lead.velocity)(0);
    st.formation.push_back(f);
  }
}

void ClosedLoopFlight::finish(eval::RunRecord& rec) const {
  rec.closed_loop = true;
  for (const auto& u : cfg_.uavs) rec.formation_uavs.push_back(u.name);
  rec.settling_time = cfg_.control.settling_time;
}

}  // namespace wingman::app
