// The lead's trajectories beyond eq. 66: timed waypoints and TUM/CSV files through a cubic spline,
// and a formation that turns with the lead's heading.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "sim/scenario.hpp"
#include "sim/trajectory.hpp"
#include "sim/truth.hpp"

namespace wingman::sim {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

std::string doc(const char* text) {
  std::string s(text);
  if (!s.empty() && s.front() == '\n') s.erase(0, 1);
  return s;
}

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("wingman_traj_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d / name;
}

void write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

std::string error_of(const std::string& yaml, const std::string& origin = "scn.yaml") {
  try {
    parse_scenarios(yaml, origin);
  } catch (const ScenarioError& e) {
    return e.what();
  }
  return "no error";
}

const std::string kWaypoints = doc(R"(
duration: 40
lead:
  trajectory:
    type: waypoints
    waypoints:
      - [0, 0, 0, 0]
      - [10, 12, 0, 0]
      - [20, 14, 11, 1]
      - [32, 0, 15, 0]
)");

TEST(WaypointPath, PassesEachWaypointAtItsTime) {
  const Scenario s = parse_scenarios(kWaypoints, "scn.yaml").at(0);
  const OpenLoopTruth truth(s);
  for (const auto& r : s.lead.trajectory.waypoints.rows)
    EXPECT_LT((truth.lead(r[0]).position - r.tail<3>()).norm(), 1e-9) << "t = " << r[0];
  // The lead starts at its first waypoint when lead.initial_position is not set.
  EXPECT_LT(s.lead.initial_position.norm(), 1e-12);
}

TEST(WaypointPath, VelocityAndAccelerationAreContinuousAcrossWaypoints) {
  const Scenario s = parse_scenarios(kWaypoints, "scn.yaml").at(0);
  const auto& tr = s.lead.trajectory;
  const double e = 1e-7;
  for (double t : {10.0, 20.0}) {
    const KinematicState a = nominal_motion(tr, t - e), b = nominal_motion(tr, t + e);
    EXPECT_LT((a.velocity - b.velocity).norm(), 1e-5) << t;
    EXPECT_LT((a.acceleration - b.acceleration).norm(), 1e-5) << t;
  }
  // At rest at both ends, so that waiting before the first and after the last is smooth.
  EXPECT_LT(nominal_motion(tr, 1e-9).velocity.norm(), 1e-6);
  EXPECT_LT(nominal_motion(tr, 32 - 1e-9).velocity.norm(), 1e-6);
  EXPECT_LT((nominal_motion(tr, 38).position - Eigen::Vector3d(0, 15, 0)).norm(), 1e-12);
  // Bounded acceleration: a few m/s^2 for these 12-15 m legs.
  double peak = 0;
  for (double t = 0; t <= 32; t += 0.01) peak = std::max(peak, nominal_motion(tr, t).acceleration.norm());
  EXPECT_GT(peak, 0.1);
  EXPECT_LT(peak, 2.0);
}

TEST(WaypointPath, DerivativesAreThoseOfTheCurve) {
  const Scenario s = parse_scenarios(kWaypoints, "scn.yaml").at(0);
  const auto& tr = s.lead.trajectory;
  const double h = 1e-4;
  for (double t : {3.3, 11.0, 25.7}) {
    const KinematicState k = nominal_motion(tr, t);
    const KinematicState p = nominal_motion(tr, t + h), m = nominal_motion(tr, t - h);
    EXPECT_LT((k.velocity - (p.position - m.position) / (2 * h)).norm(), 1e-6);
    EXPECT_LT((k.acceleration - (p.velocity - m.velocity) / (2 * h)).norm(), 1e-6);
    EXPECT_LT((k.jerk - (p.acceleration - m.acceleration) / (2 * h)).norm(), 1e-6);
  }
}

TEST(WaypointPath, OutOfOrderWaypointIsAnErrorNamingItsLine) {
  const std::string yaml = doc(R"(
lead:
  trajectory:
    type: waypoints
    waypoints:
      - [0, 0, 0, 0]
      - [10, 5, 0, 0]
      - [8, 9, 0, 0]
)");
  EXPECT_THAT(error_of(yaml), HasSubstr("scn.yaml:7:9: lead.trajectory.waypoints[2]: time 8 is not after the "
                                        "previous waypoint's (10)"));
  EXPECT_THAT(error_of("lead: {trajectory: {type: waypoints}}\n"), HasSubstr("type waypoints needs"));
  EXPECT_THAT(error_of("lead: {trajectory: {waypoints: [[0, 0, 0, 0], [1, 1, 0, 0]]}}\n"),
              HasSubstr("lead.trajectory.waypoints: is used by type waypoints; this trajectory's type is lemniscate"));
  EXPECT_THAT(error_of("lead: {trajectory: {type: waypoints, waypoints: [[0, 0, 0]]}}\n"),
              HasSubstr("expected a list of at least 2 waypoints"));
}

TEST(TrajectoryFile, TumFileReadBackReproducesItsPoses) {
  const fs::path f = scratch("lead.tum");
  write(f, "# timestamp tx ty tz qx qy qz qw\n"
           "1403636580.0 10 20 1 0 0 0 1\n"
           "1403636581.0 11 20.5 1.1 0 0 0.0998334 0.9950042\n"
           "\n"
           "1403636582.5 12.5 21 1.0 0 0 0.1986693 0.9800666\n");
  const auto samples = read_trajectory_file(f.string(), TrajectoryFormat::Tum);
  ASSERT_EQ(samples.size(), 3u);
  EXPECT_DOUBLE_EQ(samples[0].t, 0.0);
  EXPECT_NEAR(samples[2].t, 2.5, 1e-6);
  const SplinePath path(samples, SplineEnds::Rest);
  const Eigen::Vector3d expected[] = {{10, 20, 1}, {11, 20.5, 1.1}, {12.5, 21, 1.0}};
  const double yaw[] = {0.0, 0.2, 0.4};
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT((path.at(samples[i].t).position - expected[i]).norm(), 1e-9) << i;
    const Eigen::Quaterniond q = *path.orientation(samples[i].t);
    EXPECT_NEAR(2 * std::atan2(q.z(), q.w()), yaw[i], 1e-6) << i;
  }
}

TEST(TrajectoryFile, CsvWithHeaderReads) {
  const fs::path f = scratch("lead.csv");
  write(f, "t,x,y,z\n5,0,0,0\n6,1.5,0,0\n7,3,0.5,0\n");
  const auto samples = read_trajectory_file(f.string(), TrajectoryFormat::Csv);
  ASSERT_EQ(samples.size(), 3u);
  EXPECT_DOUBLE_EQ(samples[1].t, 1.0);
  EXPECT_FALSE(samples[1].orientation.has_value());
  EXPECT_EQ(samples[2].position, Eigen::Vector3d(3, 0.5, 0));
}

TEST(TrajectoryFile, MalformedLineIsAnErrorNamingFileLineAndKey) {
  const fs::path f = scratch("bad.csv");
  write(f, "t,x,y,z\n0,0,0,0\n1,1,zero,0\n");
  const fs::path scn = scratch("bad_file.yaml");
  const std::string yaml = doc(R"(
lead:
  trajectory: {type: file, file: bad.csv}
)");
  EXPECT_THAT(error_of(yaml, scn.string()),
              HasSubstr(scn.string() + ":2:34: lead.trajectory.file: " + f.string() +
                        ":3: column 3 (y): 'zero' is not a finite number"));
  write(f, "0 0 0 0 0 0 0 1\n1 1 0 0 0 0 0\n");
  EXPECT_THAT(error_of(doc("lead: {trajectory: {type: file, file: bad.csv, format: tum}}\n"), scn.string()),
              HasSubstr(":2: expected 8 fields (timestamp tx ty tz qx qy qz qw), got 7"));
  write(f, "0,0,0,0\n2,1,0,0\n1,2,0,0\n");
  EXPECT_THAT(error_of(doc("lead: {trajectory: {type: file, file: bad.csv}}\n"), scn.string()),
              HasSubstr(":3: time 1 is not after the previous sample's (2)"));
  EXPECT_THAT(error_of(doc("lead: {trajectory: {type: file, file: none.csv}}\n"), scn.string()),
              HasSubstr("none.csv: file not found"));
  EXPECT_THAT(error_of(doc("lead: {trajectory: {type: file, file: lead.gpx}}\n"), scn.string()),
              HasSubstr("cannot tell its format"));
}

// A formation in the lead's heading frame: each UAV's offset turns with the lead.
TEST(HeadingFormation, OffsetsTurnWithTheLeadAndVelocitiesAreDerivatives) {
  Scenario s = parse_scenarios(doc(R"(
lead: {formation_frame: heading}
uavs:
  - {name: uav1, initial_position: [-4, 3, 15]}
  - {name: uav2, initial_position: [2, -5, 17]}
)"), "scn.yaml").at(0);
  const OpenLoopTruth truth(s);
  const double psi0 = curve_turn(s.lead.trajectory, 0).heading;
  const double h = 1e-4;
  for (double t : {0.0, 17.0, 55.0, 120.0}) {
    const double dpsi = curve_turn(s.lead.trajectory, t).heading - psi0;
    for (int j = 0; j < 2; ++j) {
      const Eigen::Vector3d o0 = s.uavs[j].initial_position - s.lead.initial_position;
      const Eigen::Vector3d o = truth.uav(j, t).position - truth.lead(t).position;
      EXPECT_NEAR(o.head<2>().norm(), o0.head<2>().norm(), 1e-9);
      EXPECT_NEAR(o.z(), o0.z(), 1e-9);
      const double turned = std::atan2(o.y(), o.x()) - std::atan2(o0.y(), o0.x());
      EXPECT_NEAR(std::remainder(turned - dpsi, 2 * M_PI), 0, 1e-9) << t;
      const KinematicState k = truth.uav(j, t), p = truth.uav(j, t + h), m = truth.uav(j, t - h);
      EXPECT_LT((k.velocity - (p.position - m.position) / (2 * h)).norm(), 1e-6) << t;
      EXPECT_LT((k.acceleration - (p.velocity - m.velocity) / (2 * h)).norm(), 1e-5) << t;
    }
  }
  // The lemniscate turns through more than 90 degrees in its first 60 s.
  EXPECT_GT(std::abs(curve_turn(s.lead.trajectory, 60).heading - psi0), M_PI / 2);
}

TEST(HeadingFormation, WorldFrameKeepsTheOffsetFixed) {
  const Scenario s = parse_scenarios("uavs: [{name: uav1, initial_position: [-4, 3, 15]}]\n", "scn.yaml").at(0);
  const OpenLoopTruth truth(s);
  EXPECT_LT((truth.uav(0, 55).position - truth.lead(55).position - Eigen::Vector3d(-4, 3, 15)).norm(), 1e-9);
}

}  // namespace
}  // namespace wingman::sim
