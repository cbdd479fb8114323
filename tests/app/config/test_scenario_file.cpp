// The scenario file as a user writes it: every section read strictly into the settings of the
// module that owns it, with file:line:col and key path in every error.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "app/config/run_config.hpp"

namespace wingman::app {
namespace {

using sim::Config;
using sim::MeasurementMode;
using sim::ScenarioError;
using sim::Sensor;
using slam::EstimatorMode;
using Scenario = RunConfig;

std::vector<RunConfig> parse_scenarios(const std::string& text, const std::string& origin) {
  return parse_run_configs(text, origin);
}
std::vector<RunConfig> load_scenarios(const std::string& path) { return load_run_configs(path); }

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

// Raw string literals start with a newline for readability; drop it so that line 1 is the
// first line of YAML.
std::string doc(const char* text) {
  std::string s(text);
  if (!s.empty() && s.front() == '\n') s.erase(0, 1);
  return s;
}

// 1-based line of the first line containing `needle`.
int line_of(const std::string& text, const std::string& needle) {
  const auto pos = text.find(needle);
  if (pos == std::string::npos) {
    ADD_FAILURE() << "'" << needle << "' not in the document";
    return -1;
  }
  return 1 +
         static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(pos), '\n'));
}

std::string error_of(const std::string& yaml, const std::string& origin = "scn.yaml") {
  try {
    parse_scenarios(yaml, origin);
  } catch (const ScenarioError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a ScenarioError for:\n" << yaml;
  return "";
}

std::string at_line(const std::string& text, const std::string& needle,
                    const std::string& origin = "scn.yaml") {
  return origin + ":" + std::to_string(line_of(text, needle)) + ":";
}

const std::string kFull = doc(R"(
name: paper_synthetic
duration: 210
rate: 20
seed: 7
measurements: synthetic
lead:
  initial_position: [1, 2, 3]
  gps: true
  trajectory: {type: lemniscate, scale: 80, omega: 0.02, z_amplitude: 1.5, z_omega: 0.04}
uavs:
  - name: uav1
    initial_position: [-1.5, 0, 15]
    sees_lead: true
    altimeter: true
    range: true
    camera: {fx: 300, fy: 310, cx: 320, cy: 240, width: 640, height: 480,
             distortion: [0.1, -0.05, 0.001, 0.002], offset: [0, 0, -0.2]}
  - name: uav2
    initial_position: [1.5, 0, 17]
noise: {pixel_sigma: 2, gps_sigma: 1.0, outlier_fraction: 0.1}
landmarks: {density: 0.05, margin: 40}
phases:
  - {name: config1, from: 0, to: 70, config: 1}
  - {name: config2, from: 70, to: 140, config: 2, add: [lead_projection], remove: [gps]}
  - {name: config3, from: 140, to: 210, config: 3}
outages:
  - {sensor: gps, from: 105, to: 210, agent: lead}
  - {sensor: altimeter, from: 10, to: 20}
estimator:
  mode: multi
  single_uav: uav1
  process_noise: {accel_sigma_lead: 0.1, accel_sigma_uav: 0.2, accel_sigma_common: 0.3,
                  common_acceleration_state: {sigma: 0.05, time_constant: 60}}
  measurement_noise: {pixel_sigma: 4}
  initial_sigma: {position: 0.01, velocity: 0.02}
  gating: {probability: 0.99, one_point_ransac: false, ransac_inlier_px: 3,
           ransac_success_probability: 0.95, ransac_max_hypotheses: 50}
  map: {max_landmarks: 200, target_per_camera: 30, max_misses: 7, image_margin_px: 12}
  initialisation: {min_parallax_deg: 2, max_reprojection_px: 8, min_depth_m: 4.5,
                   low_parallax_inverse_depth: true,
                   inverse_depth_rho: 0.1, inverse_depth_sigma: 0.05, linearity_threshold: 0.2}
variants:
  - name: multi
    estimator: {mode: multi}
  - name: single-short
    seed: 9
    duration: 100
    phases:
      - {from: 0, to: 100, config: integrated}
    outages: []
    noise: {pixel_sigma: 5}
    estimator: {mode: single, gating: {probability: 0.9}}
)");

TEST(ScenarioYaml, FullDocumentParses) {
  const auto all = parse_scenarios(kFull, "dir/paper.yaml");
  ASSERT_EQ(all.size(), 2u);
  const Scenario& s = all[0];
  EXPECT_EQ(s.source_path, "dir/paper.yaml");
  EXPECT_EQ(s.name, "paper_synthetic");
  EXPECT_EQ(s.variant, "multi");
  EXPECT_DOUBLE_EQ(s.duration, 210);
  EXPECT_DOUBLE_EQ(s.rate, 20);
  EXPECT_DOUBLE_EQ(s.dt(), 0.05);
  EXPECT_EQ(s.num_steps(), 4200);
  EXPECT_EQ(s.seed, 7u);
  EXPECT_EQ(s.lead.initial_position, Eigen::Vector3d(1, 2, 3));
  EXPECT_DOUBLE_EQ(s.lead.trajectory.scale, 80);
  EXPECT_DOUBLE_EQ(s.lead.trajectory.z_omega, 0.04);
  ASSERT_EQ(s.uavs.size(), 2u);
  EXPECT_EQ(s.uavs[0].name, "uav1");
  EXPECT_TRUE(s.uavs[0].sees_lead);
  EXPECT_DOUBLE_EQ(s.uavs[0].camera.fy, 310);
  EXPECT_EQ(s.uavs[0].camera.width, 640);
  EXPECT_EQ(s.uavs[0].camera.height, 480);
  EXPECT_DOUBLE_EQ(s.uavs[0].camera.distortion.k2, -0.05);
  EXPECT_DOUBLE_EQ(s.uavs[0].camera.distortion.p2, 0.002);
  EXPECT_DOUBLE_EQ(s.uavs[0].camera.distortion.k3, 0.0);
  EXPECT_DOUBLE_EQ(s.uavs[0].camera.offset.z(), -0.2);
  // A listed UAV carries every sensor unless its entry switches one off.
  EXPECT_TRUE(s.uavs[1].sees_lead);
  EXPECT_TRUE(s.uavs[1].altimeter);
  EXPECT_TRUE(s.uavs[1].range);
  EXPECT_DOUBLE_EQ(s.uavs[1].camera.fx, 200.1);
  EXPECT_DOUBLE_EQ(s.noise.pixel_sigma, 2);
  EXPECT_DOUBLE_EQ(s.noise.outlier_fraction, 0.1);
  EXPECT_DOUBLE_EQ(s.noise.range_sigma, 0.5);  // default
  EXPECT_DOUBLE_EQ(s.field.density, 0.05);
  EXPECT_DOUBLE_EQ(s.field.height_spread, 2.0);  // default
  ASSERT_EQ(s.phases.size(), 3u);
  EXPECT_EQ(s.phases[1].name, "config2");
  EXPECT_EQ(s.phases[1].config, Config::C2);
  EXPECT_EQ(s.phases[1].add, std::vector<Sensor>{Sensor::LeadProjection});
  EXPECT_EQ(s.phases[1].remove, std::vector<Sensor>{Sensor::Gps});
  EXPECT_EQ(s.phases[2].config, Config::C3);
  ASSERT_EQ(s.outages.size(), 2u);
  EXPECT_EQ(s.outages[0].agent, "lead");
  EXPECT_EQ(s.outages[1].sensor, Sensor::Altimeter);
  EXPECT_EQ(s.outages[1].agent, "");
  EXPECT_EQ(s.estimator.mode, EstimatorMode::MultiUav);
  EXPECT_DOUBLE_EQ(s.estimator.process_noise.accel_sigma_uav, 0.2);
  EXPECT_DOUBLE_EQ(s.estimator.process_noise.accel_sigma_common, 0.3);
  EXPECT_DOUBLE_EQ(s.estimator.process_noise.common_state_sigma, 0.05);
  EXPECT_DOUBLE_EQ(s.estimator.process_noise.common_state_time_constant, 60);
  EXPECT_DOUBLE_EQ(s.estimator.measurement_noise.pixel_sigma, 4);
  EXPECT_DOUBLE_EQ(s.estimator.measurement_noise.gps_sigma, 1.5);  // default
  EXPECT_DOUBLE_EQ(s.estimator.initial_sigma.velocity, 0.02);
  EXPECT_DOUBLE_EQ(s.estimator.gating.probability, 0.99);
  EXPECT_FALSE(s.estimator.gating.one_point_ransac);
  EXPECT_EQ(s.estimator.gating.ransac_max_hypotheses, 50);
  EXPECT_EQ(s.estimator.map.max_landmarks, 200);
  EXPECT_EQ(s.estimator.map.target_per_camera, 30);
  EXPECT_EQ(s.estimator.map.max_misses, 7);
  EXPECT_DOUBLE_EQ(s.estimator.initialisation.min_parallax_deg, 2);
  EXPECT_DOUBLE_EQ(s.estimator.initialisation.min_depth_m, 4.5);
  EXPECT_TRUE(s.estimator.initialisation.low_parallax_inverse_depth);
  EXPECT_DOUBLE_EQ(s.estimator.initialisation.linearity_threshold, 0.2);

  // The second variant: overrides on top of the base, maps merged key by key.
  const Scenario& v = all[1];
  EXPECT_EQ(v.variant, "single-short");
  EXPECT_EQ(v.name, "paper_synthetic");
  EXPECT_EQ(v.seed, 9u);
  EXPECT_DOUBLE_EQ(v.duration, 100);
  EXPECT_DOUBLE_EQ(v.rate, 20);  // from the base
  EXPECT_EQ(v.estimator.mode, EstimatorMode::SingleUav);
  EXPECT_DOUBLE_EQ(v.estimator.gating.probability, 0.9);
  EXPECT_EQ(v.estimator.gating.ransac_max_hypotheses, 50);  // base gating kept
  EXPECT_FALSE(v.estimator.gating.one_point_ransac);
  EXPECT_DOUBLE_EQ(v.noise.pixel_sigma, 5);
  EXPECT_DOUBLE_EQ(v.noise.gps_sigma, 1.0);  // base noise kept
  ASSERT_EQ(v.phases.size(), 1u);            // list replaced wholesale
  EXPECT_EQ(v.phases[0].name, "phase1");
  EXPECT_EQ(v.phases[0].config, Config::Integrated);
  EXPECT_TRUE(v.outages.empty());
  // The base is untouched by the variant.
  EXPECT_EQ(all[0].phases.size(), 3u);
}

TEST(ScenarioYaml, MissingSectionsGivePaperDefaults) {
  const auto all = parse_scenarios("seed: 3\n", "scenes/minimal.yaml");
  ASSERT_EQ(all.size(), 1u);
  const Scenario& s = all[0];
  EXPECT_EQ(s.variant, "");
  EXPECT_EQ(s.name, "minimal");
  EXPECT_EQ(s.source_path, "scenes/minimal.yaml");
  EXPECT_EQ(s.seed, 3u);
  EXPECT_DOUBLE_EQ(s.duration, 210);
  EXPECT_DOUBLE_EQ(s.rate, 10);
  EXPECT_EQ(s.num_steps(), 2100);
  EXPECT_EQ(s.measurements, MeasurementMode::Synthetic);
  EXPECT_TRUE(s.lead.gps);
  EXPECT_EQ(s.lead.trajectory.type, "lemniscate");
  EXPECT_DOUBLE_EQ(s.lead.trajectory.omega, 0.015);
  ASSERT_EQ(s.uavs.size(), 2u);
  EXPECT_EQ(s.uavs[0].name, "uav1");
  EXPECT_EQ(s.uavs[0].initial_position, Eigen::Vector3d(-1.5, 0, 15));
  EXPECT_TRUE(s.uavs[0].sees_lead);
  EXPECT_TRUE(s.uavs[0].altimeter);
  EXPECT_TRUE(s.uavs[0].range);
  EXPECT_EQ(s.uavs[1].name, "uav2");
  EXPECT_EQ(s.uavs[1].initial_position, Eigen::Vector3d(1.5, 0, 17));
  EXPECT_FALSE(s.uavs[1].sees_lead);
  EXPECT_FALSE(s.uavs[1].altimeter);
  EXPECT_FALSE(s.uavs[1].range);
  EXPECT_DOUBLE_EQ(s.uavs[1].camera.fx, 200.1);
  EXPECT_EQ(s.uavs[1].camera.width, 1000);
  ASSERT_EQ(s.phases.size(), 1u);
  EXPECT_EQ(s.phases[0].name, "all");
  EXPECT_EQ(s.phases[0].config, Config::Integrated);
  EXPECT_DOUBLE_EQ(s.phases[0].t_start, 0);
  EXPECT_DOUBLE_EQ(s.phases[0].t_end, 210);
  EXPECT_TRUE(s.outages.empty());
  EXPECT_EQ(s.estimator.mode, EstimatorMode::MultiUav);
  EXPECT_EQ(s.estimator.single_uav, "uav1");
  EXPECT_DOUBLE_EQ(s.estimator.gating.probability, 0.999);
  EXPECT_EQ(s.estimator.map.max_landmarks, 150);
  EXPECT_DOUBLE_EQ(s.noise.outlier_max_px, 15);
  EXPECT_DOUBLE_EQ(s.field.density, 0.02);
}

TEST(ScenarioYaml, DefaultPhaseFollowsVariantDuration) {
  const auto all = parse_scenarios(doc(R"(
duration: 50
variants:
  - {name: a}
  - {name: b, duration: 20}
)"),
                                   "x.yaml");
  ASSERT_EQ(all.size(), 2u);
  EXPECT_DOUBLE_EQ(all[0].phases.at(0).t_end, 50);
  EXPECT_DOUBLE_EQ(all[1].phases.at(0).t_end, 20);
  EXPECT_EQ(all[1].num_steps(), 200);
}

TEST(ScenarioYaml, MisspelledDeepKeyNamesFileLineKeyAndSuggestion) {
  const std::string y = doc(R"(
duration: 100
estimator:
  mode: multi
  gating:
    one_point_ransac: true
    probabilty: 0.99
)");
  const std::string msg = error_of(y);
  EXPECT_EQ(msg,
            "scn.yaml:6:5: estimator.gating.probabilty: unknown key 'probabilty' "
            "(did you mean 'probability'?)");
  EXPECT_THAT(msg, StartsWith(at_line(y, "probabilty")));
}

TEST(ScenarioYaml, UnknownKeyWithoutCloseMatchHasNoSuggestion) {
  const std::string msg = error_of("noise: {pixel_sigma: 1, banana: 2}\n");
  EXPECT_THAT(msg, HasSubstr("scn.yaml:1:25: noise.banana: unknown key 'banana'"));
  EXPECT_THAT(msg, Not(HasSubstr("did you mean")));
  EXPECT_THAT(error_of("durration: 3\n"), HasSubstr("(did you mean 'duration'?)"));
}

TEST(ScenarioYaml, WrongTypesNameLineAndKey) {
  EXPECT_EQ(error_of("duration: 10\nrate: abc\n"),
            "scn.yaml:2:7: rate: expected a number, got 'abc'");
  const std::string y = doc(R"(
uavs:
  - name: a
  - name: b
    camera:
      fx: fast
)");
  EXPECT_EQ(error_of(y), "scn.yaml:5:11: uavs[1].camera.fx: expected a number, got 'fast'");
  EXPECT_EQ(error_of("lead: {gps: maybe}\n"),
            "scn.yaml:1:13: lead.gps: expected true or false, got 'maybe'");
  EXPECT_THAT(error_of("lead:\n  initial_position: [1, 2]\n"),
              HasSubstr("scn.yaml:2:21: lead.initial_position: expected a list of 3 numbers"));
  EXPECT_THAT(error_of("lead:\n  initial_position: [1, x, 2]\n"),
              HasSubstr("scn.yaml:2:25: lead.initial_position[1]: expected a number, got 'x'"));
  EXPECT_THAT(error_of("estimator:\n  map: {max_misses: 2.5}\n"),
              HasSubstr("scn.yaml:2:21: estimator.map.max_misses: expected an integer, got '2.5'"));
  EXPECT_THAT(error_of("seed: 1.5\n"), HasSubstr("seed: expected an integer"));
  EXPECT_THAT(error_of("noise:\n  pixel_sigma: 1\nnoise:\n"),
              HasSubstr("scn.yaml:3:1: noise: duplicate key 'noise' (first at line 1)"));
  EXPECT_THAT(error_of("estimator:\n  gating: {probability: }\n"),
              HasSubstr("scn.yaml:2:12: estimator.gating.probability: expected a number, got "
                        "nothing"));
  EXPECT_THAT(
      error_of("phases:\n  - {from: 0, to: 10, config: 1, add: gps}\n"),
      HasSubstr("scn.yaml:2:39: phases[0].add: expected a list of sensor names, got 'gps'"));
  EXPECT_THAT(error_of("noise: [1, 2]\n"),
              HasSubstr("scn.yaml:1:8: noise: expected a map, got a list"));
  EXPECT_THAT(error_of("duration:\n"),
              HasSubstr("scn.yaml:1:1: duration: expected a number, got nothing"));
  EXPECT_THAT(error_of("uavs:\n  - name: a\n    camera: {distortion: [1, 2, 3]}\n  - name: b\n"),
              HasSubstr("scn.yaml:3:26: uavs[0].camera.distortion: expected a list of 4 or 5"));
  EXPECT_THAT(
      error_of("phases:\n  - {from: 0, to: 210, config: 4}\n"),
      HasSubstr("scn.yaml:2:32: phases[0].config: expected 1, 2, 3 or integrated, got '4'"));
  EXPECT_THAT(error_of("phases:\n  - {from: 0, to: 210, config: 1, add: [gsp]}\n"),
              HasSubstr("phases[0].add[0]: unknown sensor 'gsp' (did you mean 'gps'?)"));
  EXPECT_THAT(error_of("estimator: {mode: solo}\n"),
              HasSubstr("estimator.mode: expected one of multi, single, got 'solo'"));
  EXPECT_THAT(error_of("measurements: photos\n"),
              HasSubstr("scn.yaml:1:15: measurements: unknown measurement mode 'photos'"));
  EXPECT_THAT(error_of("lead: {trajectory: {type: circle}}\n"),
              HasSubstr("lead.trajectory.type: expected one of lemniscate, line, waypoints, file, got 'circle'"));
  EXPECT_THAT(error_of("noise: {motion: {accel_sigma_lead: -0.1}}\n"),
              HasSubstr("noise.motion.accel_sigma_lead: must be in [0, 100], got -0.1"));
  EXPECT_THAT(error_of("noise: {motion: {accel_sigma: 0.1}}\n"),
              HasSubstr("scn.yaml:1:18: noise.motion.accel_sigma: unknown key 'accel_sigma'"));
}

TEST(ScenarioYaml, LineTrajectoryAndTruthMotionNoise) {
  const Scenario s = parse_scenarios(
      "lead: {trajectory: {type: line, velocity: [1, 2, 0]}}\n"
      "noise: {motion: {accel_sigma_lead: 0.01, accel_sigma_uav: 0.02, accel_sigma_common: 0.03}}\n",
      "x.yaml")[0];
  EXPECT_EQ(s.lead.trajectory.type, "line");
  EXPECT_EQ(s.lead.trajectory.velocity, Eigen::Vector3d(1, 2, 0));
  EXPECT_EQ(s.noise.motion.accel_sigma_lead, 0.01);
  EXPECT_EQ(s.noise.motion.accel_sigma_uav, 0.02);
  EXPECT_EQ(s.noise.motion.accel_sigma_common, 0.03);
  EXPECT_FALSE(parse_scenarios("seed: 1\n", "x.yaml")[0].noise.motion.any());
  EXPECT_FALSE(parse_scenarios("seed: 1\n", "x.yaml")[0].estimator.initial_sigma.draw);
  EXPECT_TRUE(parse_scenarios("estimator: {initial_sigma: {position: 0.5, draw: true}}\n", "x.yaml")[0]
                  .estimator.initial_sigma.draw);
}

TEST(ScenarioYaml, ValuesOutOfRange) {
  const std::string y = doc(R"(
estimator:
  gating:
    probability: 1.0
)");
  EXPECT_EQ(error_of(y), "scn.yaml:3:18: estimator.gating.probability: must be in (0, 1), got 1.0");
  EXPECT_THAT(error_of("duration: 0\n"), HasSubstr("scn.yaml:1:11: duration: must be > 0, got 0"));
  EXPECT_THAT(error_of("rate: 0\n"), HasSubstr("rate: must be in (0, 1000], got 0"));
  EXPECT_THAT(error_of("rate: 1001\n"), HasSubstr("rate: must be in (0, 1000], got 1001"));
  EXPECT_NO_THROW(parse_scenarios("rate: 1000\n", "x.yaml"));
  EXPECT_THAT(error_of("seed: -1\n"), HasSubstr("seed: must be >= 0, got -1"));
  EXPECT_EQ(parse_scenarios("seed: 18446744073709551615\n", "x.yaml")[0].seed,
            18446744073709551615ull);
  EXPECT_THAT(error_of("noise: {gps_sigma: -0.1}\n"), HasSubstr("noise.gps_sigma: must be in [0, 10000]"));
  EXPECT_THAT(error_of("noise: {outlier_fraction: 1.5}\n"),
              HasSubstr("noise.outlier_fraction: must be in [0, 1], got 1.5"));
  EXPECT_THAT(error_of("landmarks: {density: 0}\n"), HasSubstr("landmarks.density: must be > 0"));
  EXPECT_THAT(error_of("uavs:\n  - {name: a, camera: {width: 0}}\n  - {name: b}\n"),
              HasSubstr("uavs[0].camera.width: must be in [1, 16384], got 0"));
  EXPECT_THAT(error_of("estimator: {initialisation: {min_parallax_deg: 90}}\n"),
              HasSubstr("estimator.initialisation.min_parallax_deg: must be in [0, 90), got 90"));
  EXPECT_THAT(error_of("estimator: {initialisation: {min_depth_m: -1}}\n"),
              HasSubstr("estimator.initialisation.min_depth_m: must be >= 0, got -1"));
  EXPECT_THAT(error_of("estimator: {initialisation: {low_parallax_inverse_depth: 2}}\n"),
              HasSubstr("expected true or false, got '2'"));
  EXPECT_THAT(error_of("estimator: {map: {max_landmarks: -1}}\n"),
              HasSubstr("estimator.map.max_landmarks: must be in [0, 2000], got -1"));
  EXPECT_THAT(error_of("estimator: {map: {max_misses: 99999999999}}\n"),
              HasSubstr("estimator.map.max_misses: must be at most 2147483647"));
  EXPECT_THAT(error_of("estimator: {gating: {ransac_max_hypotheses: 0}}\n"),
              HasSubstr("estimator.gating.ransac_max_hypotheses: must be in [1, 100000]"));
  EXPECT_THAT(error_of("estimator: {initialisation: {inverse_depth_rho: 0}}\n"),
              HasSubstr("estimator.initialisation.inverse_depth_rho: must be > 0"));
  EXPECT_THAT(error_of("estimator:\n  map: {max_landmarks: 20, target_per_camera: 25}\n"),
              HasSubstr("scn.yaml:2:47: estimator.map.target_per_camera: must not exceed "
                        "max_landmarks (20), got 25"));
  EXPECT_THAT(error_of("estimator:\n  map: {max_landmarks: 20}\n"),
              HasSubstr("scn.yaml:2:24: estimator.map.max_landmarks: must be at least "
                        "target_per_camera (25), got 20"));
  EXPECT_THAT(error_of("duration: .inf\n"), HasSubstr("duration: expected a number"));
}

TEST(ScenarioYaml, PhasesMustBeSortedDisjointAndInsideDuration) {
  const std::string overlap = doc(R"(
duration: 210
phases:
  - {name: a, from: 0, to: 70, config: 1}
  - {name: b, from: 60, to: 140, config: 2}
)");
  const std::string msg = error_of(overlap);
  EXPECT_THAT(msg, StartsWith("scn.yaml:4:21: phases[1].from: phase 'b' starts at 60, before "
                              "the previous phase 'a' ends (70)"));
  EXPECT_THAT(error_of("phases:\n  - {from: 50, to: 40, config: 1}\n"),
              HasSubstr("scn.yaml:2:20: phases[0].to: must be greater than from (50), got 40"));
  EXPECT_THAT(error_of("phases:\n  - {from: -1, to: 40, config: 1}\n"),
              HasSubstr("phases[0].from: must be >= 0, got -1"));
  EXPECT_THAT(error_of("phases: []\n"), HasSubstr("phases: expected at least one phase"));
  EXPECT_THAT(error_of("phases:\n  - {to: 40, config: 1}\n"),
              HasSubstr("scn.yaml:2:5: phases[0]: missing required key 'from'"));
  EXPECT_THAT(error_of("phases:\n  - {from: 0, to: 40, config: 1, add: [gps], remove: [gps]}\n"),
              HasSubstr("phases[0].remove[0]: sensor 'gps' is both added and removed"));
  // The keys of a phase, an outage and the control section are their visit()'s: a misspelt one
  // is named with the closest.
  EXPECT_THAT(error_of("phases:\n  - {from: 0, to: 40, confg: 1}\n"),
              HasSubstr("phases[0].confg: unknown key 'confg' (did you mean 'config'?)"));
  EXPECT_THAT(error_of("outages:\n  - {sensor: gps, from: 1, to: 2, agnet: lead}\n"),
              HasSubstr("outages[0].agnet: unknown key 'agnet' (did you mean 'agent'?)"));
  EXPECT_THAT(error_of("control:\n  disturbance: {bund: [0, 0, 0, 0]}\n"),
              HasSubstr("control.disturbance.bund: unknown key 'bund' (did you mean 'bound'?)"));
  // Gaps are allowed.
  EXPECT_NO_THROW(parse_scenarios(
      "phases:\n  - {from: 0, to: 10, config: 1}\n  - {from: 20, to: 30, config: 2}\n", "x.yaml"));

  // Past the duration: checked after the variant overrides, pointing at the phase's `to`.
  const std::string past = doc(R"(
duration: 210
phases:
  - {name: a, from: 0, to: 70, config: 1}
  - {name: b, from: 70, to: 210, config: 2}
variants:
  - {name: full}
  - {name: short, duration: 100}
)");
  EXPECT_EQ(error_of(past),
            "scn.yaml:4:29: phases[1].to: phase 'b' ends at 210, after the scenario's duration "
            "(100)");
  std::string fixed = past;
  fixed.replace(fixed.find("{name: short, duration: 100}"), 28,
                "{name: short, duration: 100, phases: [{from: 0, to: 100, config: 3}]}");
  const auto all = parse_scenarios(fixed, "x.yaml");
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[1].phases.size(), 1u);
}

TEST(ScenarioYaml, AVariantMayLightTheWorldOtherwiseButNotMoveIt) {
  const auto all = parse_scenarios(doc(R"(
world: {light: {ambient: 0.3}, objects: {trees: 5}}
variants:
  - name: ideal
  - name: low_sun
    world: {light: {sun: {enabled: true, time_utc: 7.9}, shadows: true}}
)"), "scn.yaml");
  ASSERT_EQ(all.size(), 2u);
  EXPECT_FALSE(all[0].world.light.sun.enabled);
  EXPECT_TRUE(all[1].world.light.sun.enabled);
  EXPECT_DOUBLE_EQ(all[1].world.light.sun.time_utc, 7.9);
  EXPECT_TRUE(all[1].world.light.shadows);
  EXPECT_DOUBLE_EQ(all[1].world.light.ambient, 0.3);  // the base's light, key by key
  EXPECT_DOUBLE_EQ(all[1].world.objects.trees, all[0].world.objects.trees);
  EXPECT_THAT(error_of("variants:\n  - {name: a, world: {objects: {trees: 1}}}\n"),
              HasSubstr("scn.yaml:2:23: variants[0].world.objects: unknown key 'objects' (a variant may set only "
                        "world.light)"));
  EXPECT_THAT(error_of("variants:\n  - {name: a, world: {light: {sun: {enabled: true, time_utc: 2}}}}\n"),
              HasSubstr("the sun is below the horizon"));
}

TEST(ScenarioYaml, VariantErrors) {
  const std::string y = doc(R"(
variants:
  - name: multi
    estimator: {mode: multi}
  - name: single
    estimater: {mode: single}
)");
  EXPECT_EQ(error_of(y),
            "scn.yaml:5:5: variants[1].estimater: unknown key 'estimater' (did you mean "
            "'estimator'?)");
  EXPECT_THAT(error_of("variants:\n  - {name: a, rate: 5}\n"),
              HasSubstr("scn.yaml:2:15: variants[0].rate: unknown key 'rate' (a variant may set "
                        "only name, uavs, seed, duration"));
  EXPECT_THAT(error_of("variants:\n  - {name: a}\n  - {name: a}\n"),
              HasSubstr("scn.yaml:3:12: variants[1].name: duplicate variant name 'a' (first at "
                        "line 2)"));
  EXPECT_THAT(error_of("variants:\n  - {seed: 2}\n"),
              HasSubstr("variants[0]: missing required key 'name'"));
  EXPECT_THAT(error_of("variants:\n  - {name: Big One}\n"),
              HasSubstr("variants[0].name: variant names must match [a-z0-9_-]+"));
  EXPECT_THAT(error_of("variants:\n  - {name: a, estimator: {gating: {probability: 2}}}\n"),
              HasSubstr("variants[0].estimator.gating.probability: must be in (0, 1), got 2"));
  EXPECT_THAT(error_of("variants: []\n"), HasSubstr("variants: expected at least one variant"));
}

TEST(ScenarioYaml, CrossFieldChecksAfterVariants) {
  const std::string single = doc(R"(
uavs:
  - {name: a}
  - {name: b}
variants:
  - {name: m}
  - name: s
    estimator: {mode: single}
)");
  // Without a uav1 the single-UAV baseline takes the first UAV's camera.
  EXPECT_EQ(parse_scenarios(single, "x.yaml")[1].estimator.single_uav, "a");
  EXPECT_THAT(error_of("estimator: {single_uav: uav7}\n"),
              HasSubstr("scn.yaml:1:25: estimator.single_uav: 'uav7' is not a UAV of this "
                        "scenario (UAVs: uav1, uav2)"));
  EXPECT_THAT(error_of("uavs:\n  - {name: uav1}\nestimator: {mode: multi}\n"),
              HasSubstr("scn.yaml:3:19: estimator.mode: mode multi needs at least 2 UAVs"));
  // One UAV runs the single-UAV estimator without being told.
  EXPECT_EQ(parse_scenarios("uavs:\n  - {name: q}\n", "x.yaml")[0].estimator.mode, EstimatorMode::SingleUav);
  EXPECT_EQ(parse_scenarios("uavs:\n  - {name: q}\n", "x.yaml")[0].estimator.single_uav, "q");
  EXPECT_NO_THROW(
      parse_scenarios("uavs:\n  - {name: uav1}\nestimator: {mode: single}\n", "x.yaml"));
  EXPECT_THAT(error_of("uavs: []\n"), HasSubstr("uavs: at least one UAV is needed"));
  EXPECT_THAT(error_of("outages:\n  - {sensor: gps, from: 1, to: 2, agent: uav9}\n"),
              HasSubstr("scn.yaml:2:42: outages[0].agent: unknown agent 'uav9' (expected lead or "
                        "one of the UAVs: uav1, uav2)"));
  EXPECT_THAT(error_of("outages:\n  - {sensor: gps, from: 3, to: 2}\n"),
              HasSubstr("outages[0].to: must be greater than from (3), got 2"));
  EXPECT_THAT(error_of("outages:\n  - {sensor: compass, from: 1, to: 2}\n"),
              HasSubstr("outages[0].sensor: unknown sensor 'compass'"));
}

TEST(ScenarioYaml, UavNames) {
  EXPECT_THAT(error_of("uavs:\n  - {name: a}\n  - {name: a}\n"),
              HasSubstr("scn.yaml:3:12: uavs[1].name: duplicate UAV name 'a' (first at line 2)"));
  EXPECT_THAT(error_of("uavs:\n  - {name: Uav-1}\n  - {name: b}\n"),
              HasSubstr("uavs[0].name: UAV names must match [a-z0-9_]+ and be at most 64 characters, got 'Uav-1'"));
  EXPECT_THAT(error_of("uavs:\n  - {name: lead}\n  - {name: b}\n"),
              HasSubstr("uavs[0].name: 'lead' is reserved"));
  EXPECT_THAT(error_of("uavs:\n  - {sees_lead: true}\n  - {name: b}\n"),
              HasSubstr("scn.yaml:2:5: uavs[0]: missing required key 'name'"));
  // Names become file names: a 300-character name is refused when the file is read, not when
  // the results are written after the whole run.
  EXPECT_THAT(error_of("uavs:\n  - {name: " + std::string(300, 'a') + "}\n"),
              HasSubstr("scn.yaml:2:12: uavs[0].name: UAV names must match"));
}

TEST(ScenarioYaml, NamesAreShortPlainText) {
  EXPECT_THAT(error_of("name: \"a\\xff\"\n"), HasSubstr("scn.yaml:1:7: name: the scenario's name names its "
                                                          "results directory"));
  EXPECT_THAT(error_of("name: \"a\xff\"\n"), HasSubstr("scn.yaml:1:7: name: not valid UTF-8 text"));
  EXPECT_THAT(error_of("name: ../../etc\n"), HasSubstr("name: the scenario's name"));
  EXPECT_THAT(error_of("name: " + std::string(65, 'x') + "\n"), HasSubstr("at most 64 characters"));
  EXPECT_THAT(error_of("phases:\n  - {name: 'a b', from: 0, to: 1, config: 1}\nduration: 1\n"),
              HasSubstr("phases[0].name: phase names must match"));
  EXPECT_THAT(error_of("world:\n  texture: {image: \"x\xc3\"}\n"), HasSubstr("world.texture.image: not valid UTF-8"));
}

TEST(ScenarioYaml, RunSizeIsBoundedByWhatItDrives) {
  EXPECT_THAT(error_of("duration: 0.01\nrate: 10\n"),
              HasSubstr("scn.yaml:1:11: duration: 0.01 s at rate 10 Hz is shorter than one step (0.1 s)"));
  EXPECT_THAT(error_of("duration: 1e308\n"), HasSubstr("scn.yaml:1:11: duration: 1e308 is beyond any setting's scale"));
  EXPECT_THAT(error_of("rate: 1000\nduration: 1e6\n"),
              HasSubstr("scn.yaml:2:11: duration: 1000000 s at rate 1000 Hz is 1e+09 steps; at most 5e+06"));
  EXPECT_THAT(error_of("landmarks: {density: 1e6}\n"),
              HasSubstr("scn.yaml:1:22: landmarks.density: 1000000 points/m^2"));
  EXPECT_THAT(error_of("landmarks: {margin: 1e7}\n"), HasSubstr("landmarks.density (default): "));
  EXPECT_THAT(error_of("lead: {initial_position: [3e8, 0, 0]}\n"),
              HasSubstr("lead.initial_position: [300000000, 0, 0] is farther than 1e+05 m"));
  EXPECT_THAT(error_of("lead: {trajectory: {scale: 1e9}}\n"),
              HasSubstr("lead.trajectory.scale: the flight spans"));
  EXPECT_THAT(error_of("measurements: rendered\nworld: {terrain: {extent: 1e6}}\n"),
              HasSubstr("world.terrain.extent: the terrain mesh would have 2.5e+11 vertices"));
  // Keys without a size of their own are still bounded: no setting is 1e308 of anything.
  EXPECT_THAT(error_of("noise: {gimbal_omega: 1e308}\n"),
              HasSubstr("noise.gimbal_omega: 1e308 is beyond any setting's scale (magnitude at most 1e+09)"));
  EXPECT_THAT(error_of("noise: {gps_sigma: 1e308}\n"), HasSubstr("noise.gps_sigma: must be in [0, 10000], got 1e308"));
  EXPECT_THAT(error_of("estimator: {process_noise: {accel_sigma_common: 1e300}}\n"),
              HasSubstr("estimator.process_noise.accel_sigma_common: must be in [0, 100], got 1e300"));
  EXPECT_THAT(error_of("estimator: {map: {max_landmarks: 100000}}\n"), HasSubstr("estimator.map.max_landmarks: must be"));
  EXPECT_THAT(error_of("frontend: {max_features: 10000000}\n"), HasSubstr("frontend.max_features: must be in [1, 100000]"));
  EXPECT_THAT(error_of("lead: {trajectory: {z_amplitude: 1e8}}\n"),
              HasSubstr("lead.trajectory.z_amplitude: the flight reaches 1e+08 m from z = 0"));
  std::string many = "uavs:\n";
  for (int i = 0; i < 65; ++i) many += "  - {name: u" + std::to_string(i) + "}\n";
  EXPECT_THAT(error_of(many), HasSubstr("scn.yaml:2:3: uavs: 65 UAVs; at most 64"));
  // 3e6 steps of 2 agents' records fit; of 64 UAVs they would not, and the message says so.
  std::string team = "duration: 4.9e5\nuavs:\n";
  for (int i = 0; i < 64; ++i) team += "  - {name: u" + std::to_string(i) + "}\n";
  EXPECT_THAT(error_of(team), HasSubstr("duration: this run would need about"));
}

std::string load_error(const std::string& path) {
  try {
    load_scenarios(path);
  } catch (const ScenarioError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a ScenarioError for " << path;
  return "";
}

// In closed loop the landmark field covers the circle the formation may fly in: a lambda_d of
// 90 km is counted before the field is built (it would have held 6.5e8 points, 15 GB).
TEST(ScenarioFile, ClosedLoopFormationOffsetsCountInTheLandmarkField) {
  std::ifstream in(WINGMAN_SOURCE_DIR "/scenes/paper_closed_loop_synthetic.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  const auto at = yaml.find("lambda_d: [2.5, 1, 14]");
  ASSERT_NE(at, std::string::npos);
  yaml.replace(at, 22, "lambda_d: [90000, 1, 14]");
  EXPECT_THAT(error_of(yaml, "cl.yaml"), HasSubstr("landmarks.density"));
  EXPECT_THAT(error_of(yaml, "cl.yaml"), HasSubstr("landmarks; at most 5e+06"));
}

TEST(ScenarioFile, OversizedOrBinaryFilesAreRefusedBeforeParsing) {
  EXPECT_THAT(load_error("/dev/zero"), HasSubstr("/dev/zero: larger than 4 MiB"));
  const std::string nul = testing::TempDir() + "/nul.yaml";
  std::ofstream(nul) << std::string("name: a\0b\n", 10);
  EXPECT_THAT(load_error(nul), HasSubstr("nul.yaml: holds a NUL byte at offset 7"));
}

TEST(ScenarioYaml, DuplicateKeys) {
  EXPECT_EQ(error_of("duration: 10\nrate: 5\nduration: 20\n"),
            "scn.yaml:3:1: duration: duplicate key 'duration' (first at line 1)");
  EXPECT_THAT(error_of("estimator:\n  gating:\n    probability: 0.9\n    probability: 0.8\n"),
              HasSubstr("scn.yaml:4:5: estimator.gating.probability: duplicate key"));
}

TEST(ScenarioYaml, DocumentShapeAndSyntaxErrors) {
  const std::string msg = error_of("duration: 10\nnoise: {pixel_sigma: [1, 2\nrate: 5\n");
  EXPECT_THAT(msg, StartsWith("scn.yaml:"));
  EXPECT_THAT(msg, HasSubstr("YAML syntax error"));
  EXPECT_THAT(msg, testing::ContainsRegex("^scn\\.yaml:[23]:[0-9]+: YAML syntax error: "));
  EXPECT_THAT(error_of("a: b: c\n"), testing::ContainsRegex("^scn\\.yaml:1:[0-9]+: YAML syntax"));
  EXPECT_EQ(error_of(""), "scn.yaml: empty document: expected a map of scenario settings");
  EXPECT_THAT(error_of("# only a comment\n"), HasSubstr("empty document"));
  EXPECT_THAT(error_of("- 1\n- 2\n"),
              HasSubstr("scn.yaml:1:1: expected a map of scenario settings at the top level, got "
                        "a list"));
  EXPECT_THAT(error_of("seed: 1\n---\nseed: 2\n"), HasSubstr("more than one YAML document"));
}

TEST(ScenarioYaml, LoadFromFile) {
  const std::string dir = testing::TempDir();
  const std::string path = dir + "/wingman_scn_test.yaml";
  {
    std::ofstream out(path);
    out << "duration: 30\nvariants:\n  - {name: a}\n  - {name: b, seed: 4}\n";
  }
  const auto all = load_scenarios(path);
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[0].source_path, path);
  EXPECT_EQ(all[1].source_path, path);
  EXPECT_EQ(all[0].name, "wingman_scn_test");
  EXPECT_EQ(all[1].variant, "b");
  EXPECT_EQ(all[1].seed, 4u);
  EXPECT_DOUBLE_EQ(all[0].duration, 30);

  {
    std::ofstream out(path);
    out << "duration: 30\nrate: fast\n";
  }
  try {
    load_scenarios(path);
    ADD_FAILURE() << "no error";
  } catch (const ScenarioError& e) {
    EXPECT_EQ(std::string(e.what()), path + ":2:7: rate: expected a number, got 'fast'");
  }
  std::filesystem::remove(path);

  const std::string missing = dir + "/wingman_no_such_scenario.yaml";
  try {
    load_scenarios(missing);
    ADD_FAILURE() << "no error";
  } catch (const ScenarioError& e) {
    EXPECT_EQ(std::string(e.what()), missing + ": cannot read scenario: No such file or directory");
  }
  EXPECT_THROW(load_scenarios(dir), ScenarioError);
}

TEST(ScenarioYaml, RenderedMeasurementsParse) {
  EXPECT_EQ(parse_scenarios("measurements: rendered\n", "scn.yaml").front().measurements,
            MeasurementMode::Rendered);
  EXPECT_EQ(parse_scenarios("measurements: synthetic\n", "scn.yaml").front().measurements,
            MeasurementMode::Synthetic);
}

TEST(ScenarioYaml, FrontendSectionParsesAndVariantsOverrideIt) {
  const std::string yaml = doc(R"(
measurements: rendered
frontend:
  detector: gftt_orb
  max_features: 400
  grid: [6, 5]
  orb: {fast_threshold: 15, levels: 3, scale_factor: 1.3}
  gftt: {quality: 0.01, min_distance_px: 7}
  tracking: {gate_d2: 11.8, ratio: 0.7, max_search_radius_px: 80, max_distance: 50, match_latest_descriptor: true}
  cross_matching: {ratio: 0.75, max_epipolar_px: 4, max_reprojection_px: 3}
  oracle_pixels: true
variants:
  - name: a
  - name: b
    frontend: {detector: akaze, akaze: {threshold: 0.001}}
)");
  const auto v = parse_scenarios(yaml, "scn.yaml");
  ASSERT_EQ(v.size(), 2u);
  const vision::FrontendSettings& f = v[0].frontend;
  EXPECT_EQ(f.features.kind, vision::DetectorKind::GfttOrb);
  EXPECT_EQ(f.features.max_features, 400);
  EXPECT_EQ(f.features.grid_cols, 6);
  EXPECT_EQ(f.features.grid_rows, 5);
  EXPECT_EQ(f.features.orb_fast_threshold, 15);
  EXPECT_EQ(f.features.orb_levels, 3);
  EXPECT_FLOAT_EQ(f.features.orb_scale_factor, 1.3f);
  EXPECT_DOUBLE_EQ(f.features.gftt_quality, 0.01);
  EXPECT_DOUBLE_EQ(f.features.gftt_min_distance, 7);
  EXPECT_DOUBLE_EQ(f.tracking.gate_d2, 11.8);
  EXPECT_DOUBLE_EQ(f.tracking.ratio, 0.7);
  EXPECT_DOUBLE_EQ(f.tracking.max_search_radius_px, 80);
  EXPECT_DOUBLE_EQ(f.tracking.max_distance, 50);
  EXPECT_TRUE(f.tracking.match_latest_descriptor);
  EXPECT_DOUBLE_EQ(f.cross_matching.ratio, 0.75);
  EXPECT_DOUBLE_EQ(f.cross_matching.max_epipolar_px, 4);
  EXPECT_DOUBLE_EQ(f.cross_matching.max_reprojection_px, 3);
  EXPECT_TRUE(f.oracle_pixels);
  // The variant changes the detector and keeps the rest of the base section.
  EXPECT_EQ(v[1].frontend.features.kind, vision::DetectorKind::Akaze);
  EXPECT_DOUBLE_EQ(v[1].frontend.features.akaze_threshold, 0.001);
  EXPECT_EQ(v[1].frontend.features.max_features, 400);
  // Defaults without the section.
  EXPECT_EQ(parse_scenarios("measurements: rendered\n", "scn.yaml").front().frontend.features.kind, vision::DetectorKind::Orb);
  EXPECT_FALSE(parse_scenarios("measurements: rendered\n", "scn.yaml").front().frontend.oracle_pixels);
}

TEST(ScenarioYaml, FrontendErrorsNameLineAndKey) {
  const std::string bad_detector = doc(R"(
frontend:
  detector: surf
)");
  std::string e = error_of(bad_detector);
  EXPECT_THAT(e, StartsWith(at_line(bad_detector, "detector")));
  EXPECT_THAT(e, HasSubstr("frontend.detector"));
  EXPECT_THAT(e, HasSubstr("expected one of orb, akaze, sift, gftt_orb, got 'surf'"));

  const std::string bad_grid = doc(R"(
frontend:
  grid: [8]
)");
  EXPECT_THAT(error_of(bad_grid), HasSubstr("frontend.grid"));
  const std::string zero_cols = doc(R"(
frontend:
  grid: [0, 4]
)");
  EXPECT_THAT(error_of(zero_cols), HasSubstr("frontend.grid[0]"));

  const std::string bad_ratio = doc(R"(
frontend:
  tracking: {ratio: 1.5}
)");
  e = error_of(bad_ratio);
  EXPECT_THAT(e, StartsWith(at_line(bad_ratio, "ratio")));
  EXPECT_THAT(e, HasSubstr("frontend.tracking.ratio"));

  const std::string unknown = doc(R"(
frontend:
  orb: {levles: 3}
)");
  EXPECT_THAT(error_of(unknown), HasSubstr("unknown key 'levles'"));

  const std::string oracle = doc(R"(
frontend:
  oracle_pixels: 1
)");
  EXPECT_THAT(error_of(oracle), HasSubstr("frontend.oracle_pixels"));
}

TEST(ScenarioYaml, PixelBiasAndPixelOffsetSigmasParseAndMustBeNonNegative) {
  const Scenario s = parse_scenarios("noise: {pixel_bias_sigma: 0.53}\n"
                                     "estimator: {measurement_noise: {pixel_offset_sigma: 0.75}}\n",
                                     "scn.yaml").front();
  EXPECT_DOUBLE_EQ(s.noise.pixel_bias_sigma, 0.53);
  EXPECT_DOUBLE_EQ(s.estimator.measurement_noise.pixel_offset_sigma, 0.75);
  const Scenario d = parse_scenarios("duration: 5\n", "scn.yaml").front();
  EXPECT_DOUBLE_EQ(d.noise.pixel_bias_sigma, 0.0);
  EXPECT_DOUBLE_EQ(d.estimator.measurement_noise.pixel_offset_sigma, 0.0);
  const std::string bad1 = "noise: {pixel_bias_sigma: -1}\n";
  EXPECT_NE(error_of(bad1).find("pixel_bias_sigma"), std::string::npos) << error_of(bad1);
  const std::string bad2 = "estimator:\n  measurement_noise: {pixel_offset_sigma: -0.1}\n";
  const std::string e2 = error_of(bad2);
  EXPECT_NE(e2.find("scn.yaml:2:"), std::string::npos) << e2;
  EXPECT_NE(e2.find("pixel_offset_sigma"), std::string::npos) << e2;
}

// A configuration of Table 1 is defined by its sensors: needing one that nothing in the filter
// carries is an error naming the phase and the sensor, unless the phase removes it on purpose.
TEST(ScenarioYaml, PhaseNeedingASensorNothingCarriesIsAnError) {
  const std::string y = doc(R"(
uavs:
  - {name: a, sees_lead: false}
  - {name: b, sees_lead: false}
phases:
  - {name: first, from: 0, to: 100, config: 3}
  - {name: second, from: 100, to: 210, config: 1}
)");
  EXPECT_EQ(error_of(y),
            "scn.yaml:5: phases[0]: phase 'first' (configuration 3) needs lead_projection, but no UAV "
            "carries it; switch it on (uavs[i].sees_lead: true) or add 'remove: [lead_projection]' "
            "to the phase to run without it");
  std::string removed = y;
  removed.replace(removed.find("config: 3}"), 10, "config: 3, remove: [lead_projection]}");
  removed.replace(removed.find("config: 1}"), 10, "config: 1, remove: [lead_projection]}");
  EXPECT_NO_THROW(parse_scenarios(removed, "x.yaml"));
  EXPECT_THAT(error_of("lead: {gps: false}\nphases:\n  - {from: 0, to: 210, config: 2}\n"),
              HasSubstr("phase 'phase1' (configuration 2) needs gps, but the lead does not carry it"));
  // The single-UAV baseline has only its own UAV's sensors.
  EXPECT_THAT(error_of("uavs:\n  - {name: a, range: false}\n  - {name: b}\nestimator: {mode: single, "
                       "single_uav: a}\nphases:\n  - {from: 0, to: 210, config: 2}\n"),
              HasSubstr("needs range, but the single-UAV estimator's UAV 'a' does not carry it"));
  // The integrated configuration feeds what is carried and needs nothing.
  EXPECT_NO_THROW(parse_scenarios("lead: {gps: false}\n", "x.yaml"));
}

// The resolved configuration is a scenario of its own: read back, it resolves to itself.
TEST(ScenarioYaml, ResolvedConfigurationReadsBackToItself) {
  for (const auto& cfg : parse_scenarios(kFull, "dir/paper.yaml")) {
    const std::string text = config_yaml(cfg);
    const RunConfig back = parse_scenarios(text, "config.yaml").front();
    std::string again = config_yaml(back);
    // Only the comment naming the source differs, and the comments saying where a derived value
    // came from (read back, it is a value written in the file).
    const auto without_origins = [](std::string s) {
      for (std::size_t at; (at = s.find("  # auto:")) != std::string::npos;) s.erase(at, s.find('\n', at) - at);
      return s.substr(s.find('\n'));
    };
    EXPECT_EQ(without_origins(text), without_origins(again)) << cfg.variant;
    EXPECT_EQ(back.estimator.mode, cfg.estimator.mode);
    EXPECT_EQ(back.seed, cfg.seed);
  }
}

}  // namespace
}  // namespace wingman::app
