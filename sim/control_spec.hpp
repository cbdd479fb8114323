// The `control:` section of a scenario (paper section 6 and 7.3): what the closed loop flies.
// A scenario with this section runs in closed loop. sim owns what the truth and the evaluation
// need (initial yaws, the desired formation the truth is scored against, Delta_g, the settling
// time); the controller's gains and limits are control::SlidingModeSettings, read by app/.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace wingman::sim {

// One controlled UAV: its initial yaw and lambda_d (eq. 60); psi_d fixed or the lead's bearing
// atan2(y_h, x_h) from its estimate (section 7.3).
struct UavControlSpec {
  std::string uav;
  double initial_yaw = 0;
  Eigen::Vector3d lambda_d{2.5, 1, 14};
  std::optional<double> yaw_d;  // empty: lead bearing
};

struct ControlSpec {
  // The keys of the control: section that are sim's; the others are the controller's.
  static constexpr std::array<std::string_view, 3> kKeys = {"settling_time", "disturbance", "uavs"};
  bool enabled = false;  // set by the presence of the section
  // Delta_g of eq. 58, added to u = [-vx, -vy, vz, w] of every UAV: each component a sum of two
  // sinusoids with random frequencies and phases, |Delta_g_i| <= bound_i.
  Eigen::Vector4d disturbance_bound = Eigen::Vector4d::Zero();
  std::optional<std::uint64_t> disturbance_seed;  // default: the scenario's seed
  double settling_time = 10.0;                    // s, formation metrics start this long into a phase
  std::vector<UavControlSpec> uavs;               // one per UAV of the scenario
};

// Section 7.3: psi1(0) = 1, psi2(0) = 0.5, lambda_d^1 = [2.5, 1, 14, bearing],
// lambda_d^2 = [0.5, -1, 16, bearing].
std::vector<UavControlSpec> paper_control_uavs();

}  // namespace wingman::sim
