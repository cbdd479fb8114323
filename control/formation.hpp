// Leader-follower kinematics of paper section 6: the UAV model of eq. 53 (body-frame horizontal
// velocity, world vertical velocity, yaw rate), the formation variables lambda = [lx, ly, lz, psi]
// of eq. 54 (the lead's position in the UAV's yaw frame Q, the height above the lead, the yaw)
// and their dynamics lambda' = g + u of eq. 55-57 with u = [-vx, -vy, vz, w].
#pragma once

#include <Eigen/Core>

namespace wingman::control {

// The inputs of eq. 53: vx, vy in the UAV frame Q, vz in the world frame, w the yaw rate.
struct BodyVelocity {
  double vx = 0, vy = 0, vz = 0, omega = 0;
};

struct UavPose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // x_q, world frame
  double yaw = 0;                                        // psi about world z
};

// Angle in (-pi, pi].
double wrap_angle(double a);

// eq. 53: the world-frame velocity of a UAV at yaw psi under body velocity u.
Eigen::Vector3d world_velocity(double yaw, const BodyVelocity& u);

// eq. 53 integrated exactly over dt with u held constant (the zero-order hold of Fig. 7).
UavPose propagate(const UavPose& q, const BodyVelocity& u, double dt);

// eq. 54: lambda = [lx, ly, lz, psi] of a UAV with respect to the lead at lead_position.
Eigen::Vector4d formation_variables(const Eigen::Vector3d& lead_position, const UavPose& q);

// u of eq. 57 from the UAV's inputs, and back.
Eigen::Vector4d input_vector(const BodyVelocity& u);
BodyVelocity body_velocity(const Eigen::Vector4d& u);

// g of eq. 57: the drift of the formation variables for the lead velocity and the yaw rate.
Eigen::Vector4d drift(const Eigen::Vector4d& lambda, const Eigen::Vector3d& lead_velocity,
                      double omega);

// eq. 55-56: lambda' = g + u.
Eigen::Vector4d formation_rate(const Eigen::Vector4d& lambda, const Eigen::Vector3d& lead_velocity,
                               const BodyVelocity& u);

}  // namespace wingman::control
