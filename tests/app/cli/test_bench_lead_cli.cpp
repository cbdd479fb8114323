// `wingman bench-lead`: the learned detector scored on a rendered dataset of an unmarked truck; the
// detections it writes score the same when read back; the motion detector runs in a flight and in
// the benchmark; bad input (a malformed detections row, a missing weights file, a detector the
// world's cue cannot serve, motion settings that contradict each other) exits 2 naming the file
// and line with nothing written.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "app/app_test_support.hpp"

namespace wingman::app::test {
namespace {

std::string unmarked_truck(const std::string& frontend = "") {
  const std::string cam = "camera: {fx: 200, fy: 200, cx: 159.5, cy: 119.5, width: 320, height: 240}";
  std::string s = "name: unmarked\nrate: 10\nduration: 1\nmeasurements: rendered\n";
  s += "uavs:\n  - {name: uav1, initial_position: [-1.5, 0, 15], sees_lead: true, ";
  s += cam;
  s += "}\n  - {name: uav2, initial_position: [1.5, 0, 17], range: false, ";
  s += cam;
  s += "}\nworld: {lead: {cue: none}, image: {msaa: 1}}\n";
  s += frontend;
  return s;
}

TEST(BenchLeadCli, TheLearnedDetectorFindsTheUnmarkedTruckAndItsDetectionsScoreTheSameReadBack) {
  TempDir tmp;
  write_file(tmp / "s.yaml", unmarked_truck());
  const fs::path ds = tmp / "ds";
  const auto r = run_wingman({"render", (tmp / "s.yaml").string(), "--out", ds.string(), "-q"}, tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto b = run_wingman({"bench-lead", ds.string(), "--prediction-sigma", "3", "--quiet", "--out",
                              (tmp / "scores").string(), "--write-detections", (tmp / "det.csv").string()},
                             tmp.path());
  ASSERT_EQ(b.exit_code, 0) << b.output;
  EXPECT_THAT(b.output, ::testing::HasSubstr("Lead detector: learned"));
  const auto j = nlohmann::json::parse(read_file(tmp / "scores" / "lead_scores.json"));
  const auto& all = j["scores"][0];
  EXPECT_EQ(all["by"], "all");
  EXPECT_EQ(all["frames"], 22);
  EXPECT_EQ(all["showing"], 22);
  EXPECT_GE(all["detection_rate"].get<double>(), 0.9);
  EXPECT_LE(all["median_px"].get<double>(), 1.5);
  EXPECT_EQ(all["false_detections"], 0);
  const auto again = run_wingman({"bench-lead", ds.string(), "--detections", (tmp / "det.csv").string(), "--quiet"},
                                 tmp.path());
  ASSERT_EQ(again.exit_code, 0) << again.output;
  const std::string row = b.output.substr(b.output.find("\nall"), 60);
  EXPECT_THAT(again.output, ::testing::HasSubstr(row.substr(0, row.find("  ", 40))));
}

TEST(BenchLeadCli, BadInputExitsTwoNamingTheFileWithNothingWritten) {
  TempDir tmp;
  write_file(tmp / "s.yaml", unmarked_truck());
  const fs::path ds = tmp / "ds";
  ASSERT_EQ(run_wingman({"render", (tmp / "s.yaml").string(), "--out", ds.string(), "-q"}, tmp.path()).exit_code, 0);
  write_file(tmp / "det.csv", "#dataset,agent,timestamp [ns],u [px],v [px],score\n,uav1,0,10,oops,1\n");
  auto r = run_wingman({"bench-lead", ds.string(), "--detections", (tmp / "det.csv").string(), "--out",
                        (tmp / "o1").string()},
                       tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, ::testing::HasSubstr((tmp / "det.csv").string() + ":2: v 'oops' is not a finite number"));
  EXPECT_FALSE(fs::exists(tmp / "o1"));

  r = run_wingman({"bench-lead", ds.string(), "--weights", (tmp / "none.onnx").string(), "--out", (tmp / "o2").string()},
                  tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, ::testing::HasSubstr((tmp / "none.onnx").string() + ": weights file not found"));
  EXPECT_FALSE(fs::exists(tmp / "o2"));

  write_file(tmp / "aruco.yaml", unmarked_truck("frontend: {lead_detector: aruco}\n"));
  r = run_wingman({"run", (tmp / "aruco.yaml").string(), "--out", (tmp / "o3").string()}, tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, ::testing::HasSubstr("aruco.yaml:9:27: frontend.lead_detector: "));
  EXPECT_THAT(r.output, ::testing::HasSubstr("it needs world.lead.cue: aruco"));
  EXPECT_FALSE(fs::exists(tmp / "o3"));

  write_file(tmp / "w.yaml", unmarked_truck("frontend: {learned_lead: {weights: missing.onnx}}\n"));
  r = run_wingman({"run", (tmp / "w.yaml").string(), "--out", (tmp / "o4").string()}, tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, ::testing::HasSubstr("w.yaml:9:36: frontend.learned_lead.weights: lead detector weights 'missing.onnx': file not found"));
  EXPECT_THAT(r.output, ::testing::HasSubstr("missing.onnx"));
  EXPECT_FALSE(fs::exists(tmp / "o4"));

  write_file(tmp / "m.yaml", unmarked_truck("frontend: {lead_detector: motion, motion_lead: {references: 6, history: 5}}\n"));
  r = run_wingman({"run", (tmp / "m.yaml").string(), "--out", (tmp / "o5").string()}, tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, ::testing::HasSubstr("m.yaml:9:73: frontend.motion_lead.history: motion lead detector: "
                                             "history must be >= references, got 5"));
  EXPECT_FALSE(fs::exists(tmp / "o5"));
}

TEST(BenchLeadCli, TheMotionDetectorRunsInAFlightAndInTheBenchmark) {
  TempDir tmp;
  write_file(tmp / "s.yaml", unmarked_truck("frontend: {lead_detector: motion}\n"));
  const auto r = run_wingman({"run", (tmp / "s.yaml").string(), "--out", (tmp / "run").string(), "-q", "--no-plots"},
                             tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(tmp / "run" / "lead.csv"));
  const fs::path ds = tmp / "ds";
  ASSERT_EQ(run_wingman({"render", (tmp / "s.yaml").string(), "--out", ds.string(), "-q"}, tmp.path()).exit_code, 0);
  const auto b = run_wingman({"bench-lead", ds.string(), "--quiet"}, tmp.path());
  ASSERT_EQ(b.exit_code, 0) << b.output;
  EXPECT_THAT(b.output, ::testing::HasSubstr("Lead detector: motion"));
}

}  // namespace
}  // namespace wingman::app::test
