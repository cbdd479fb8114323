// The estimator's noise a scenario leaves `auto` (app/config/derived_noise.hpp): process noise from the
// path flown, pixel noise from the truth's noise or the frontend noise model, the lead's pixel noise
// from its detector, printed with its origin in the resolved configuration; and the bad inputs
// around them.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "app/app_test_support.hpp"
#include "app/config/derived_noise.hpp"
#include "gl_required.hpp"
#include "app/config/run_config.hpp"
#include "sim/assets.hpp"
#include "sim/settings_yaml.hpp"

namespace wingman::app {
namespace {

namespace fs = std::filesystem;
using test::TempDir;
using test::write_file;

std::string error_of(const std::string& yaml) {
  try {
    parse_run_configs(yaml, "scn.yaml");
  } catch (const sim::ScenarioError& e) {
    return e.what();
  }
  return "";
}

TEST(DerivedNoise, WindowedRmsBoundOfASineIsItsAmplitudeOverRootTwo) {
  std::vector<Eigen::Vector3d> a;
  for (int k = 0; k < 1000; ++k) a.push_back({0.3 * std::sin(2 * M_PI * k / 50.0), 0.01, 0});
  EXPECT_NEAR(eval::windowed_rms_bound(a, 50), 0.3 / std::sqrt(2.0), 1e-3);
  // A burst in one window dominates the bound, not the whole run's RMS.
  std::vector<Eigen::Vector3d> burst(1000, Eigen::Vector3d::Zero());
  for (int k = 500; k < 550; ++k) burst[k] = {0, 1.0, 0};
  EXPECT_NEAR(eval::windowed_rms_bound(burst, 50), 1.0, 1e-12);
}

TEST(DerivedNoise, LemniscateCommonAccelerationFollowsTheCurve) {
  // The paper's curve: x = 100 sin(w t) with w = 0.015 has |x''| up to 100 w^2 = 0.0225; y is the
  // 2w component, amplitude 100 (2w)^2 / 2 = 0.045: the bound is under its peak, over the floor's.
  const RunConfig c = parse_run_configs("duration: 210\n", "scn.yaml").front();
  const auto& q = c.estimator.process_noise;
  EXPECT_TRUE(q.accel_sigma_common.automatic);
  EXPECT_GT(q.accel_sigma_common, 0.05);
  EXPECT_LT(q.accel_sigma_common, 0.045 * 1.01 + 0.05);
  // World-frame formation: the UAVs fly the lead's acceleration; their own part is the floor.
  EXPECT_NEAR(q.accel_sigma_uav, kAccelerationFloor, 1e-9);
  EXPECT_NEAR(q.accel_sigma_lead, kAccelerationFloor, 1e-9);
  EXPECT_NE(q.accel_sigma_common.source.find("lead's nominal acceleration"), std::string::npos);
}

TEST(DerivedNoise, HeadingFormationGivesTheOuterUavsTheirTurn) {
  const std::string scn =
      "duration: 30\nlead: {formation_frame: heading, trajectory: {type: waypoints, waypoints: "
      "[[0, 0, 0, 0], [10, 20, 0, 0], [20, 20, 20, 0], [30, 0, 20, 0]]}}\n"
      "uavs:\n  - {name: uav1, initial_position: [-10, 0, 15]}\n  - {name: uav2, initial_position: [0, 10, 16]}\n";
  const RunConfig c = parse_run_configs(scn, "scn.yaml").front();
  EXPECT_GT(c.estimator.process_noise.accel_sigma_common, 0.2);
  EXPECT_GT(c.estimator.process_noise.accel_sigma_uav, 0.1);
}

TEST(DerivedNoise, MotionNoiseAddsInQuadratureAndWrittenValuesStay) {
  const RunConfig c = parse_run_configs(
                          "noise: {motion: {accel_sigma_uav: 0.3}}\n"
                          "estimator: {process_noise: {accel_sigma_common: 0.7}}\n",
                          "scn.yaml")
                          .front();
  EXPECT_NEAR(c.estimator.process_noise.accel_sigma_uav, std::hypot(kAccelerationFloor, 0.3), 1e-12);
  EXPECT_DOUBLE_EQ(c.estimator.process_noise.accel_sigma_common, 0.7);
  EXPECT_FALSE(c.estimator.process_noise.accel_sigma_common.automatic);
}

TEST(DerivedNoise, SyntheticPixelNoiseIsTheTruthsSpecification) {
  const RunConfig c = parse_run_configs("noise: {pixel_sigma: 0.8, pixel_bias_sigma: 0.5}\n", "scn.yaml").front();
  EXPECT_DOUBLE_EQ(c.estimator.measurement_noise.pixel_sigma, 0.8);
  EXPECT_NEAR(c.estimator.measurement_noise.pixel_offset_sigma, 0.5 * std::sqrt(2.0), 1e-12);
}

TEST(DerivedNoise, ResolvedConfigurationSaysWhereEachValueCameFromAndRerunsTheSame) {
  const RunConfig c = parse_run_configs("duration: 20\n", "scn.yaml").front();
  const std::string yaml = config_yaml(c);
  EXPECT_NE(yaml.find("accel_sigma_common: " + sim::number_text(c.estimator.process_noise.accel_sigma_common) +
                      "  # auto: the lead's nominal acceleration"),
            std::string::npos)
      << yaml;
  const RunConfig again = parse_run_configs(yaml, "config.yaml").front();
  EXPECT_DOUBLE_EQ(again.estimator.process_noise.accel_sigma_common, c.estimator.process_noise.accel_sigma_common);
  EXPECT_FALSE(again.estimator.process_noise.accel_sigma_common.automatic);
  EXPECT_EQ(config_yaml(again).find("# auto"), std::string::npos);
}

TEST(DerivedNoise, RenderedPixelNoiseComesFromTheShippedModel) {
  const RunConfig c = parse_run_configs("measurements: rendered\n", "scn.yaml").front();
  const vision::FrontendNoiseModel m =
      read_noise_model(sim::assets_dir() + "/frontend/noise_model.yaml");
  EXPECT_DOUBLE_EQ(c.estimator.measurement_noise.pixel_sigma, m.orb.pixel_sigma);
  EXPECT_DOUBLE_EQ(c.estimator.measurement_noise.pixel_offset_sigma, m.orb.pixel_offset_sigma);
  EXPECT_NE(c.estimator.measurement_noise.pixel_sigma.source.find("detector orb"), std::string::npos);
}

TEST(DerivedNoise, TheLeadsPixelNoiseIsTheMarkersPixelSigmaOrAMarkerFreeDetectorsOwn) {
  const auto noise = [](const std::string& yaml) {
    return parse_run_configs("measurements: rendered\n" + yaml, "scn.yaml").front().estimator.measurement_noise;
  };
  const auto marked = noise("");
  EXPECT_TRUE(marked.lead_pixel_sigma.automatic);
  EXPECT_TRUE(marked.lead_pixel_sigma.source.empty());  // stays auto: pixel_sigma
  EXPECT_DOUBLE_EQ(marked.lead_sigma(), marked.pixel_sigma.value);

  const auto learned = noise("world: {lead: {cue: none}}\n");
  EXPECT_DOUBLE_EQ(learned.lead_sigma(), 1.5);
  EXPECT_EQ(learned.lead_pixel_sigma.source, "auto: frontend.learned_lead.pixel_sigma");
  EXPECT_DOUBLE_EQ(noise("world: {lead: {cue: none}}\nfrontend: {learned_lead: {pixel_sigma: 0.8}}\n").lead_sigma(), 0.8);
  EXPECT_DOUBLE_EQ(noise("world: {lead: {cue: none}}\nfrontend: {lead_detector: motion}\n").lead_sigma(), 10.0);
  EXPECT_DOUBLE_EQ(noise("world: {lead: {cue: none}}\nestimator: {measurement_noise: {lead_pixel_sigma: 2.5}}\n")
                       .lead_sigma(),
                   2.5);
  const auto synthetic = parse_run_configs("world: {lead: {cue: none}}\n", "scn.yaml").front().estimator.measurement_noise;
  EXPECT_DOUBLE_EQ(synthetic.lead_sigma(), synthetic.pixel_sigma.value);
}

TEST(DerivedNoise, AnEstimatorSigmaOfZeroIsRefusedAtItsKey) {
  for (const char* v : {"0", "-0.0"}) {
    const std::string e = error_of(std::string("estimator:\n  measurement_noise: {gps_sigma: ") + v + "}\n");
    EXPECT_NE(e.find("scn.yaml:2:"), std::string::npos) << e;
    EXPECT_NE(e.find("estimator.measurement_noise.gps_sigma"), std::string::npos) << e;
  }
  EXPECT_NE(error_of("estimator: {measurement_noise: {pixel_sigma: 0}}\n").find("pixel_sigma"), std::string::npos);
  EXPECT_NE(error_of("estimator: {measurement_noise: {pixel_sigma: autp}}\n").find("pixel_sigma"), std::string::npos);
}

TEST(DerivedNoise, MalformedNoiseModelsAreRefusedNamingFileLineAndKey) {
  TempDir tmp;
  const auto model = [&](const std::string& name, const std::string& text) {
    write_file(tmp.path() / name, text);
    return error_of("measurements: rendered\nfrontend: {noise_model: " + (tmp.path() / name).string() + "}\n");
  };
  std::string e = model("unknown.yaml", "detectors:\n  sfit: {pixel_sigma: 1, pixel_offset_sigma: 1, observations: 3}\n");
  EXPECT_NE(e.find("unknown.yaml:2:"), std::string::npos) << e;
  EXPECT_NE(e.find("detectors.sfit"), std::string::npos) << e;
  EXPECT_NE(e.find("frontend.noise_model"), std::string::npos) << e;
  e = model("missing_key.yaml", "detectors:\n  orb: {pixel_sigma: 1, observations: 3}\n");
  EXPECT_NE(e.find("missing_key.yaml:2:"), std::string::npos) << e;
  EXPECT_NE(e.find("pixel_offset_sigma"), std::string::npos) << e;
  e = model("negative.yaml", "detectors:\n  orb: {pixel_sigma: -1, pixel_offset_sigma: 1, observations: 3}\n");
  EXPECT_NE(e.find("negative.yaml:2:"), std::string::npos) << e;
  e = model("syntax.yaml", "detectors: [\n");
  EXPECT_NE(e.find("syntax.yaml"), std::string::npos) << e;
  e = model("other.yaml", "detectors:\n  sift: {pixel_sigma: 1, pixel_offset_sigma: 1, observations: 3}\n");
  EXPECT_NE(e.find("no figures for detector 'orb'"), std::string::npos) << e;
  e = error_of("measurements: rendered\nfrontend: {noise_model: /nonexistent/model.yaml}\n");
  EXPECT_NE(e.find("scn.yaml:2:"), std::string::npos) << e;
  EXPECT_NE(e.find("not found"), std::string::npos) << e;
}

TEST(DerivedNoise, CommandLineRefusesABadModelAndAZeroSigmaWithExit2AndWritesNothing) {
  TempDir tmp;
  write_file(tmp.path() / "model.yaml", "detectors:\n  orb: {pixel_sigma: 1, pixel_offset_sigma: 1, observations: 3,\n    colour: red}\n");
  write_file(tmp.path() / "bad_model.yaml", "measurements: rendered\nfrontend: {noise_model: model.yaml}\n");
  auto r = test::run_wingman({"run", (tmp.path() / "bad_model.yaml").string(), "--out", (tmp.path() / "out").string()},
                             tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("model.yaml:3:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("detectors.orb.colour"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(tmp.path() / "out"));
  write_file(tmp.path() / "zero.yaml", "estimator:\n  measurement_noise: {gps_sigma: -0.0}\n");
  r = test::run_wingman({"run", (tmp.path() / "zero.yaml").string(), "--out", (tmp.path() / "out").string()}, tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("zero.yaml:2:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("estimator.measurement_noise.gps_sigma"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(tmp.path() / "out"));
  // calibrate-frontend refuses an output that exists, before any work.
  write_file(tmp.path() / "exists.yaml", "x");
  r = test::run_wingman({"calibrate-frontend", tmp.path().string(), "--out", (tmp.path() / "exists.yaml").string()},
                        tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(test::read_file(tmp.path() / "exists.yaml"), "x");
}

// The command end to end on a small rendered dataset: a model the loader reads back, with
// figures of the size the frontend's pixels have.
TEST(DerivedNoise, CalibrateFrontendWritesAModelRenderedRunsRead) {
  TempDir tmp;
  const std::string cam = "camera: {fx: 300, fy: 300, cx: 319.5, cy: 239.5, width: 640, height: 480}";
  write_file(tmp.path() / "cal.yaml", "name: cal\nduration: 6\nmeasurements: rendered\nuavs:\n"
                                      "  - {name: uav1, initial_position: [-1.5, 0, 15], " + cam + "}\n"
                                      "  - {name: uav2, initial_position: [1.5, 0, 17], " + cam + "}\n");
  auto r = test::run_wingman({"render", (tmp.path() / "cal.yaml").string(), "--out", (tmp.path() / "ds").string(), "-q"},
                             tmp.path());
  if (r.exit_code != 0 && r.output.find("GL") != std::string::npos) WINGMAN_NO_GL_CONTEXT(r.output);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = test::run_wingman({"calibrate-frontend", (tmp.path() / "ds").string(), "--out", (tmp.path() / "m.yaml").string(),
                         "--detectors", "orb", "-q"},
                        tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const vision::FrontendNoiseModel m = read_noise_model((tmp.path() / "m.yaml").string());
  ASSERT_TRUE(m.orb.calibrated());
  EXPECT_FALSE(m.gftt_orb.calibrated());
  EXPECT_GT(m.orb.tracks, 20);
  EXPECT_GT(m.orb.pixel_sigma, 0.05);
  EXPECT_LT(m.orb.pixel_sigma, 1.5);
  EXPECT_LT(m.orb.median_error_px, 1.5);
  EXPECT_NE(m.made_by.find("wingman render of cal"), std::string::npos) << m.made_by;
  // A rendered scenario that names the model takes its figures.
  const RunConfig c = parse_run_configs("measurements: rendered\nfrontend: {noise_model: " +
                                            (tmp.path() / "m.yaml").string() + "}\n",
                                        "scn.yaml")
                          .front();
  EXPECT_DOUBLE_EQ(c.estimator.measurement_noise.pixel_sigma, m.orb.pixel_sigma);
}

TEST(DerivedNoise, TrackNoiseSplitsConstantOffsetsFromWhiteScatter) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> white(0, 0.4), offset(0, 0.5);
  std::vector<eval::TrackedCorrespondence> corr;
  for (int track = 0; track < 400; ++track) {
    const Eigen::Vector2d o(offset(rng), offset(rng));
    for (int k = 0; k < 30; ++k) {
      eval::TrackedCorrespondence c;
      c.k = k;
      c.cam = track % 2;
      c.landmark = track;
      c.true_uv = {100, 100};
      c.uv = c.true_uv + o + Eigen::Vector2d(white(rng), white(rng));
      c.accepted = true;
      corr.push_back(c);
    }
  }
  const vision::DetectorNoise d = track_noise(corr);
  EXPECT_EQ(d.tracks, 400);
  EXPECT_NEAR(d.pixel_sigma, 0.4, 0.02);
  EXPECT_NEAR(d.track_offset_rms, std::sqrt(0.25 + 0.16 / 30), 0.03);
  EXPECT_NEAR(d.pixel_offset_sigma, std::sqrt(2.0) * d.track_offset_rms, 1e-12);
}

}  // namespace
}  // namespace wingman::app
