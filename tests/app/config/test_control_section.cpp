// The control: section (closed loop, paper section 6 and 7.3): sim's part (initial yaws, desired
// formation, Delta_g, settling time) and the controller's (gains, switching, limits) read from one
// map, with defaults, overrides, and errors that name the file, line and key.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "app/config/run_config.hpp"

namespace wingman::app {
namespace {

using ::testing::HasSubstr;

std::vector<RunConfig> parse_scenarios(const std::string& text, const std::string& origin) {
  return parse_run_configs(text, origin);
}

std::string error_of(const std::string& yaml) {
  try {
    parse_scenarios(yaml, "cl.yaml");
  } catch (const sim::ScenarioError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a ScenarioError for:\n" << yaml;
  return "";
}

TEST(ControlSpec, AbsentSectionIsOpenLoop) {
  const auto s = parse_scenarios("seed: 3\n", "a.yaml").front();
  EXPECT_FALSE(s.closed_loop());
}

TEST(ControlSpec, EmptySectionGivesSection73Defaults) {
  const auto s = parse_scenarios("control: {}\n", "a.yaml").front();
  ASSERT_TRUE(s.closed_loop());
  ASSERT_EQ(s.control.uavs.size(), 2u);
  EXPECT_EQ(s.control.uavs[0].uav, "uav1");
  EXPECT_EQ(s.control.uavs[0].initial_yaw, 1.0);
  EXPECT_EQ(s.control.uavs[0].lambda_d, Eigen::Vector3d(2.5, 1, 14));
  EXPECT_FALSE(s.control.uavs[0].yaw_d.has_value());
  EXPECT_EQ(s.control.uavs[1].initial_yaw, 0.5);
  EXPECT_EQ(s.control.uavs[1].lambda_d, Eigen::Vector3d(0.5, -1, 16));
  EXPECT_EQ(s.controller.switching, control::Switching::Saturation);
  EXPECT_EQ(s.control.settling_time, 10.0);
  EXPECT_EQ(s.control.disturbance_bound, Eigen::Vector4d::Zero());
}

TEST(ControlSpec, Overrides) {
  const auto s = parse_scenarios(R"(control:
  k1: 0.4
  k2: [2, 2, 1.5, 0.7]
  switching: tanh
  limits: {horizontal_speed: 3, yaw_rate: 0.2, acceleration: 0}
  disturbance: {bound: [0.1, 0.2, 0.3, 0.01], seed: 9}
  uavs:
    - {name: uav1, initial_yaw: -0.5, lambda_d: [1, 2, 3], yaw_d: 0.25}
    - {name: uav2}
)", "a.yaml").front();
  EXPECT_EQ(s.controller.k1, Eigen::Vector4d::Constant(0.4));
  EXPECT_EQ(s.controller.k2, Eigen::Vector4d(2, 2, 1.5, 0.7));
  EXPECT_EQ(s.controller.switching, control::Switching::Tanh);
  EXPECT_EQ(s.controller.max_horizontal_speed, 3.0);
  EXPECT_EQ(s.controller.max_acceleration, 0.0);
  EXPECT_EQ(*s.control.disturbance_seed, 9u);
  EXPECT_EQ(s.control.uavs[0].yaw_d, std::optional<double>(0.25));
  EXPECT_EQ(s.control.uavs[0].lambda_d, Eigen::Vector3d(1, 2, 3));
}

TEST(ControlSpec, Errors) {
  EXPECT_THAT(error_of("control:\n  gains: 1\n"),
              HasSubstr("cl.yaml:2:3: control.gains: unknown key 'gains'"));
  EXPECT_THAT(error_of("control:\n  k2: [1, 0, 1, 1]\n"),
              HasSubstr("cl.yaml:2:11: control.k2[1]: must be in (0, 1000], got 0"));
  EXPECT_THAT(error_of("control:\n  k1: [1, 1, 1]\n"),
              HasSubstr("control.k1: expected a number or a list of 4 numbers"));
  EXPECT_THAT(error_of("control:\n  switching: sgn\n"),
              HasSubstr("cl.yaml:2:14: control.switching: expected one of sign, sat, tanh, got 'sgn'"));
  EXPECT_THAT(error_of("control:\n  uavs:\n    - {name: uav1, yaw_d: north}\n    - {name: uav2}\n"),
              HasSubstr("control.uavs[0].yaw_d: expected lead_bearing or a yaw in radians"));
  EXPECT_THAT(error_of("control:\n  uavs:\n    - {name: uav1}\n"),
              HasSubstr("control.uavs: UAV 'uav2' has no entry"));
  EXPECT_THAT(error_of("control:\n  uavs:\n    - {name: uav1}\n    - {name: uav2}\n    - {name: uav7}\n"),
              HasSubstr("'uav7' is not a UAV of this scenario"));
  EXPECT_THAT(error_of("control:\n  limits: {yaw_rate: -1}\n"),
              HasSubstr("control.limits.yaw_rate: must be in (0, 10], got -1"));
  EXPECT_THAT(error_of("estimator: {mode: single}\ncontrol: {}\n"),
              HasSubstr("closed loop (the control: section) needs mode multi"));
}

}  // namespace
}  // namespace wingman::app
