// The lead detectors' benchmark scores: the detection rate over the frames that show the lead, the
// false detections, the pixel error and the groupings, on frames made by hand; and the detections
// file, read back and refused naming its line when a row is malformed.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "frontend_bench/lead_scores.hpp"
#include "frontend_bench/match_files.hpp"

namespace wingman::frontend_bench {
namespace {

namespace fs = std::filesystem;

LeadFrame frame(const std::string& lead, double u, double visible, double distance,
                std::optional<Eigen::Vector2d> detected) {
  static const std::string kAgent = "uav1", kGround = "g";
  LeadFrame f;
  f.agent = kAgent;
  f.t_ns = 0;
  f.lead = lead;
  f.ground = kGround;
  f.width = 640, f.height = 480;
  f.truth.uv = {u, 100};
  f.truth.visible = visible;
  f.truth.distance = distance;
  f.detected = detected;
  f.cpu_ms = 2;
  return f;
}

TEST(LeadScores, RateFalseDetectionsAndErrorFollowTheFrames) {
  const std::vector<LeadFrame> frames{
      frame("truck", 100, 1.0, 10, Eigen::Vector2d(101, 100)),   // found, 1 px
      frame("truck", 200, 0.9, 10, Eigen::Vector2d(203, 104)),   // found, 5 px
      frame("truck", 300, 1.0, 15, Eigen::Vector2d(350, 100)),   // false (50 px)
      frame("person", 400, 0.5, 15, Eigen::Vector2d(400, 100)),  // hidden half: not counted, not false
      frame("person", 700, 1.0, 15, std::nullopt),               // x_h outside the image: not counted
      frame("person", 500, 1.0, 25, std::nullopt)};              // missed
  const auto s = score_leads(frames, {});
  ASSERT_FALSE(s.empty());
  EXPECT_EQ(s[0].by, "all");
  EXPECT_EQ(s[0].frames, 6);
  EXPECT_EQ(s[0].showing, 4);
  EXPECT_EQ(s[0].found, 2);
  EXPECT_EQ(s[0].false_detections, 1);
  EXPECT_DOUBLE_EQ(s[0].median_px, 3.0);
  EXPECT_DOUBLE_EQ(s[0].cpu_ms, 2.0);
  auto row = [&](const std::string& by, const std::string& key) {
    for (const auto& x : s)
      if (x.by == by && x.key == key) return x;
    ADD_FAILURE() << by << " " << key;
    return LeadScore{};
  };
  EXPECT_DOUBLE_EQ(row("lead", "truck").rate(), 2.0 / 3.0);
  EXPECT_EQ(row("lead", "person").showing, 1);
  EXPECT_EQ(row("distance", "8-12 m").found, 2);
  EXPECT_EQ(row("distance", ">= 20 m").frames, 1);
  // Per visible share the rate counts every frame with x_h in the image.
  EXPECT_EQ(row("visible", "0.5-0.8").showing, 1);
  EXPECT_EQ(row("visible", "0.5-0.8").found, 1);
}

TEST(LeadScores, TheDetectionsFileRoundTripsAndTheBestScoreOfAFrameCounts) {
  const fs::path p = fs::temp_directory_path() / ("wingman-lead-det-" + std::to_string(::getpid()) + ".csv");
  std::vector<LeadDetectionRow> rows{{"", "uav1", 100, {10.5, 20.25}, 0.4}, {"", "uav1", 100, {30, 40}, 0.9}};
  std::ofstream(p) << lead_detections_csv(rows);
  const auto back = read_lead_detections(p);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_DOUBLE_EQ(back[0].uv.y(), 20.25);
  std::vector<LeadFrame> frames{frame("truck", 30, 1, 10, std::nullopt)};
  frames[0].t_ns = 100;
  attach_detections(frames, back, p);
  ASSERT_TRUE(frames[0].detected);
  EXPECT_DOUBLE_EQ(frames[0].detected->x(), 30);
  fs::remove(p);
}

TEST(LeadScores, AMalformedDetectionsRowIsRefusedNamingTheFileAndLine) {
  const fs::path p = fs::temp_directory_path() / ("wingman-lead-bad-" + std::to_string(::getpid()) + ".csv");
  for (const auto& [row, why] : {std::pair{",uav1,100,10,x,1", "v 'x' is not a finite number"},
                                 std::pair{",uav1,100,10,20", "expected 6 columns"},
                                 std::pair{",uav1,-5,10,20,1", "timestamp '-5' is not whole nanoseconds >= 0"},
                                 std::pair{",,100,10,20,1", "the agent is empty"}}) {
    std::ofstream(p) << kLeadDetectionsHeader << "\n,uav1,0,1,2,1\n" << row << "\n";
    try {
      read_lead_detections(p);
      ADD_FAILURE() << row;
    } catch (const MatchInputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(p.string() + ":3: " + why, 0), 0u) << e.what();
    }
  }
  fs::remove(p);
}

}  // namespace
}  // namespace wingman::frontend_bench
