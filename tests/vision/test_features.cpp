// Feature extraction: detector parsing and errors, every detector on a synthetic aerial view,
// exclusion boxes and grid bucketing.
#include <gtest/gtest.h>

#include <algorithm>
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
