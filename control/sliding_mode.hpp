// The sliding-mode formation controller of paper section 6: the camera-to-body transform of
// eq. 59, the surface s = e + K1 int(e) of eq. 60 and the law u = lambda_d' - K1 e - g - K2 sw(s)
// of eq. 62, with u = [-vx, -vy, vz, w] (eq. 57), then limits on the horizontal speed, the
// vertical speed and the yaw rate. It takes plain numbers (a lead estimate, a camera estimate, a
// yaw), so it runs the same whether they come from synthetic measurements or rendered frames.
#pragma once

#include "geometry/settings.hpp"

#include <Eigen/Core>
#include <optional>

#include "control/formation.hpp"

namespace wingman::control {

// What replaces sign(s) in eq. 62. sign chatters in discrete time: with the command held for a
// step (the ZOH of Fig. 7) s overshoots zero by up to K2 dt and the command flips by 2 K2 every
// step, which shakes the vehicle and breaks the estimator's constant-velocity model. Saturation,
// sat(s / phi), is the default: outside the layer |s| > phi it is exactly sign(s), so the
// reaching condition of eq. 65 holds unchanged there; inside it the law is linear with gain
// K2 / phi, stable in discrete time while K2 dt / phi < 2. tanh(s / phi) is smooth but reaches
// the full K2 only asymptotically (tanh(1) = 0.76).
enum class Switching { Sign, Saturation, Tanh };
const char* to_string(Switching s);

struct SlidingModeSettings {
  Eigen::Vector4d k1 = Eigen::Vector4d::Constant(0.3);  // eq. 60, 1/s
  Eigen::Vector4d k2{1.0, 1.0, 1.0, 0.5};               // eq. 62, m/s and rad/s
  Switching switching = Switching::Saturation;
  Eigen::Vector4d boundary_width{1.0, 1.0, 1.0, 0.3};  // phi, m and rad
  double max_horizontal_speed = 5.0;                   // |(vx, vy)|, m/s
  double max_vertical_speed = 2.0;                     // |vz|, m/s
  double max_yaw_rate = 0.5;                           // |w|, rad/s
  // Largest change of (vx, vy, vz) from one command to the next, per second: a vehicle cannot
  // jump in velocity, and the estimator's constant-velocity model (eq. 33-34) cannot follow one.
  // 0 turns it off.
  double max_acceleration = 1.0;  // m/s^2
  // Freeze the integral of a component whose command hit a limit, so a long saturation does
  // not wind it up.
  bool anti_windup = true;
  // psi_d = atan2(y_h, x_h) is undefined at the origin and jumps with the noise near it: closer
  // than this the last psi_d is held (the UAV's first yaw before any).
  double lead_bearing_min_range = 5.0;  // m

  // The controller's keys of the scenario's control: section (sim owns the others).
  template <class V>
  void visit(V& v) {
    // Gains and limits of a multirotor's velocity loop: the bounds keep a typo from flying the
    // formation out of the world (and the filter with it).
    v("k1", k1, geometry::in(0, 1e3));
    v("k2", k2, geometry::in(0, 1e3, true));
    v.choice("switching", switching,
             {{"sign", Switching::Sign}, {"sat", Switching::Saturation}, {"tanh", Switching::Tanh}});
    v("boundary_width", boundary_width, geometry::gt(0));
    v.section("limits", [&](auto& l) {
      l("horizontal_speed", max_horizontal_speed, geometry::in(0, 100, true));
      l("vertical_speed", max_vertical_speed, geometry::in(0, 100, true));
      l("yaw_rate", max_yaw_rate, geometry::in(0, 10, true));
      l("acceleration", max_acceleration, geometry::in(0, 100));
    });
    v("anti_windup", anti_windup);
    v("lead_bearing_min_range", lead_bearing_min_range, geometry::ge(0));
  }
};

// lambda_d of one UAV: [lx, ly, lz] and either a fixed yaw or the lead's bearing from the world
// origin, atan2(y_h, x_h) (section 7.3).
struct DesiredFormation {
  Eigen::Vector3d position{2.5, 1.0, 14.0};
  std::optional<double> yaw;  // empty: lead bearing
};

// The controller's inputs at one instant.
struct ControllerInput {
  Eigen::Vector3d lead_position = Eigen::Vector3d::Zero();  // estimate of x_h
  Eigen::Vector3d lead_velocity = Eigen::Vector3d::Zero();  // estimate of x_h'
  Eigen::Vector3d camera_position = Eigen::Vector3d::Zero();  // estimate of x_c
  double yaw = 0;                                             // AHRS
};

struct ControllerOutput {
  BodyVelocity command;       // what the UAV flies until the next update
  Eigen::Vector4d lambda;     // estimated formation variables (eq. 54)
  Eigen::Vector4d lambda_d;   // desired ones, psi_d included
  Eigen::Vector4d error;      // e = lambda - lambda_d, psi wrapped
  Eigen::Vector4d surface;    // s of eq. 60
  bool limited = false;       // some limit clipped the command
};

class FormationController {
 public:
  // camera_offset is d of eq. 59 (x_c = x_q + d, world frame, known and constant).
  FormationController(DesiredFormation desired, SlidingModeSettings settings,
                      Eigen::Vector3d camera_offset = Eigen::Vector3d::Zero());

  // One control step: dt is the time since the previous update (0 on the first), over which
  // the integral of eq. 60 accumulates the current error and the acceleration limit applies
  // (the first command starts from rest).
  ControllerOutput update(const ControllerInput& in, double dt);
  void reset();

  const SlidingModeSettings& settings() const { return cfg_; }
  const DesiredFormation& desired() const { return desired_; }

  // sign, sat or tanh of s / phi, componentwise.
  static double switching(Switching kind, double s, double phi);
  // The desired yaw and its rate for a lead at p moving at v (atan2(y, x) and its derivative).
  static Eigen::Vector2d lead_bearing(const Eigen::Vector3d& p, const Eigen::Vector3d& v);

 private:
  DesiredFormation desired_;
  SlidingModeSettings cfg_;
  Eigen::Vector3d offset_;
  Eigen::Vector4d integral_ = Eigen::Vector4d::Zero();
  std::optional<double> held_yaw_;
  Eigen::Vector4d frozen_ = Eigen::Vector4d::Zero();  // 1 where the last command was clipped
  std::optional<Eigen::Vector3d> last_velocity_;       // (vx, vy, vz) of the last command
};

}  // namespace wingman::control
