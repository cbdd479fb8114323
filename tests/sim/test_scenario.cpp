// The scenario model: Table 1 configurations, phases and outages over time.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "sim/scenario.hpp"

namespace wingman::sim {
namespace {

// Raw string literals start with a newline for readability; drop it so that line 1 is the
// first line of YAML.
std::string doc(const char* text) {
  std::string s(text);
  if (!s.empty() && s.front() == '\n') s.erase(0, 1);
  return s;
}

TEST(ScenarioModel, NamesRoundTrip) {
  for (Sensor s :
       {Sensor::Landmarks, Sensor::LeadProjection, Sensor::Altimeter, Sensor::Range, Sensor::Gps}) {
    EXPECT_EQ(sensor_from_string(to_string(s)), s);
  }
  EXPECT_STREQ(to_string(Sensor::LeadProjection), "lead_projection");
  EXPECT_STREQ(to_string(Sensor::Gps), "gps");
  EXPECT_FALSE(sensor_from_string("GPS").has_value());
  EXPECT_STREQ(to_string(Config::C1), "1");
  EXPECT_STREQ(to_string(Config::C3), "3");
  EXPECT_STREQ(to_string(Config::Integrated), "integrated");
  EXPECT_STREQ(to_string(MeasurementMode::Synthetic), "synthetic");
  EXPECT_STREQ(to_string(MeasurementMode::Rendered), "rendered");
}

TEST(ScenarioModel, SensorsOfFollowsTable1) {
  using S = Sensor;
  EXPECT_EQ(sensors_of(Config::C1), (std::vector<S>{S::Landmarks, S::LeadProjection, S::Gps}));
  EXPECT_EQ(sensors_of(Config::C2), (std::vector<S>{S::Landmarks, S::Altimeter, S::Range, S::Gps}));
  EXPECT_EQ(sensors_of(Config::C3),
            (std::vector<S>{S::Landmarks, S::LeadProjection, S::Altimeter, S::Range}));
  EXPECT_EQ(sensors_of(Config::Integrated).size(), 5u);
}

const std::string kPaper = doc(R"(
duration: 280
phases:
  - {name: c1, from: 0, to: 70, config: 1}
  - {name: c2, from: 70, to: 140, config: 2}
  - {name: c3, from: 140, to: 210, config: 3}
  - {name: all, from: 220, to: 280, config: integrated, add: [], remove: [range]}
outages:
  - {sensor: gps, from: 30, to: 40, agent: lead}
  - {sensor: landmarks, from: 50, to: 60, agent: uav2}
  - {sensor: lead_projection, from: 240, to: 280}
)");

TEST(ScenarioModel, PhaseAtBoundaries) {
  const Scenario s = parse_scenarios(kPaper, "x.yaml").at(0);
  EXPECT_EQ(s.phase_at(-0.1), -1);
  EXPECT_EQ(s.phase_at(0.0), 0);
  EXPECT_EQ(s.phase_at(69.9), 0);
  EXPECT_EQ(s.phase_at(70.0), 1);
  EXPECT_EQ(s.phase_at(700 * 0.1), 1);
  EXPECT_EQ(s.phase_at(139.99), 1);
  EXPECT_EQ(s.phase_at(140.0), 2);
  EXPECT_EQ(s.phase_at(209.9), 2);
  EXPECT_EQ(s.phase_at(210.0), -1);  // gap
  EXPECT_EQ(s.phase_at(215.0), -1);
  EXPECT_EQ(s.phase_at(220.0), 3);
  EXPECT_EQ(s.phase_at(280.0), 3);  // t == duration: the last phase ending there
  EXPECT_EQ(s.phase_at(280.1), -1);

  // The end of a phase that ends before the duration is not inside it.
  Scenario t;
  t.duration = 100;
  t.phases = {Phase{"a", 0, 50, Config::C1, {}, {}, {}, 0}};
  EXPECT_EQ(t.phase_at(50.0), -1);
  EXPECT_EQ(t.phase_at(100.0), -1);
  t.phases.push_back(Phase{"b", 50, 100, Config::C2, {}, {}, {}, 0});
  EXPECT_EQ(t.phase_at(50.0), 1);
  EXPECT_EQ(t.phase_at(100.0), 1);
  // Accumulated time stamps land on the right side of a boundary.
  double acc = 0;
  for (int k = 0; k < 500; ++k) acc += 0.1;
  EXPECT_EQ(t.phase_at(acc), 1);
  EXPECT_EQ(Scenario{}.phase_at(0), -1);
}

TEST(ScenarioModel, SensorActiveTruthTable) {
  const Scenario s = parse_scenarios(kPaper, "x.yaml").at(0);
  using S = Sensor;
  struct Row {
    double t;
    S sensor;
    const char* agent;
    bool active;
  };
  const Row rows[] = {
      // Config 1: landmarks, lead projection, GPS.
      {10, S::Landmarks, "uav1", true},
      {10, S::Landmarks, "uav2", true},
      {10, S::Landmarks, "lead", false},
      {10, S::LeadProjection, "uav1", true},
      {10, S::LeadProjection, "uav2", false},  // uav2 does not see the lead
      {10, S::Gps, "lead", true},
      {10, S::Gps, "uav1", false},
      {10, S::Altimeter, "uav1", false},
      {10, S::Range, "uav1", false},
      {35, S::Gps, "lead", false},  // outage on the lead's GPS
      {40, S::Gps, "lead", true},   // outage window is [30, 40)
      {30, S::Gps, "lead", false},
      // Config 2: landmarks, altimeter, range, GPS.
      {100, S::Landmarks, "uav1", true},
      {100, S::LeadProjection, "uav1", false},
      {100, S::Altimeter, "uav1", true},
      {100, S::Altimeter, "uav2", false},  // uav2 carries no altimeter
      {100, S::Range, "uav1", true},
      {100, S::Range, "uav2", false},
      {100, S::Gps, "lead", true},
      {55, S::Landmarks, "uav2", false},  // outage for uav2 only
      {55, S::Landmarks, "uav1", true},
      // Config 3: landmarks, lead projection, altimeter, range; no GPS.
      {150, S::Gps, "lead", false},
      {150, S::LeadProjection, "uav1", true},
      {150, S::Altimeter, "uav1", true},
      {150, S::Range, "uav1", true},
      {150, S::Landmarks, "uav2", true},
      // Gap between phases: nothing.
      {215, S::Landmarks, "uav1", false},
      {215, S::Gps, "lead", false},
      // Integrated minus range, with a lead-projection outage for everyone from 240 to the end.
      {230, S::Gps, "lead", true},
      {230, S::Altimeter, "uav1", true},
      {230, S::Range, "uav1", false},
      {230, S::LeadProjection, "uav1", true},
      {250, S::LeadProjection, "uav1", false},
      {280, S::LeadProjection, "uav1", false},  // the outage reaches the final step
      {280, S::Landmarks, "uav1", true},
      // Unknown agents carry nothing; outside the scenario nothing is active.
      {10, S::Landmarks, "uav9", false},
      {-1, S::Landmarks, "uav1", false},
      {300, S::Landmarks, "uav1", false},
  };
  for (const Row& r : rows) {
    EXPECT_EQ(s.sensor_active(r.sensor, r.t, r.agent), r.active)
        << "t=" << r.t << " sensor=" << to_string(r.sensor) << " agent=" << r.agent;
  }

  // A lead without GPS never has it; `add` brings a sensor into a preset.
  Scenario t = s;
  t.lead.gps = false;
  EXPECT_FALSE(t.sensor_active(S::Gps, 10, "lead"));
  t = s;
  t.phases[2].add = {S::Gps};
  EXPECT_TRUE(t.sensor_active(S::Gps, 150, "lead"));
  t.phases[0].remove = {S::Landmarks};
  EXPECT_FALSE(t.sensor_active(S::Landmarks, 10, "uav1"));
  EXPECT_EQ(s.uav_index("uav2"), 1);
  EXPECT_EQ(s.uav_index("lead"), -1);
}


}  // namespace
}  // namespace wingman::sim
