// Teams beyond two UAVs: cooperative initialisation between every pair of cameras that shares
// view, the map cap that grows with the team, and teams of 1 and 6 end to end.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <utility>

#include "app/loop.hpp"
#include "app/pipeline.hpp"
#include "app/run_config.hpp"
#include "app/synthetic_measurements.hpp"
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
  std::vector<LandmarkObservation> landmarks(int cam, const std::vector<slam::LandmarkPrediction>& p) override {
    return in_.landmarks(cam, p);
  }
  std::optional<Eigen::Vector2d> lead_pixel(int cam) override { return in_.lead_pixel(cam); }
  std::optional<Eigen::Vector3d> gps() override { return in_.gps(); }
  std::optional<double> altimeter(int cam) override { return in_.altimeter(cam); }
  std::optional<double> range(int cam) override { return in_.range(cam); }
  void verdict(const LandmarkObservation& o, bool a) override { in_.verdict(o, a); }
  std::vector<PairObservation> pairs(int a, int b, int needed, const slam::Estimator& est) override {
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

}  // namespace
}  // namespace wingman::app
