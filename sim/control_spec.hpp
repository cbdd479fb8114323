// The `control:` section of a scenario (paper section 6 and 7.3): what the closed loop flies.
// A scenario with this section runs in closed loop. sim owns what the truth and the evaluation
// need (initial yaws, the desired formation the truth is scored against, Delta_g, the settling
// time); the controller's gains and limits are control::SlidingModeSettings, read by app/.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "geometry/settings.hpp"
#include "sim/limits.hpp"

namespace wingman::sim {

// A yaw set-point as a file writes it: a yaw in radians, or `lead_bearing` (empty).
struct YawSetpoint {
  std::optional<double>& yaw;
};

// One controlled UAV: its initial yaw and lambda_d (eq. 60); psi_d fixed or the lead's bearing
// atan2(y_h, x_h) from its estimate (section 7.3).
struct UavControlSpec {
  std::string uav;
  double initial_yaw = 0;
  Eigen::Vector3d lambda_d{2.5, 1, 14};
  std::optional<double> yaw_d;  // empty: lead bearing

  template <class V>
  void visit(V& v) {
    v.required("name");
    v("name", uav);
    v("initial_yaw", initial_yaw, geometry::in(-2 * M_PI, 2 * M_PI));
    // The formation's offset from the lead: within the world's bounds.
    v("lambda_d", lambda_d, geometry::in(-RunLimits::kMaxCoordinate, RunLimits::kMaxCoordinate));
    YawSetpoint yaw{yaw_d};
    v("yaw_d", yaw, geometry::in(-2 * M_PI, 2 * M_PI));
  }
};
inline constexpr geometry::ListNames kControlUavList{"controlled UAVs", "controlled UAV", 1};

struct ControlSpec {
  bool enabled = false;  // set by the presence of the section
  // Delta_g of eq. 58, added to u = [-vx, -vy, vz, w] of every UAV: each component a sum of two
  // sinusoids with random frequencies and phases, |Delta_g_i| <= bound_i.
  Eigen::Vector4d disturbance_bound = Eigen::Vector4d::Zero();
  std::optional<std::uint64_t> disturbance_seed;  // default: the scenario's seed
  double settling_time = 10.0;                    // s, formation metrics start this long into a phase
  std::vector<UavControlSpec> uavs;               // one per UAV of the scenario

  // sim's keys of the section (the controller's are control::SlidingModeSettings').
  template <class V>
  void visit(V& v) {
    v("settling_time", settling_time, geometry::ge(0));
    v.section("disturbance", [&](auto& d) {
      d("bound", disturbance_bound, geometry::ge(0));
      d.optional("seed", disturbance_seed);
    });
    v.list("uavs", uavs, kControlUavList);
  }
};

// Section 7.3: psi1(0) = 1, psi2(0) = 0.5, lambda_d^1 = [2.5, 1, 14, bearing],
// lambda_d^2 = [0.5, -1, 16, bearing].
std::vector<UavControlSpec> paper_control_uavs();

}  // namespace wingman::sim
