// Teams beyond two UAVs: cooperative initialisation between every pair of cameras that shares
// view, the map cap that grows with the team, and teams of 1 and 6 end to end.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <ostream>

#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <utility>

#include "app/pipeline/loop.hpp"
#include "app/pipeline/pipeline.hpp"
#include "app/config/run_config.hpp"
#include "app/pipeline/synthetic_measurements.hpp"
#include "eval/metrics/metrics.hpp"
#include "gl_required.hpp"
#include "sim/synthetic_source.hpp"
#include "sim/truth.hpp"

namespace wingman::app {
namespace {

// Counts, per camera pair, the cross matches the source returned.
class PairCounter final : public MeasurementSource {
 public:
  explicit PairCounter(MeasurementSource& inner) : in_(inner) {}
  std::map<std::pair<int, int>, int> matches;

  StageTimes begin_step(int k, double t, const slam::Estimator& est) override { return in_.begin_step(k, t, est); }
  Labelled<LandmarkObservation> landmarks(int cam, const std::vector<slam::LandmarkPrediction>& p) override {
    return in_.landmarks(cam, p);
  }
  std::optional<Eigen::Vector2d> lead_pixel(int cam) override { return in_.lead_pixel(cam); }
  slam::SensorBatch sensors(const SensorRequest& wanted) override { return in_.sensors(wanted); }
  void verdict(const LandmarkObservation& o, const TruthLabel& l, bool a) override { in_.verdict(o, l, a); }
  Labelled<PairObservation> pairs(int a, int b, int needed, const slam::Estimator& est) override {
    auto found = in_.pairs(a, b, needed, est);
    matches[{a, b}] += static_cast<int>(found.size());
    return found;
  }
  std::vector<PointObservation> points(int cam, int needed) override { return in_.points(cam, needed); }
  std::optional<Eigen::Vector3d> added(slam::LandmarkId id, int cam, std::int64_t h, const Eigen::Vector2d& uv) override {
    return in_.added(id, cam, h, uv);
  }
  void removed(slam::LandmarkId id) override { in_.removed(id); }
  void end_step(double t) override { in_.end_step(t); }
  void finish(eval::RunRecord& r) override { in_.finish(r); }

 private:
  MeasurementSource& in_;
};

// Two sub-teams 200 m apart: within each the cameras share view, across them they do not.
const char* kTwoGroups = R"(
duration: 6
uavs:
  - {name: uav1, initial_position: [-1.5, 0, 15]}
  - {name: uav2, initial_position: [1.5, 0, 17], sees_lead: false, altimeter: false, range: false}
  - {name: uav3, initial_position: [200, 3, 15], sees_lead: false, altimeter: true, range: false}
  - {name: uav4, initial_position: [203, -2, 17], sees_lead: false, altimeter: false, range: false}
)";

TEST(TeamPairs, CrossMatchingPairsEveryCameraPairThatSharesView) {
  const RunConfig cfg = parse_run_configs(kTwoGroups, "teams.yaml").at(0);
  const sim::OpenLoopTruth truth(cfg);
  sim::SyntheticSource sensors(cfg, truth);
  SyntheticMeasurements inner(cfg, sensors);
  PairCounter counter(inner);
  const eval::RunRecord rec = run_loop(cfg, truth, counter);
  EXPECT_GT(counter.matches[std::make_pair(0, 1)], 20);
  EXPECT_GT(counter.matches[std::make_pair(2, 3)], 20);  // the UAVs beyond the first two
  for (const auto& [pr, n] : counter.matches)
    EXPECT_TRUE(pr == std::make_pair(0, 1) || pr == std::make_pair(2, 3)) << pr.first << "," << pr.second;
  int cooperative = 0;
  for (const auto& l : rec.landmarks) cooperative += l.origin == "cooperative";
  EXPECT_GT(cooperative, 40);
}

TEST(TeamPairs, MapCapGrowsWithTheTeamUnlessSet) {
  const RunConfig four = parse_run_configs(kTwoGroups, "teams.yaml").at(0);
  EXPECT_EQ(four.estimator.map.max_landmarks, 4 * 75);
  const RunConfig set = parse_run_configs(std::string(kTwoGroups) + "estimator: {map: {max_landmarks: 120}}\n",
                                          "teams.yaml").at(0);
  EXPECT_EQ(set.estimator.map.max_landmarks, 120);
  const RunConfig per = parse_run_configs(std::string(kTwoGroups) + "estimator: {map: {max_landmarks_per_camera: 40}}\n",
                                          "teams.yaml").at(0);
  EXPECT_EQ(per.estimator.map.max_landmarks, 160);
}

// A team of n UAVs around the lead (the first carries the lead sensors), 1.5 s, with cameras of
// two kinds in turn: 320 x 320 of the paper's field of view, and 400 x 300 with radial-tangential
// distortion and a lever arm; closed: every UAV flown by the controller.
const std::string kSquare = "{fx: 64.03, fy: 64.03, cx: 160, cy: 160, width: 320, height: 320}";
const std::string kWide = "{fx: 90, fy: 92, cx: 201, cy: 148, width: 400, height: 300, "
                          "distortion: [-0.05, 0.01, 0.001, -0.001], offset: [0.1, 0, -0.05]}";

std::string team_yaml(int n, const std::string& mode, bool closed) {
  const double offsets[8][3] = {{-1.5, 0, 15}, {1.5, 0, 17}, {-4, 5, 16}, {4, -5, 18},
                                {-5, -5, 16.5}, {5, 5, 15.5}, {0, 7, 17}, {0, -7, 16}};
  std::string y = "duration: 1.5\nmeasurements: " + mode + "\nuavs:\n";
  std::string control = "control:\n  uavs:\n";
  for (int i = 0; i < n; ++i) {
    const auto& o = offsets[i];
    const std::string sensors = i == 0 ? "true" : "false";
    y += "  - {name: uav" + std::to_string(i + 1) + ", initial_position: [" + std::to_string(o[0]) + ", " +
         std::to_string(o[1]) + ", " + std::to_string(o[2]) + "], sees_lead: " + sensors + ", altimeter: " + sensors +
         ", range: " + sensors + ", camera: " + (i % 2 == 0 ? kSquare : kWide) + "}\n";
    control += "    - {name: uav" + std::to_string(i + 1) + ", initial_yaw: 0, lambda_d: [" + std::to_string(o[0]) + ", " +
               std::to_string(o[1]) + ", " + std::to_string(o[2]) + "]}\n";
  }
  y += "world: {objects: {boulders: 0, trees: 0, buildings: 0}, image: {msaa: 1}}\n";
  return closed ? y + control : y;
}

struct TeamCase {
  int uavs;
  const char* mode;
  bool closed;
};
// How gtest names the case in its output.
void PrintTo(const TeamCase& c, std::ostream* os) {
  *os << c.uavs << " UAVs, " << c.mode << (c.closed ? ", closed loop" : ", open loop");
}

class TeamRuns : public ::testing::TestWithParam<TeamCase> {};

// Teams of 1 and 6 (and 8, the largest the docs promise) run to the end in both modes, the
// estimate of the lead within a few metres of the truth, every camera's frames through the frontend.
TEST_P(TeamRuns, RunToTheEndWithABoundedEstimate) {
  const TeamCase c = GetParam();
  const bool rendered = std::string(c.mode) == "rendered";
  std::string why;
  if (rendered && !wingman::testing::gl_available(&why)) WINGMAN_NO_GL_CONTEXT(why);
  const RunConfig cfg = parse_run_configs(team_yaml(c.uavs, c.mode, c.closed), "team.yaml").at(0);
  ASSERT_EQ(static_cast<int>(cfg.uavs.size()), c.uavs);
  EXPECT_EQ(cfg.single_uav(), c.uavs == 1);
  const eval::RunRecord rec = run_scenario(cfg);
  ASSERT_EQ(static_cast<int>(rec.steps.size()), cfg.num_steps() + 1);
  EXPECT_EQ(rec.closed_loop, c.closed);
  const eval::Metrics m = eval::compute_metrics(rec);
  ASSERT_EQ(static_cast<int>(m.table4.total.size()), 1 + c.uavs);
  for (const auto& a : m.table4.total) {
    EXPECT_TRUE(std::isfinite(a.rms_error));
    EXPECT_LT(a.rms_error, 3.0);
  }
  if (rendered) {
    EXPECT_EQ(rec.frontend.frames, static_cast<long>(c.uavs) * cfg.num_steps());
  }
  EXPECT_GT(m.landmarks.initialised, 10);
}

INSTANTIATE_TEST_SUITE_P(Teams, TeamRuns,
                         ::testing::Values(TeamCase{1, "synthetic", false}, TeamCase{6, "synthetic", false},
                                           TeamCase{8, "synthetic", false}, TeamCase{6, "synthetic", true},
                                           TeamCase{1, "rendered", false}, TeamCase{6, "rendered", false},
                                           TeamCase{6, "rendered", true}),
                         [](const auto& info) {
                           return std::to_string(info.param.uavs) + "Uavs" +
                                  (std::string(info.param.mode) == "rendered" ? "Rendered" : "Synthetic") +
                                  (info.param.closed ? "ClosedLoop" : "OpenLoop");
                         });

}  // namespace
}  // namespace wingman::app

namespace wingman::app {
namespace {

// Every shipped scene loads with its modules' settings, its assets and trajectory files found.
TEST(ShippedScenes, EverySceneLoads) {
  int scenes = 0;
  for (const auto& e : std::filesystem::directory_iterator(WINGMAN_SOURCE_DIR "/scenes")) {
    if (e.path().extension() != ".yaml") continue;
    ++scenes;
    SCOPED_TRACE(e.path().string());
    std::vector<RunConfig> configs;
    EXPECT_NO_THROW(configs = load_run_configs(e.path().string()));
    EXPECT_FALSE(configs.empty());
  }
  EXPECT_GE(scenes, 20);
}

}  // namespace
}  // namespace wingman::app
