#include "sim/truth.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "geometry/rotation.hpp"
#include "sim/rng.hpp"

namespace wingman::sim {

namespace {

Eigen::Vector3d lemniscate_acceleration(const LeadTrajectorySpec& p, double t) {
  const double w = p.omega, a = p.scale;
  const double s = std::sin(w * t), c = std::cos(w * t);
  const double D = 1 + s * s, D3 = D * D * D;
  // The second derivative, simplified with s^2 + c^2 = 1 (checked against differences in the tests).
  return {-a * w * w * c * (3 * c * c * D - 4 * s * s * (3 - s * s)) / D3,
          -a * w * w * s * c * (10 - 6 * s * s) / D3,
          -p.z_amplitude * p.z_omega * p.z_omega * std::sin(p.z_omega * t)};
}

}  // namespace

KinematicState lemniscate(const LeadTrajectorySpec& p, double t) {
  const double w = p.omega, a = p.scale;
  const double s = std::sin(w * t), c = std::cos(w * t);
  const double D = 1 + s * s;
  KinematicState k;
  k.position = {a * c / D, a * s * c / D, p.z_amplitude * std::sin(p.z_omega * t)};
  // d/dt of a c / D and a s c / D with D' = 2 s c w.
  k.velocity = {-a * w * s * (D + 2 * c * c) / (D * D),
                a * w * (std::cos(2 * w * t) * D - 2 * s * s * c * c) / (D * D),
                p.z_amplitude * p.z_omega * std::cos(p.z_omega * t)};
  k.acceleration = lemniscate_acceleration(p, t);
  const double h = 1e-3;  // s; the difference's error is O(h^2 w^5 a), below 1e-12 m/s^3
  k.jerk = (lemniscate_acceleration(p, t + h) - lemniscate_acceleration(p, t - h)) / (2 * h);
  return k;
}

KinematicState nominal_motion(const LeadTrajectorySpec& p, double t) {
  if (p.type == "line") return {p.velocity * t, p.velocity, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  if (p.spline()) {
    if (!p.path) throw std::logic_error("trajectory '" + p.type + "' has no spline: built by the scenario loader");
    return p.path->at(t);
  }
  return lemniscate(p, t);
}

Turn curve_turn(const LeadTrajectorySpec& p, double t) {
  const KinematicState k = nominal_motion(p, t);
  const Eigen::Vector2d v = k.velocity.head<2>(), a = k.acceleration.head<2>(), j = k.jerk.head<2>();
  const double D = v.squaredNorm();
  if (D < 1e-12) {  // at rest: the direction of the nearest motion, leaving first
    for (double dt : {1e-3, -1e-3, 0.1, -0.1, 1.0, -1.0}) {
      const Eigen::Vector3d w = nominal_motion(p, t + dt).velocity;
      if (w.head<2>().squaredNorm() >= 1e-12) return {std::atan2(w.y(), w.x()), 0, 0};
    }
    return {};
  }
  // psi = atan2(vy, vx): psi' = (v x a) / |v|^2, and its derivative with (v x a)' = v x j.
  const double N = v.x() * a.y() - v.y() * a.x(), dN = v.x() * j.y() - v.y() * j.x();
  const double dD = 2 * v.dot(a);
  return {std::atan2(v.y(), v.x()), N / D, (dN * D - N * dD) / (D * D)};
}

OpenLoopTruth::OpenLoopTruth(const Scenario& scn)
    : Truth(scn),
      origin_(nominal_motion(scn.lead.trajectory, 0).position),
      heading0_(curve_turn(scn.lead.trajectory, 0).heading) {
  const auto& m = scn.noise.motion;
  if (!m.any() || scn.num_steps() < 1) return;
  // The filter's discrete model (slam/motion_model.hpp): p += v dt, then v += a dt, with one
  // acceleration shared by every agent plus each agent's own.
  const std::size_t agents = 1 + scn.uavs.size();
  const int n = scn.num_steps();
  const double dt = scn.dt();
  wander_.assign(agents, std::vector<KinematicState>(static_cast<std::size_t>(n) + 1));
  std::mt19937_64 rng = make_stream(scn.seed, "motion");
  std::normal_distribution<double> unit(0.0, 1.0);
  for (std::size_t k = 0; k < static_cast<std::size_t>(n); ++k) {
    const Eigen::Vector3d common = gaussian3(rng, unit, m.accel_sigma_common);
    for (std::size_t a = 0; a < agents; ++a) {
      const Eigen::Vector3d acc = common + gaussian3(rng, unit, a == 0 ? m.accel_sigma_lead : m.accel_sigma_uav);
      const KinematicState& now = wander_[a][k];
      KinematicState& next = wander_[a][k + 1];
      next.position = now.position + now.velocity * dt;
      next.velocity = now.velocity + acc * dt;
    }
  }
}

KinematicState OpenLoopTruth::agent(std::size_t a, const Eigen::Vector3d& start, double t) const {
  KinematicState k = nominal_motion(scn_.lead.trajectory, t);
  if (wander_.empty()) {
    k.position += start - origin_;
    return k;
  }
  // The deviation, interpolated between steps.
  const auto& w = wander_[a];
  const double s = std::clamp(t / scn_.dt(), 0.0, static_cast<double>(w.size() - 1));
  const auto i = std::min(static_cast<std::size_t>(s), w.size() - 2);
  const double f = s - static_cast<double>(i);
  k.position += start - origin_ + ((1 - f) * w[i].position + f * w[i + 1].position);
  k.velocity += (1 - f) * w[i].velocity + f * w[i + 1].velocity;
  // Within a step the velocity changes linearly: the step's drawn acceleration.
  if (t >= 0 && t < scn_.dt() * static_cast<double>(w.size() - 1))
    k.acceleration += (w[i + 1].velocity - w[i].velocity) / scn_.dt();
  return k;
}

KinematicState OpenLoopTruth::lead(double t) const { return agent(0, scn_.lead.initial_position, t); }

KinematicState OpenLoopTruth::uav(int j, double t) const {
  if (scn_.lead.formation_frame == FormationFrame::World)
    return agent(1 + static_cast<std::size_t>(j), scn_.uavs[j].initial_position, t);
  KinematicState k = agent(1 + static_cast<std::size_t>(j), scn_.lead.initial_position, t);
  const KinematicState o = formation_offset(j, t);
  k.position += o.position;
  k.velocity += o.velocity;
  k.acceleration += o.acceleration;
  return k;
}

// R(psi - psi0) o, with o the offset at t = 0; its derivatives with R' = psi' S R and
// R'' = (psi'' S + psi'^2 S^2) R, S the rotation by +90 deg about z (S^2 = -1 in the plane).
KinematicState OpenLoopTruth::formation_offset(int j, double t) const {
  const Eigen::Vector3d o = scn_.uavs[j].initial_position - scn_.lead.initial_position;
  KinematicState k;
  const Turn turn = curve_turn(scn_.lead.trajectory, t);
  const Eigen::Vector2d r = Eigen::Rotation2Dd(turn.heading - heading0_) * o.head<2>();
  const Eigen::Vector2d Sr(-r.y(), r.x());
  k.position = {r.x(), r.y(), o.z()};
  k.velocity.head<2>() = turn.rate * Sr;
  k.acceleration.head<2>() = turn.acceleration * Sr - turn.rate * turn.rate * r;
  return k;
}

KinematicState Truth::camera(int j, double t) const {
  KinematicState k = uav(j, t);
  k.position += scn_.uavs[j].camera.offset;
  return k;
}

Eigen::Matrix3d Truth::commanded_R_CW() const { return geometry::nadir_R_CW(); }

Truth::Truth(const Scenario& scn) : scn_(scn) {
  gimbal_phase_.assign(scn.uavs.size(), Eigen::Vector2d::Zero());
  if (!scn.noise.gimbal_random_phase) return;
  std::mt19937_64 rng = make_stream(scn.seed, "gimbal");
  std::uniform_real_distribution<double> phase(0.0, 2 * M_PI);
  for (auto& p : gimbal_phase_) p = {phase(rng), phase(rng)};
}

Eigen::Matrix3d Truth::camera_R_CW(int j, double t) const {
  const auto& n = scn_.noise;
  const Eigen::Vector2d phi = gimbal_phase_.at(static_cast<std::size_t>(j));
  const double ex = n.gimbal_amplitude * std::sin(n.gimbal_omega * t + phi.x());
  const double ey = n.gimbal_amplitude * std::sin(n.gimbal_omega * t + phi.y());
  return geometry::rot_x(ex) * geometry::rot_y(ey) * commanded_R_CW();
}

Eigen::Vector4d OpenLoopTruth::horizontal_extent() const {
  Eigen::Vector4d box(INFINITY, INFINITY, -INFINITY, -INFINITY);
  const int n = scn_.num_steps();
  auto grow = [&](const Eigen::Vector3d& p) {
    box(0) = std::min(box(0), p.x());
    box(1) = std::min(box(1), p.y());
    box(2) = std::max(box(2), p.x());
    box(3) = std::max(box(3), p.y());
  };
  for (int k = 0; k <= n; ++k) {
    const double t = k * scn_.dt();
    grow(lead(t).position);
    for (int j = 0; j < static_cast<int>(scn_.uavs.size()); ++j) grow(uav(j, t).position);
  }
  return box;
}

}  // namespace wingman::sim
