// The matching scores (frontend_bench/match_score.hpp) on hand-made keypoints and matches between two
// nadir frames whose true correspondences are A's pixel moved 10 px left.
#include <gtest/gtest.h>

#include <cmath>

#include "frontend_bench/match_score.hpp"
#include "frontend_bench/match_test_support.hpp"

namespace wingman::frontend_bench {
namespace {

using test::nadir_frame;

ScoreOptions one_three_five() {
  ScoreOptions o;
  o.thresholds_px = {1, 3, 5};
  return o;
}

std::vector<Keypoint> kps(std::initializer_list<Eigen::Vector2d> uvs) {
  std::vector<Keypoint> out;
  for (const auto& uv : uvs) out.push_back({uv, 0});
  return out;
}

// A: a0..a4 seen in B, a5 projects outside B. B: b0 exact for a0, b1 0.5 px and b2 2 px off
// a1 and a2, b3 far from every truth, b4 exact for a4 (left unmatched).
struct Scene {
  FrameTruth a = nadir_frame({0, 0, 10}), b = nadir_frame({2, 0, 10});
  std::vector<Keypoint> kp_a = kps({{60, 40}, {70, 50}, {80, 60}, {65, 30}, {90, 20}, {5, 40}});
  std::vector<Keypoint> kp_b = kps({{50, 40}, {60.5, 50}, {72, 60}, {20, 80}, {80, 20}});
};

TEST(ScorePair, CountsCorrectAndWrongMatchesPerThreshold) {
  const Scene s;
  const std::vector<Match> matches{{0, 0}, {1, 1}, {2, 2}, {3, 3}, {5, 0}};
  const MatchCounts c = score_pair(s.a, s.b, s.kp_a, s.kp_b, matches, one_three_five());
  EXPECT_EQ(c.keypoints_a, 6);
  EXPECT_EQ(c.covisible, 5);
  EXPECT_EQ(c.matches, 5);
  EXPECT_EQ(c.repeatable, (std::vector<long>{3, 4, 4}));  // a0, a1, a4; then a2 too
  EXPECT_EQ(c.correct, (std::vector<long>{2, 3, 3}));
  EXPECT_DOUBLE_EQ(c.precision(0), 0.4);
  EXPECT_DOUBLE_EQ(c.precision(1), 0.6);
  EXPECT_DOUBLE_EQ(c.recall(0), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(c.recall(1), 0.75);
  EXPECT_DOUBLE_EQ(c.repeatability(0), 0.6);
  EXPECT_DOUBLE_EQ(c.repeatability(1), 0.8);
  EXPECT_EQ(c.localised, 3);
  EXPECT_NEAR(c.localisation_px(), (0 + 0.5 + 2) / 3.0, 1e-9);
}

TEST(ScorePair, KeypointMatchedTwiceCountsOnceInRecallTwiceInPrecision) {
  const Scene s;
  const std::vector<Match> matches{{0, 0}, {0, 0}};
  const MatchCounts c = score_pair(s.a, s.b, s.kp_a, s.kp_b, matches, one_three_five());
  EXPECT_EQ(c.correct[0], 2);
  EXPECT_EQ(c.correct_a[0], 1);
  EXPECT_DOUBLE_EQ(c.precision(0), 1.0);
  EXPECT_DOUBLE_EQ(c.recall(0), 1.0 / 3.0);
}

TEST(ScorePair, OccludedKeypointIsNeitherCovisibleNorCorrectlyMatched) {
  Scene s;
  s.b.depth(cv::Rect(45, 35, 10, 10)).setTo(6.0);  // hides a0's point from B
  const MatchCounts c = score_pair(s.a, s.b, s.kp_a, s.kp_b, {{0, 0}}, one_three_five());
  EXPECT_EQ(c.covisible, 4);
  EXPECT_EQ(c.correct[2], 0);
  EXPECT_DOUBLE_EQ(c.precision(2), 0.0);
}

TEST(ScorePair, NoMatchesGivesNoPrecisionAndZeroRecall) {
  const Scene s;
  const MatchCounts c = score_pair(s.a, s.b, s.kp_a, s.kp_b, {}, one_three_five());
  EXPECT_TRUE(std::isnan(c.precision(1)));
  EXPECT_DOUBLE_EQ(c.recall(1), 0.0);
  EXPECT_TRUE(std::isnan(c.localisation_px()));
}

TEST(GroupScores, PoolsCountsPerPairTypeAndBaselineBin) {
  const ScoreOptions o = one_three_five();  // bins 0-0.5, 0.5-1.5, 1.5-3, >=3 m
  std::vector<FramePair> pairs{{0, "uav1", 0, "uav1", 1, PairType::Temporal, 0.2},
                               {1, "uav1", 0, "uav1", 5, PairType::Temporal, 2.0},
                               {2, "uav1", 0, "uav2", 0, PairType::Cross, 3.6}};
  std::vector<MatchCounts> counts(3, MatchCounts(3));
  for (int i = 0; i < 3; ++i) {
    counts[i].pairs = 1;
    counts[i].matches = 10 * (i + 1);
    counts[i].correct = {i + 1, i + 2, i + 3};
  }
  const auto g = group_scores(pairs, counts, o);
  ASSERT_EQ(g.size(), 6u);
  EXPECT_EQ(g[0].type, "all");
  EXPECT_EQ(g[0].counts.matches, 60);
  EXPECT_EQ(g[1].type, "temporal");
  EXPECT_EQ(g[1].baseline, "all");
  EXPECT_EQ(g[1].counts.matches, 30);
  EXPECT_DOUBLE_EQ(g[1].counts.precision(1), 5.0 / 30.0);
  EXPECT_EQ(g[2].baseline, "0-0.5 m");
  EXPECT_EQ(g[3].baseline, "1.5-3 m");
  EXPECT_EQ(g[3].counts.matches, 20);
  EXPECT_EQ(g[4].type, "cross");
  EXPECT_EQ(g[5].baseline, ">=3 m");
  EXPECT_EQ(g[5].counts.correct[2], 5);
}

TEST(GroupScores, GroupsEachConditionByTypeAfterTheReference) {
  const ScoreOptions o = one_three_five();
  std::vector<FramePair> pairs{{0, "uav1", 0, "uav1", 1, PairType::Temporal, 0.2, "blur"},
                               {1, "uav1", 0, "uav1", 0, PairType::SameInstant, 0, "blur"},
                               {2, "uav1", 0, "uav1", 1, PairType::Temporal, 0.2, kReference},
                               {3, "uav1", 0, "uav1", 0, PairType::SameInstant, 0, "noise"}};
  std::vector<MatchCounts> counts(4, MatchCounts(3));
  for (int i = 0; i < 4; ++i) {
    counts[i].pairs = 1;
    counts[i].matches = 10 * (i + 1);
  }
  const auto g = group_scores(pairs, counts, o);
  // reference: all, temporal, its bin; blur: all, temporal, bin, same-instant, bin; noise: all, same-instant, bin.
  ASSERT_EQ(g.size(), 11u);
  EXPECT_EQ(g[0].condition, kReference);
  EXPECT_EQ(g[0].counts.matches, 30);
  EXPECT_EQ(g[3].condition, "blur");
  EXPECT_EQ(g[3].type, "all");
  EXPECT_EQ(g[3].counts.matches, 30);
  EXPECT_EQ(g[6].type, "same-instant");
  EXPECT_EQ(g[6].counts.matches, 20);
  EXPECT_EQ(g[7].baseline, "0-0.5 m");
  EXPECT_EQ(g[8].condition, "noise");
  EXPECT_EQ(g[9].type, "same-instant");
  EXPECT_EQ(g[10].counts.matches, 40);
}

}  // namespace
}  // namespace wingman::frontend_bench
