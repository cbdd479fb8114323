// What the observability analysis (slam/observability.hpp, paper section 4) evaluates for a
// scenario: the sensor set of a Table 1 preset, the sensors a scenario feeds at time t, and the
// true state of its trajectory there.
#pragma once

#include "app/config/run_config.hpp"
#include "slam/observability.hpp"

namespace wingman::app {

// The sensor set of a Table 1 preset (1, 2 or 3) for n2 UAVs and n1 landmarks.
slam::SensorSet preset(int config, int n2, int n1);
// The sensors a scenario feeds at time t (its phase's configuration and each agent's kit).
slam::SensorSet scenario_sensors(const RunConfig& scn, double t, int n1);
// The true state at t of a scenario's open-loop trajectory with the n1 landmarks of its field
// nearest the UAVs below every camera; an io::UsageError when the field has fewer.
slam::EvaluationPoint scenario_point(const RunConfig& scn, double t, int n1);

}  // namespace wingman::app
