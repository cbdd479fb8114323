// The scenario model's non-inline functions (docs/design.md, the estimator and files). The YAML loader lives in
// scenario_yaml.cpp.
#include "sim/scenario.hpp"

#include <algorithm>
#include <cmath>

namespace wingman::sim {

namespace {

// Time stamps are usually computed as k * dt or by accumulating dt; a boundary written as 70 in the
// YAML must not flip phase because k * dt came out as 69.99999999999999. Boundaries are therefore
// compared with this tolerance (s), far below any sensible sampling period.
constexpr double kTimeEps = 1e-9;

bool contains(const std::vector<Sensor>& v, Sensor s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

// Whether t lies in [t_start, t_end), with t == duration counting as inside a window that ends at
// the scenario's end (so the final step belongs to the last phase / outage, not after it).
bool covers(double t_start, double t_end, double t, double duration) {
  if (t >= t_start - kTimeEps && t < t_end - kTimeEps) return true;
  return std::abs(t - duration) <= kTimeEps && std::abs(t_end - duration) <= kTimeEps &&
         t >= t_start - kTimeEps;
}

}  // namespace

const char* to_string(Sensor s) {
  switch (s) {
    case Sensor::Landmarks:
      return "landmarks";
    case Sensor::LeadProjection:
      return "lead_projection";
    case Sensor::Altimeter:
      return "altimeter";
    case Sensor::Range:
      return "range";
    case Sensor::Gps:
      return "gps";
  }
  return "unknown";
}

std::optional<Sensor> sensor_from_string(const std::string& s) {
  for (Sensor k :
       {Sensor::Landmarks, Sensor::LeadProjection, Sensor::Altimeter, Sensor::Range, Sensor::Gps}) {
    if (s == to_string(k)) return k;
  }
  return std::nullopt;
}

const char* to_string(Config c) {
  switch (c) {
    case Config::C1:
      return "1";
    case Config::C2:
      return "2";
    case Config::C3:
      return "3";
    case Config::Integrated:
      return "integrated";
  }
  return "unknown";
}

std::vector<Sensor> sensors_of(Config c) {
  switch (c) {
    case Config::C1:
      return {Sensor::Landmarks, Sensor::LeadProjection, Sensor::Gps};
    case Config::C2:
      return {Sensor::Landmarks, Sensor::Altimeter, Sensor::Range, Sensor::Gps};
    case Config::C3:
      return {Sensor::Landmarks, Sensor::LeadProjection, Sensor::Altimeter, Sensor::Range};
    case Config::Integrated:
      return {Sensor::Landmarks, Sensor::LeadProjection, Sensor::Altimeter, Sensor::Range,
              Sensor::Gps};
  }
  return {};
}

const char* to_string(MeasurementMode m) {
  switch (m) {
    case MeasurementMode::Synthetic:
      return "synthetic";
    case MeasurementMode::Rendered:
      return "rendered";
  }
  return "unknown";
}

int Scenario::num_steps() const { return static_cast<int>(std::llround(duration * rate)); }

int Scenario::phase_at(double t) const {
  for (std::size_t i = 0; i < phases.size(); ++i) {
    const Phase& p = phases[i];
    if (t >= p.t_start - kTimeEps && t < p.t_end - kTimeEps) return static_cast<int>(i);
  }
  // t == duration: the last phase that ends there.
  if (std::abs(t - duration) <= kTimeEps) {
    for (std::size_t i = phases.size(); i-- > 0;) {
      if (std::abs(phases[i].t_end - duration) <= kTimeEps) return static_cast<int>(i);
    }
  }
  return -1;
}

bool Scenario::sensor_active(Sensor s, double t, const std::string& agent) const {
  const int pi = phase_at(t);
  if (pi < 0) return false;
  const Phase& phase = phases[static_cast<std::size_t>(pi)];
  const bool in_set = (contains(sensors_of(phase.config), s) || contains(phase.add, s)) &&
                      !contains(phase.remove, s);
  if (!in_set) return false;

  // Does the agent carry this sensor at all?
  if (agent == "lead") {
    if (s != Sensor::Gps || !lead.gps) return false;
  } else {
    const int ui = uav_index(agent);
    if (ui < 0) return false;
    const UavSpec& u = uavs[static_cast<std::size_t>(ui)];
    switch (s) {
      case Sensor::Gps:
        return false;
      case Sensor::Landmarks:
        break;
      case Sensor::LeadProjection:
        if (!u.sees_lead) return false;
        break;
      case Sensor::Altimeter:
        if (!u.altimeter) return false;
        break;
      case Sensor::Range:
        if (!u.range) return false;
        break;
    }
  }

  for (const Outage& o : outages) {
    if (o.sensor != s) continue;
    if (!o.agent.empty() && o.agent != agent) continue;
    if (covers(o.t_start, o.t_end, t, duration)) return false;
  }
  return true;
}

std::string Scenario::uav_names() const {
  std::string out;
  for (const UavSpec& u : uavs) out += (out.empty() ? "" : ", ") + u.name;
  return out;
}

int Scenario::uav_index(const std::string& name) const {
  for (std::size_t i = 0; i < uavs.size(); ++i) {
    if (uavs[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace wingman::sim

namespace wingman::sim {

std::vector<UavControlSpec> paper_control_uavs() {
  UavControlSpec u1{"uav1", 1.0, {2.5, 1, 14}, std::nullopt};
  UavControlSpec u2{"uav2", 0.5, {0.5, -1, 16}, std::nullopt};
  return {u1, u2};
}

}  // namespace wingman::sim
