// Paper section 6: the formation dynamics (eq. 55) against a numerical derivative of eq. 54, the
// sliding-mode law (eq. 60-62) driving the errors to zero with a perfect state, reaching the
// surface under a disturbance bounded below K2 (eq. 65), and the limits.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "control/formation.hpp"
#include "control/sliding_mode.hpp"

namespace wingman::control {
namespace {

TEST(Formation, WrapAngle) {
  EXPECT_NEAR(wrap_angle(3 * M_PI / 2), -M_PI / 2, 1e-12);
  EXPECT_NEAR(wrap_angle(-M_PI), M_PI, 1e-12);
  EXPECT_NEAR(wrap_angle(0.3 + 4 * M_PI), 0.3, 1e-12);
}

TEST(Formation, PropagateMatchesFineEulerIntegrationOfEq53) {
  const UavPose q0{{1, -2, 10}, 0.4};
  const BodyVelocity u{1.2, -0.7, 0.3, 0.6};
  UavPose e = q0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    e.position += world_velocity(e.yaw, u) * (2.0 / n);
    e.yaw += u.omega * (2.0 / n);
  }
  const UavPose q = propagate(q0, u, 2.0);
  EXPECT_LT((q.position - e.position).norm(), 1e-4);
  EXPECT_NEAR(q.yaw, wrap_angle(e.yaw), 1e-9);
  // The straight-line branch (w = 0).
  const UavPose s = propagate(q0, {1, 0, 0, 0}, 2.0);
  EXPECT_NEAR(s.position.x(), 1 + 2 * std::cos(0.4), 1e-12);
  EXPECT_NEAR(s.position.y(), -2 + 2 * std::sin(0.4), 1e-12);
}

// eq. 55 is the time derivative of eq. 54 along eq. 53 and a moving lead.
TEST(Formation, Eq55AgreesWithNumericalDerivativeOfEq54) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-3, 3);
  const double h = 1e-5;
  double worst = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const UavPose q{{U(rng), U(rng), 10 + U(rng)}, U(rng)};
    const BodyVelocity u{U(rng), U(rng), U(rng), U(rng) / 3};
    const Eigen::Vector3d h0(U(rng) * 5, U(rng) * 5, U(rng)), vh(U(rng), U(rng), U(rng) / 3);
    const Eigen::Vector4d lp = formation_variables(h0 + vh * h, propagate(q, u, h));
    const Eigen::Vector4d lm = formation_variables(h0 - vh * h, propagate(q, u, -h));
    Eigen::Vector4d num = (lp - lm) / (2 * h);
    num(3) = wrap_angle(lp(3) - lm(3)) / (2 * h);
    const Eigen::Vector4d ana = formation_rate(formation_variables(h0, q), vh, u);
    worst = std::max(worst, (num - ana).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 1e-6);
}

TEST(SlidingMode, SwitchingFunctions) {
  EXPECT_EQ(FormationController::switching(Switching::Sign, -0.01, 1), -1.0);
  EXPECT_EQ(FormationController::switching(Switching::Saturation, 0.25, 0.5), 0.5);
  EXPECT_EQ(FormationController::switching(Switching::Saturation, 3, 0.5), 1.0);
  EXPECT_NEAR(FormationController::switching(Switching::Tanh, 0.5, 0.5), std::tanh(1.0), 1e-15);
}

// A lead on a straight line at constant velocity; the controller sees the exact state.
struct Sim {
  Eigen::Vector3d h0{20, 5, 0}, vh{0.8, 1.1, 0.1};
  Eigen::Vector3d lead(double t) const { return h0 + vh * t; }
};

TEST(SlidingMode, PerfectStateNoDisturbanceErrorsConvergeToZero) {
  for (bool bearing : {false, true}) {
    const Sim sim;
    DesiredFormation d{{2.5, 1, 14}, bearing ? std::nullopt : std::optional<double>(0.7)};
    SlidingModeSettings cfg;
    const Eigen::Vector3d offset(0.1, 0, -0.2);  // eq. 59
    FormationController c(d, cfg, offset);
    UavPose q{{18, 3, 15}, 1.5};
    const double dt = 0.1;
    ControllerOutput out;
    for (int k = 0; k <= 1200; ++k) {
      const double t = k * dt;
      out = c.update({sim.lead(t), sim.vh, q.position + offset, q.yaw}, k == 0 ? 0 : dt);
      q = propagate(q, out.command, dt);
    }
    EXPECT_LT(out.error.head<3>().cwiseAbs().maxCoeff(), 1e-3) << "bearing " << bearing;
    EXPECT_LT(std::abs(out.error(3)), 1e-3) << "bearing " << bearing;
    // The truth agrees: the formation the controller sees is the real one.
    const Eigen::Vector4d l = formation_variables(sim.lead(120.1), q);  // q is one step on
    EXPECT_NEAR(l(0), 2.5, 0.05);
    EXPECT_NEAR(l(1), 1.0, 0.05);
    EXPECT_NEAR(l(2), 14.0, 0.05);
  }
}

// eq. 65: with |Delta_g| <= eps < K2 and sign(s), V = s's/2 decreases and each |s_i| reaches
// zero no later than |s_i(0)| / (K2 - eps).
TEST(SlidingMode, DisturbanceBelowK2ReachesTheSurface) {
  const Sim sim;
  SlidingModeSettings cfg;
  cfg.switching = Switching::Sign;
  cfg.k2 = Eigen::Vector4d(1.0, 1.0, 1.0, 0.5);
  cfg.max_horizontal_speed = cfg.max_vertical_speed = cfg.max_yaw_rate = 100;
  cfg.max_acceleration = 0;
  const Eigen::Vector4d eps(0.6, 0.6, 0.6, 0.0);  // w undisturbed: Delta_g enters eq. 58 exactly
  FormationController c({{2.5, 1, 14}, 0.3}, cfg);
  UavPose q{{17, 8, 16}, 1.0};
  const double dt = 1e-3;
  auto dist = [&](double t) {
    return Eigen::Vector4d(eps(0) * std::sin(0.7 * t), eps(1) * std::cos(1.3 * t + 1),
                           eps(2) * std::sin(2.1 * t + 2), 0.0);
  };
  Eigen::Vector4d s0 = Eigen::Vector4d::Zero(), reached = Eigen::Vector4d::Constant(-1);
  double v_prev = INFINITY;
  int v_increases = 0;
  for (int k = 0; k <= 8000; ++k) {
    const double t = k * dt;
    const auto out = c.update({sim.lead(t), sim.vh, q.position, q.yaw}, k == 0 ? 0 : dt);
    if (k == 0) s0 = out.surface;
    const double v = 0.5 * out.surface.squaredNorm();
    if (reached.minCoeff() < 0 && v > v_prev + 1e-9) ++v_increases;
    v_prev = v;
    for (int i = 0; i < 4; ++i)
      if (reached(i) < 0 && std::abs(out.surface(i)) < 5e-3) reached(i) = t;
    const Eigen::Vector4d u = input_vector(out.command) + dist(t + 0.5 * dt);
    q = propagate(q, body_velocity(u), dt);
  }
  ASSERT_GT(s0.head<3>().cwiseAbs().minCoeff(), 0.5);  // the test starts off the surface
  EXPECT_EQ(v_increases, 0);
  for (int i = 0; i < 4; ++i) {
    ASSERT_GE(reached(i), 0) << "component " << i << " never reached s = 0";
    EXPECT_LE(reached(i), std::abs(s0(i)) / (cfg.k2(i) - eps(i)) + 0.02) << "component " << i;
  }
}

TEST(SlidingMode, LimitsAreRespected) {
  SlidingModeSettings cfg;
  cfg.max_horizontal_speed = 2.0;
  cfg.max_vertical_speed = 0.5;
  cfg.max_yaw_rate = 0.3;
  cfg.max_acceleration = 1.0;
  FormationController c({{2.5, 1, 14}, std::nullopt}, cfg);
  UavPose q{{-40, 30, 2}, -2.5};  // far from the formation: every limit is hit
  const Sim sim;
  const double dt = 0.1;
  BodyVelocity prev{};
  bool any_limited = false;
  for (int k = 0; k <= 400; ++k) {
    const auto out = c.update({sim.lead(k * dt), sim.vh, q.position, q.yaw}, k == 0 ? 0 : dt);
    const BodyVelocity& u = out.command;
    EXPECT_LE(std::hypot(u.vx, u.vy), 2.0 + 1e-12);
    EXPECT_LE(std::abs(u.vz), 0.5 + 1e-12);
    EXPECT_LE(std::abs(u.omega), 0.3 + 1e-12);
    const double dv = Eigen::Vector3d(u.vx - prev.vx, u.vy - prev.vy, u.vz - prev.vz).norm();
    EXPECT_LE(dv, 1.0 * dt + 1e-9) << "k=" << k;
    any_limited |= out.limited;
    prev = u;
    q = propagate(q, u, dt);
  }
  EXPECT_TRUE(any_limited);
}

TEST(SlidingMode, RejectsBadGains) {
  SlidingModeSettings cfg;
  cfg.k2(1) = 0;
  EXPECT_THROW(FormationController({}, cfg), std::invalid_argument);
}

}  // namespace
}  // namespace wingman::control
