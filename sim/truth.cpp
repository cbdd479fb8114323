#include "sim/truth.hpp"

#include <cmath>

#include "geometry/rotation.hpp"
#include "sim/rng.hpp"

namespace wingman::sim {

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
  return k;
}

OpenLoopTruth::OpenLoopTruth(const Scenario& scn)
    : Truth(scn), origin_(lemniscate(scn.lead.trajectory, 0).position) {}

KinematicState OpenLoopTruth::lead(double t) const {
  KinematicState k = lemniscate(scn_.lead.trajectory, t);
  k.position += scn_.lead.initial_position - origin_;
  return k;
}

KinematicState OpenLoopTruth::uav(int j, double t) const {
  KinematicState k = lemniscate(scn_.lead.trajectory, t);
  k.position += scn_.uavs[j].initial_position - origin_;
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
