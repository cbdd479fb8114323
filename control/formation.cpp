#include "control/formation.hpp"

#include <cmath>

namespace wingman::control {

double wrap_angle(double a) {
  a = std::remainder(a, 2 * M_PI);  // in [-pi, pi]
  return a <= -M_PI ? a + 2 * M_PI : a;
}

Eigen::Vector3d world_velocity(double yaw, const BodyVelocity& u) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  return {u.vx * c - u.vy * s, u.vx * s + u.vy * c, u.vz};
}

UavPose propagate(const UavPose& q, const BodyVelocity& u, double dt) {
  UavPose out;
  out.yaw = q.yaw + u.omega * dt;
  // Integrals of cos(psi) and sin(psi) over the step; the small-angle branch avoids 0/0.
  double ic, is;
  const double dpsi = u.omega * dt;
  if (std::abs(dpsi) > 1e-6) {
    ic = (std::sin(out.yaw) - std::sin(q.yaw)) / u.omega;
    is = (std::cos(q.yaw) - std::cos(out.yaw)) / u.omega;
  } else {
    const double mid = q.yaw + 0.5 * dpsi;
    ic = std::cos(mid) * dt;
    is = std::sin(mid) * dt;
  }
  out.position = q.position + Eigen::Vector3d(u.vx * ic - u.vy * is, u.vx * is + u.vy * ic, u.vz * dt);
  out.yaw = wrap_angle(out.yaw);
  return out;
}

Eigen::Vector4d formation_variables(const Eigen::Vector3d& h, const UavPose& q) {
  const double c = std::cos(q.yaw), s = std::sin(q.yaw);
  const Eigen::Vector3d d = h - q.position;
  return {d.x() * c + d.y() * s, -d.x() * s + d.y() * c, q.position.z() - h.z(), q.yaw};
}

Eigen::Vector4d input_vector(const BodyVelocity& u) { return {-u.vx, -u.vy, u.vz, u.omega}; }

BodyVelocity body_velocity(const Eigen::Vector4d& u) { return {-u(0), -u(1), u(2), u(3)}; }

Eigen::Vector4d drift(const Eigen::Vector4d& l, const Eigen::Vector3d& vh, double omega) {
  const double c = std::cos(l(3)), s = std::sin(l(3));
  return {omega * l(1) + vh.x() * c + vh.y() * s, -omega * l(0) - vh.x() * s + vh.y() * c, -vh.z(),
          0.0};
}

Eigen::Vector4d formation_rate(const Eigen::Vector4d& lambda, const Eigen::Vector3d& vh,
                               const BodyVelocity& u) {
  return drift(lambda, vh, u.omega) + input_vector(u);
}

}  // namespace wingman::control
