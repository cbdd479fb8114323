#include "app/pipeline/observability_point.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "io/usage_error.hpp"
#include "sim/synthetic_source.hpp"
#include "sim/truth.hpp"

namespace wingman::app {

// The sensor set of a Table 1 preset: Quad 1 sees the lead and carries the altimeter and the
// range sensor (paper section 7, docs/design.md, frames and conventions).
slam::SensorSet preset(int config, int n2, int n1) {
  slam::SensorSet s = slam::SensorSet::empty(n2, n1);
  const auto c = config == 1 ? sim::Config::C1 : config == 2 ? sim::Config::C2 : sim::Config::C3;
  for (sim::Sensor k : sim::sensors_of(c)) {
    if (k == sim::Sensor::LeadProjection) s.sees_lead[0] = true;
    if (k == sim::Sensor::Altimeter) s.altimeter[0] = true;
    if (k == sim::Sensor::Range) s.range[0] = true;
    if (k == sim::Sensor::Gps) s.gps = true;
  }
  return s;
}

// The sensors a scenario feeds at time t (its phase's configuration and each agent's kit).
slam::SensorSet scenario_sensors(const RunConfig& scn, double t, int n1) {
  const int n2 = static_cast<int>(scn.uavs.size());
  slam::SensorSet s = slam::SensorSet::empty(n2, 0, false);
  for (int j = 0; j < n2; ++j) {
    const std::string& name = scn.uavs[static_cast<std::size_t>(j)].name;
    const auto u = static_cast<std::size_t>(j);
    s.sees_lead[u] = scn.sensor_active(sim::Sensor::LeadProjection, t, name);
    s.altimeter[u] = scn.sensor_active(sim::Sensor::Altimeter, t, name);
    s.range[u] = scn.sensor_active(sim::Sensor::Range, t, name);
    if (scn.sensor_active(sim::Sensor::Landmarks, t, name))
      for (int i = 0; i < n1; ++i) s.visibility[u].push_back(i);
  }
  s.gps = scn.sensor_active(sim::Sensor::Gps, t, "lead");
  return s;
}

// The true state at t of a scenario's open-loop trajectory, with the n1 landmarks of its field
// nearest (horizontally) to the UAVs that lie in front of every camera.
slam::EvaluationPoint scenario_point(const RunConfig& scn, double t, int n1) {
  const sim::OpenLoopTruth truth(scn);
  const int n2 = static_cast<int>(scn.uavs.size());
  std::vector<Eigen::Vector3d> cp, cv;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double lowest = INFINITY;
  slam::EvaluationPoint p;
  for (int j = 0; j < n2; ++j) {
    const sim::KinematicState c = truth.camera(j, t);
    cp.push_back(c.position);
    cv.push_back(c.velocity);
    centre += c.position.head<2>() / n2;
    lowest = std::min(lowest, c.position.z());
    slam::CameraRig rig;
    rig.model = scn.uavs[static_cast<std::size_t>(j)].camera.camera();
    rig.R_CW = truth.commanded_R_CW();
    rig.offset = scn.uavs[static_cast<std::size_t>(j)].camera.offset;
    p.rigs.push_back(rig);
  }
  std::vector<Eigen::Vector3d> field = sim::make_landmark_field(scn, truth);
  field.erase(std::remove_if(field.begin(), field.end(),
                             [&](const Eigen::Vector3d& a) { return a.z() > lowest - 1.0; }),
              field.end());
  if (static_cast<int>(field.size()) < n1)
    throw io::UsageError(fmt::format("{}: its landmark field has only {} points below the cameras",
                                 scn.source_path, field.size()));
  std::partial_sort(field.begin(), field.begin() + n1, field.end(),
                    [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
                      return (a.head<2>() - centre).squaredNorm() < (b.head<2>() - centre).squaredNorm();
                    });
  field.resize(static_cast<std::size_t>(n1));
  const sim::KinematicState lead = truth.lead(t);
  p.state = slam::make_filter_state(lead.position, lead.velocity, cp, cv, field);
  return p;
}

}  // namespace wingman::app
