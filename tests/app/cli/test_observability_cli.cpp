// `wingman observability` as a real process: the JSON it prints for the example, the
// text report, evaluation along a scenario, and exit code 2 with a message for bad input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "app/app_test_support.hpp"

namespace wingman::app::test {
namespace {

using ::testing::HasSubstr;

class ObservabilityCli : public ::testing::Test {
 protected:
  nlohmann::json run_json(std::vector<std::string> args) {
    args.insert(args.begin(), "observability");
    args.push_back("--json");
    const RunResult r = run_wingman(args, tmp_.path());
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return nlohmann::json::parse(r.output);
  }
  void expect_usage_error(std::vector<std::string> args, const std::string& message) {
    args.insert(args.begin(), "observability");
    const RunResult r = run_wingman(args, tmp_.path());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_THAT(r.output, HasSubstr(message)) << r.output;
  }
  TempDir tmp_;
};

TEST_F(ObservabilityCli, ConfigThreeWithoutGpsJson) {
  const auto j = run_json({"--config", "3", "--uavs", "2", "--landmarks", "6", "--no-gps"});
  EXPECT_EQ(j.at("dim"), 36);
  EXPECT_EQ(j.at("rank"), 34);
  EXPECT_EQ(j.at("unobservable_modes"), 2);
  EXPECT_EQ(j.at("tolerance"), 1e-8);
  ASSERT_EQ(j.at("null_space").size(), 2u);
  EXPECT_EQ(j.at("null_space")[0].at("pivot"), "lead.x");
  EXPECT_EQ(j.at("null_space")[1].at("pivot"), "lead.y");
  EXPECT_EQ(j.at("singular_values").size(), 36u);
  EXPECT_FALSE(j.at("observable").at("uav2.y").get<bool>());
  EXPECT_TRUE(j.at("observable").at("uav2.z").get<bool>());
  EXPECT_TRUE(j.at("observable").at("lead.vx").get<bool>());
  EXPECT_EQ(j.at("unobservable_states").size(), 18u);
}

TEST_F(ObservabilityCli, ExplicitSensorsVisibilityAndOrder) {
  // Configuration 2 without GPS from an explicit list: 6 modes at order 1, 5 at order 2.
  const std::vector<std::string> c2 = {"--altimeter", "uav1", "--range", "uav1", "--landmarks", "4"};
  auto args = c2;
  EXPECT_EQ(run_json(args).at("unobservable_modes"), 6);
  args.insert(args.end(), {"--order", "2"});
  EXPECT_EQ(run_json(args).at("unobservable_modes"), 5);
  // Configuration 3 with only one shared landmark: 3 modes.
  EXPECT_EQ(run_json({"--config", "3", "--no-gps", "--visibility", "uav1:0-3,uav2:3-5"}).at("unobservable_modes"), 3);
  EXPECT_EQ(run_json({"--config", "1", "--gps"}).at("unobservable_modes"), 0);
}

TEST_F(ObservabilityCli, AlongAScenarioTrajectory) {
  const auto scn = (kSourceDir / "scenes" / "paper_gps_denied_synthetic.yaml").string();
  const auto j = run_json({"--scenario", scn, "--variant", "config3", "--at", "150"});
  EXPECT_EQ(j.at("unobservable_modes"), 2);  // the GPS-denied phase: configuration 3
  EXPECT_THAT(j.at("evaluated_at").get<std::string>(), HasSubstr("t = 150"));
  EXPECT_FALSE(j.at("sensors").at("gps").get<bool>());
  EXPECT_TRUE(run_json({"--scenario", scn, "--variant", "config3", "--at", "50"}).at("sensors").at("gps").get<bool>());
}

TEST_F(ObservabilityCli, TextReportNamesTheModesAndTheTolerance) {
  const RunResult r = run_wingman({"observability", "--config", "3", "--no-gps", "--tol", "1e-7"}, tmp_.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("dim(x) = 36, rank = 34, unobservable modes = 2"));
  EXPECT_THAT(r.output, HasSubstr("1e-07"));
  EXPECT_THAT(r.output, HasSubstr("lm5.y"));
}

TEST_F(ObservabilityCli, BadInputExits2) {
  expect_usage_error({"--config", "4"}, "--config");
  expect_usage_error({"--sees-lead", "uav3"}, "no uav3");
  expect_usage_error({"--altimeter", "quad1"}, "not a UAV name");
  expect_usage_error({"--visibility", "uav1:0-9"}, "outside 0..5");
  expect_usage_error({"--visibility", "0-3"}, "before any 'uavN:'");
  expect_usage_error({"--order", "99"}, "--order");
  expect_usage_error({"--tol", "0"}, "--tol");
  expect_usage_error({"--uavs", "0"}, "--uavs");
  expect_usage_error({"--scenario", "no/such/file.yaml"}, "file.yaml");
  expect_usage_error({"--scenario", (kSourceDir / "scenes" / "smoke.yaml").string(), "--at", "1e6"}, "--at");
  expect_usage_error({"--at", "3"}, "need --scenario");
  expect_usage_error({"--bogus"}, "bogus");
}

}  // namespace
}  // namespace wingman::app::test
