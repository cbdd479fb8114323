#include "control/sliding_mode.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace wingman::control {

const char* to_string(Switching s) {
  switch (s) {
    case Switching::Sign: return "sign";
    case Switching::Saturation: return "sat";
    case Switching::Tanh: return "tanh";
  }
  return "?";
}

FormationController::FormationController(DesiredFormation desired, SlidingModeSettings settings,
                                         Eigen::Vector3d camera_offset)
    : desired_(std::move(desired)), cfg_(std::move(settings)), offset_(std::move(camera_offset)) {
  if ((cfg_.k1.array() < 0).any() || (cfg_.k2.array() <= 0).any())
    throw std::invalid_argument("FormationController: K1 must be >= 0 and K2 > 0");
  if (cfg_.switching != Switching::Sign && (cfg_.boundary_width.array() <= 0).any())
    throw std::invalid_argument("FormationController: the boundary layer width must be > 0");
}

void FormationController::reset() {
  integral_.setZero();
  frozen_.setZero();
  held_yaw_.reset();
  last_velocity_.reset();
}

double FormationController::switching(Switching kind, double s, double phi) {
  switch (kind) {
    case Switching::Sign: return s > 0 ? 1.0 : (s < 0 ? -1.0 : 0.0);
    case Switching::Saturation: return std::clamp(s / phi, -1.0, 1.0);
    case Switching::Tanh: return std::tanh(s / phi);
  }
  return 0;
}

Eigen::Vector2d FormationController::lead_bearing(const Eigen::Vector3d& p, const Eigen::Vector3d& v) {
  const double r2 = p.x() * p.x() + p.y() * p.y();
  return {std::atan2(p.y(), p.x()), r2 > 0 ? (p.x() * v.y() - p.y() * v.x()) / r2 : 0.0};
}

ControllerOutput FormationController::update(const ControllerInput& in, double dt) {
  ControllerOutput out;
  const UavPose q{in.camera_position - offset_, in.yaw};  // eq. 59
  out.lambda = formation_variables(in.lead_position, q);

  // lambda_d and its rate; only psi_d moves.
  double psi_d = 0, psi_d_rate = 0;
  if (desired_.yaw) {
    psi_d = *desired_.yaw;
  } else if (in.lead_position.head<2>().norm() >= cfg_.lead_bearing_min_range) {
    const Eigen::Vector2d b = lead_bearing(in.lead_position, in.lead_velocity);
    psi_d = b(0);
    psi_d_rate = b(1);
    held_yaw_ = psi_d;
  } else {
    if (!held_yaw_) held_yaw_ = in.yaw;
    psi_d = *held_yaw_;
  }
  out.lambda_d << desired_.position, psi_d;
  out.error = out.lambda - out.lambda_d;
  out.error(3) = wrap_angle(out.error(3));

  // eq. 60 with the rectangle rule; frozen components keep their integral (anti-windup).
  for (int i = 0; i < 4; ++i)
    if (!(cfg_.anti_windup && frozen_(i) != 0)) integral_(i) += out.error(i) * dt;
  out.surface = out.error + cfg_.k1.cwiseProduct(integral_);

  Eigen::Vector4d sw;
  for (int i = 0; i < 4; ++i)
    sw(i) = switching(cfg_.switching, out.surface(i), cfg_.boundary_width(i));
  const Eigen::Vector4d lambda_d_rate(0, 0, 0, psi_d_rate);
  const Eigen::Vector4d base = lambda_d_rate - cfg_.k1.cwiseProduct(out.error) - cfg_.k2.cwiseProduct(sw);

  // eq. 62. g depends on w (eq. 57), so the yaw rate comes first, after its limit.
  frozen_.setZero();
  const double omega_raw = base(3);  // g_4 = 0
  const double omega = std::clamp(omega_raw, -cfg_.max_yaw_rate, cfg_.max_yaw_rate);
  if (omega != omega_raw) frozen_(3) = 1;
  const Eigen::Vector4d g = drift(out.lambda, in.lead_velocity, omega);
  Eigen::Vector4d u = base - g;
  u(3) = omega;
  BodyVelocity cmd = body_velocity(u);

  const double vh = std::hypot(cmd.vx, cmd.vy);
  if (vh > cfg_.max_horizontal_speed) {
    const double k = cfg_.max_horizontal_speed / vh;
    cmd.vx *= k;
    cmd.vy *= k;
    frozen_(0) = frozen_(1) = 1;
  }
  const double vz = std::clamp(cmd.vz, -cfg_.max_vertical_speed, cfg_.max_vertical_speed);
  if (vz != cmd.vz) frozen_(2) = 1;
  cmd.vz = vz;
  if (cfg_.max_acceleration > 0) {
    const Eigen::Vector3d prev = last_velocity_.value_or(Eigen::Vector3d::Zero());
    const Eigen::Vector3d v(cmd.vx, cmd.vy, cmd.vz);
    const double dv_max = cfg_.max_acceleration * std::max(dt, 0.0);
    if ((v - prev).norm() > dv_max) {
      const Eigen::Vector3d lim = prev + (v - prev) * (dv_max / (v - prev).norm());
      cmd.vx = lim.x();
      cmd.vy = lim.y();
      cmd.vz = lim.z();  // a rate limit, not a saturation: the integral keeps running
    }
  }
  last_velocity_ = Eigen::Vector3d(cmd.vx, cmd.vy, cmd.vz);
  out.command = cmd;
  out.limited = frozen_.any();
  return out;
}

}  // namespace wingman::control
