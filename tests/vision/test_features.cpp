// Feature extraction: detector parsing and errors, every detector on a synthetic aerial view,
// exclusion boxes and grid bucketing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/features2d.hpp>
#include <stdexcept>

#include "vision/features.hpp"
#include "vision_test_support.hpp"

using namespace wingman::vision;

TEST(Features, ParsesDetectorNamesAndRejectsUnknownOnesByName) {
  EXPECT_EQ(parse_detector("orb"), DetectorKind::Orb);
  EXPECT_EQ(parse_detector("akaze"), DetectorKind::Akaze);
  EXPECT_EQ(parse_detector("sift"), DetectorKind::Sift);
  EXPECT_EQ(parse_detector("gftt_orb"), DetectorKind::GfttOrb);
  for (auto k : {DetectorKind::Orb, DetectorKind::Akaze, DetectorKind::Sift, DetectorKind::GfttOrb})
    EXPECT_EQ(parse_detector(to_string(k)), k);
  try {
    parse_detector("surf");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'surf'"), std::string::npos) << e.what();
  }
}

TEST(Features, BadSettingsThrowNamingTheValue) {
  FeatureSettings s;
  s.max_features = 0;
  EXPECT_THROW(FeatureExtractor{s}, std::invalid_argument);
  s = {};
  s.grid_cols = 0;
  try {
    FeatureExtractor{s};
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("grid"), std::string::npos) << e.what();
  }
}

TEST(Features, SettingsSetInCodeAreHeldToTheBoundsOfTheirScenarioKeys) {
  FeatureSettings s;
  s.orb_levels = 20;  // frontend.orb.levels is in [1, 16]
  try {
    s.validate();
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("orb.levels must be in [1, 16], got 20"), std::string::npos) << e.what();
  }
  s = {};
  s.max_features = 200000;  // frontend.max_features is in [1, 100000]
  EXPECT_THROW(s.validate(), std::invalid_argument);
}

class EveryDetector : public ::testing::TestWithParam<DetectorKind> {};

TEST_P(EveryDetector, FindsSpreadDescribedFeaturesOutsideTheExclusionBox) {
  const test::PlaneScene scene;
  const cv::Mat img = scene.render(test::view_at({0, 0, 15}));
  FeatureSettings s;
  s.kind = GetParam();
  s.max_features = 500;
  s.grid_cols = 4;
  s.grid_rows = 4;
  const FeatureExtractor fx(s);
  const ExclusionBox box{{320, 240}, 60, 40};
  const Features f = fx.detect(img, {box});
  EXPECT_GE(f.size(), 300) << to_string(s.kind);
  EXPECT_LE(f.size(), 500);
  EXPECT_EQ(f.descriptors.rows, f.size());
  EXPECT_EQ(f.norm, s.kind == DetectorKind::Sift ? cv::NORM_L2 : cv::NORM_HAMMING);
  int in_box = 0;
  std::vector<int> per_cell(16, 0);
  for (int i = 0; i < f.size(); ++i) {
    if (box.contains(f.pixel(i))) ++in_box;
    ++per_cell[std::min(3, int(f.pixel(i).y() / 120)) * 4 + std::min(3, int(f.pixel(i).x() / 160))];
  }
  EXPECT_EQ(in_box, 0);
  // Bucketing: no cell is empty and none holds more than 2.5x its share.
  EXPECT_GT(*std::min_element(per_cell.begin(), per_cell.end()), 0);
  EXPECT_LE(*std::max_element(per_cell.begin(), per_cell.end()), 2.5 * 500 / 16);
  // A featureless image: no keypoint, and descriptors of the same kind and width, none of them.
  const Features none = fx.detect(cv::Mat(img.size(), img.type(), cv::Scalar::all(128)));
  EXPECT_EQ(none.size(), 0);
  EXPECT_EQ(none.descriptors.rows, 0);
  EXPECT_EQ(none.descriptors.type(), f.descriptors.type()) << to_string(s.kind);
  EXPECT_EQ(none.descriptors.cols, f.descriptors.cols) << to_string(s.kind);
}

INSTANTIATE_TEST_SUITE_P(Vision, EveryDetector,
                         ::testing::Values(DetectorKind::Orb, DetectorKind::Akaze, DetectorKind::Sift,
                                           DetectorKind::GfttOrb),
                         [](const auto& info) { return to_string(info.param); });

TEST(Features, BucketingKeepsTheStrongestPerCellBeforeFillingUp) {
  std::vector<cv::KeyPoint> kps;
  for (int i = 0; i < 100; ++i) kps.emplace_back(cv::Point2f(10 + i * 0.5f, 10), 7.f, -1.f, 100.f + i);  // top-left
  kps.emplace_back(cv::Point2f(150, 20), 7.f, -1.f, 1.f);  // top-right, weak
  kps.emplace_back(cv::Point2f(20, 150), 7.f, -1.f, 2.f);  // bottom-left, weak
  kps.emplace_back(cv::Point2f(150, 150), 7.f, -1.f, 3.f); // bottom-right, weak
  const auto kept = bucket_keypoints(kps, 200, 200, 2, 2, 20);
  ASSERT_EQ(kept.size(), 20u);
  int weak = 0;
  for (const auto& k : kept) weak += k.response < 10;
  EXPECT_EQ(weak, 3);  // every other cell keeps its single keypoint
  // The 17 others are the strongest of the crowded cell.
  for (const auto& k : kept) {
    if (k.response >= 10) {
      EXPECT_GE(k.response, 100.f + 100 - 17);
    }
  }
}

TEST(Features, OrbLevelCoordinatesMapBackThroughPixelCentres) {
  // Level 1 of a 1000 x 750 image is 833 x 625 (1000 / 1.2 = 833.3): level pixel 100 covers
  // image pixels 120.05-121.25, centre 120.65 - 0.5 = 120.145; OpenCV says 100 * 1.2 = 120.
  std::vector<cv::KeyPoint> k{cv::KeyPoint(cv::Point2f(120.f, 60.f), 31.f, -1.f, 0.f, 1),
                              cv::KeyPoint(cv::Point2f(33.f, 44.f), 31.f, -1.f, 0.f, 0)};
  orb_keypoints_to_pixel_centres(k, cv::Size(1000, 750), 1.2f);
  EXPECT_NEAR(k[0].pt.x, (100.0 + 0.5) * 1000.0 / 833.0 - 0.5, 1e-4);
  EXPECT_NEAR(k[0].pt.y, (50.0 + 0.5) * 750.0 / 625.0 - 0.5, 1e-4);
  EXPECT_FLOAT_EQ(k[1].pt.x, 33.f);  // level 0 is left alone
  EXPECT_FLOAT_EQ(k[1].pt.y, 44.f);
}

TEST(Features, OrbKeypointsSeenAtDifferentLevelsAgreeWithTheGeometry) {
  // The paper's two heights (15 m and 17 m): the same ground corner is often found one pyramid
  // level apart in the two views. Its pixel in the upper view, mapped through the plane to the
  // lower one, must land where ORB found it there, without a per-level offset.
  const test::PlaneScene scene;
  const CameraView a = test::view_at({0.4, -0.3, 15}), b = test::view_at({-0.5, 0.2, 17});
  FeatureSettings s;
  s.max_features = 2000;
  const FeatureExtractor fx(s);
  const Features fa = fx.detect(scene.render(a)), fb = fx.detect(scene.render(b));
  cv::BFMatcher bf(cv::NORM_HAMMING, true);
  std::vector<cv::DMatch> m;
  bf.match(fa.descriptors, fb.descriptors, m);
  struct Sum { int n = 0; Eigen::Vector2d e = Eigen::Vector2d::Zero(); };
  std::map<std::pair<int, int>, Sum> by_levels;
  for (const auto& d : m) {
    const auto g = test::PlaneScene::ground_point(a, fa.pixel(d.queryIdx));
    ASSERT_TRUE(g);
    const auto uv = b.camera.project(b.pose.to_camera(*g));
    if (!uv) continue;
    const Eigen::Vector2d e = fb.pixel(d.trainIdx) - *uv;
    if (e.norm() > 3) continue;  // a wrong match
    auto& sum = by_levels[{fa.keypoints[d.queryIdx].octave, fb.keypoints[d.trainIdx].octave}];
    ++sum.n;
    sum.e += e;
  }
  // The same-level pairs of this scene are off by up to 0.1 px themselves (the texture's
  // resampling); uncorrected, the level pairs with 40 or more matches here are 0.21, 0.39 and
  // 0.25 px off, 0.20 px pooled.
  int pairs = 0;
  Sum across;
  for (const auto& [levels, sum] : by_levels) {
    if (levels.first == levels.second || sum.n < 40) continue;
    ++pairs;
    across.n += sum.n;
    across.e += sum.e;
    const Eigen::Vector2d mean = sum.e / sum.n;
    EXPECT_LT(mean.norm(), 0.16) << "levels " << levels.first << " -> " << levels.second << ", "
                                 << sum.n << " matches, mean error " << mean.transpose();
  }
  EXPECT_LT((across.e / across.n).norm(), 0.06) << across.n << " matches across levels";
  EXPECT_GE(pairs, 2);
}

// orb.score: FAST's own score ranks the corners by an integer about the threshold or above; Harris's
// by its response, far below 1 on 8-bit grey. Both find the same kind of spread features.
TEST(Features, OrbScoreChoosesTheCornerRanking) {
  const test::PlaneScene scene;
  const cv::Mat img = scene.render(test::view_at({0, 0, 15}));
  for (const auto score : {cv::ORB::HARRIS_SCORE, cv::ORB::FAST_SCORE}) {
    FeatureSettings s;
    s.orb_score = score;
    s.max_features = 500;
    const Features f = FeatureExtractor(s).detect(img);
    ASSERT_GE(f.size(), 300);
    float lo = f.keypoints.front().response, hi = lo;
    for (const auto& k : f.keypoints) {
      lo = std::min(lo, k.response);
      hi = std::max(hi, k.response);
    }
    if (score == cv::ORB::FAST_SCORE) {
      EXPECT_GE(lo, static_cast<float>(s.orb_fast_threshold - 1));
      for (const auto& k : f.keypoints) EXPECT_EQ(k.response, std::round(k.response));
    } else {
      EXPECT_LT(hi, 1.0f);
    }
  }
}
