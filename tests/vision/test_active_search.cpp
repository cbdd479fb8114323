// Active search: the regions planned from the filter's predictions and the map's needs, and
// detection inside them against detection over the whole frame.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>

#include "vision/active_search.hpp"
#include "vision/features.hpp"
#include "vision_test_support.hpp"

using namespace wingman::vision;

namespace {

LandmarkPrediction pred(int id, double u, double v, double var = 4.0) {
  LandmarkPrediction p;
  p.id = id;
  p.uv = {u, v};
  p.S = Eigen::Matrix2d::Identity() * var;
  return p;
}

bool covered(const std::vector<cv::Rect>& regions, const cv::Rect& box) {
  return std::any_of(regions.begin(), regions.end(), [&](const cv::Rect& r) { return (r & box) == box; });
}

}  // namespace

TEST(PlanSearch, CoversEveryGateAndOpensBlocksWhereNoLandmarkIs) {
  const cv::Size image(1000, 1000);
  // Landmarks along the diagonal from the top left: the emptiest blocks nearest the centre lie off it.
  std::vector<LandmarkPrediction> preds;
  for (int i = 0; i < 10; ++i) preds.push_back(pred(i, 60 + 40 * i, 100 + 80 * i));
  const TrackingSettings tracking;
  const ActiveSearchSettings settings;  // blocks of 125 px, 3 landmarks each
  const SearchPlan plan =
      plan_search(image, preds, new_landmark_blocks(image, preds, 7, settings), 55, tracking, settings);
  ASSERT_FALSE(plan.whole_frame);
  EXPECT_EQ(plan.gates, 10);
  EXPECT_EQ(plan.blocks, 3);  // ceil(7 / 3)
  for (const auto& p : preds) {
    // The gate's box: 3 sigma of 2 px, plus the pixel kept beyond it.
    const cv::Rect gate(static_cast<int>(p.uv.x()) - 7, static_cast<int>(p.uv.y()) - 7, 15, 15);
    EXPECT_TRUE(covered(plan.regions, gate)) << "landmark " << p.id;
  }
  for (std::size_t i = 0; i < plan.regions.size(); ++i)
    for (std::size_t j = i + 1; j < plan.regions.size(); ++j)
      EXPECT_TRUE((plan.regions[i] & plan.regions[j]).empty()) << "regions " << i << " and " << j << " overlap";
  // Three whole blocks of 125 px, none holding a landmark.
  int block_area = 0;
  for (const auto& r : plan.regions)
    if (r.width >= 125 && r.height >= 125) {
      block_area += r.area();
      for (const auto& p : preds) EXPECT_FALSE(r.contains(cv::Point(int(p.uv.x()), int(p.uv.y()))));
    }
  EXPECT_GE(block_area, 3 * 125 * 125);
  // What the detector processes: every region with 55 px of context, well under the frame.
  double area = 0;
  for (const auto& r : plan.regions)
    area += (cv::Rect(r.x - 55, r.y - 55, r.width + 110, r.height + 110) & cv::Rect(0, 0, 1000, 1000)).area();
  EXPECT_NEAR(plan.fraction, area / 1e6, 1e-12);
  EXPECT_LT(plan.fraction, 0.6);
}

TEST(PlanSearch, MergesOverlappingGatesIntoOneRegion) {
  const std::vector<LandmarkPrediction> preds{pred(1, 500, 500, 25.0), pred(2, 510, 505, 25.0)};
  const SearchPlan plan = plan_search({1000, 1000}, preds, {}, 55, {}, {});
  ASSERT_FALSE(plan.whole_frame);
  ASSERT_EQ(plan.regions.size(), 1u);
  EXPECT_EQ(plan.blocks, 0);
  EXPECT_TRUE(plan.regions[0].contains({485, 485}));
  EXPECT_TRUE(plan.regions[0].contains({525, 520}));
}

TEST(PlanSearch, DetectsTheWholeFrameWhenTheCropsWouldCostMoreOrWhenSwitchedOff) {
  // Fresh landmarks: gates capped at 150 px, all over the image.
  std::vector<LandmarkPrediction> preds;
  for (int i = 0; i < 9; ++i) preds.push_back(pred(i, 150 + 350 * (i % 3), 150 + 350 * (i / 3), 1e4));
  const SearchPlan big = plan_search({1000, 1000}, preds, {}, 55, {}, {});
  EXPECT_TRUE(big.whole_frame);
  EXPECT_TRUE(big.regions.empty());
  EXPECT_EQ(big.fraction, 1.0);
  ActiveSearchSettings off;
  off.enabled = false;
  EXPECT_TRUE(plan_search({1000, 1000}, {pred(1, 500, 500)}, {}, 55, {}, off).whole_frame);
  ActiveSearchSettings bad;
  bad.landmarks_per_block = 0;
  EXPECT_THROW(new_landmark_blocks({1000, 1000}, {}, 1, bad), std::invalid_argument);
  EXPECT_THROW(plan_search({1000, 1000}, {}, {}, 55, {}, bad), std::invalid_argument);
}

// Inside a region, the crop's keypoints are the whole frame's at pyramid level 0: the same pixels
// and descriptors. Above it, the crop's own pyramid samples the ground at another sub-pixel phase
// (as the whole frame's does after the camera moves by a fraction of a pixel), so weak corners
// come and go: there the crop finds as many keypoints, not the same ones.
TEST(DetectIn, FindsTheWholeFramesKeypointsInsideItsRegions) {
  const test::PlaneScene scene;
  const cv::Mat img = scene.render(test::view_at({0, 0, 15}));
  FeatureSettings s;
  s.max_features = 100000;  // budgets neither path reaches: both keep every corner
  s.oversample = 20.0;
  const FeatureExtractor fx(s);
  // The last two touch the frame's edge, near which the whole frame keeps no keypoint.
  const std::vector<cv::Rect> regions{{100, 80, 120, 90}, {400, 300, 150, 100}, {0, 200, 80, 60}, {250, 0, 300, 40}};
  const ExclusionBox box{{470, 350}, 20, 20};
  const Features whole = fx.detect(img, {box});
  const Features part = fx.detect_in(img, regions, {box});
  ASSERT_GT(part.size(), 50);
  EXPECT_EQ(part.descriptors.rows, part.size());
  auto inside = [&](const cv::Point2f& pt, int slack) {
    return covered(regions, cv::Rect(cvRound(pt.x) - slack, cvRound(pt.y) - slack, 2 * slack + 1, 2 * slack + 1));
  };
  std::vector<int> upper_part(s.orb_levels, 0), upper_whole(s.orb_levels, 0);
  for (int i = 0; i < part.size(); ++i) {
    // Upper levels' keypoints move by up to 0.7 px into level 0's pixel centres.
    const cv::Rect near(cvRound(part.keypoints[i].pt.x) - 1, cvRound(part.keypoints[i].pt.y) - 1, 3, 3);
    EXPECT_TRUE(std::any_of(regions.begin(), regions.end(), [&](const cv::Rect& r) { return (r & near).area() > 0; }))
        << part.keypoints[i].pt;
    EXPECT_FALSE(box.contains(part.pixel(i))) << part.keypoints[i].pt;
    if (part.keypoints[i].octave > 0 && inside(part.keypoints[i].pt, 2)) ++upper_part[part.keypoints[i].octave];
  }
  int level0 = 0, level0_same = 0;
  for (int i = 0; i < whole.size(); ++i) {
    const cv::KeyPoint& k = whole.keypoints[i];
    if (!inside(k.pt, 2)) continue;  // well inside: a keypoint on the edge may fall either side
    if (k.octave > 0) {
      ++upper_whole[k.octave];
      continue;
    }
    ++level0;
    for (int j = 0; j < part.size(); ++j)
      if (part.keypoints[j].octave == 0 && cv::norm(part.keypoints[j].pt - k.pt) < 1e-3 &&
          cv::norm(part.descriptors.row(j), whole.descriptors.row(i), cv::NORM_HAMMING) == 0) {
        ++level0_same;
        break;
      }
  }
  // And the other way: nothing at level 0 the whole frame does not have (at its edge, say).
  int part0 = 0, part0_in_whole = 0;
  for (const auto& k : part.keypoints) {
    if (k.octave != 0) continue;
    ++part0;
    part0_in_whole += std::any_of(whole.keypoints.begin(), whole.keypoints.end(), [&](const cv::KeyPoint& w) {
      return w.octave == 0 && cv::norm(w.pt - k.pt) < 1e-3;
    });
  }
  EXPECT_EQ(part0_in_whole, part0);
  // Nor near the frame's edge at any level: 31 px of the keypoint's level (less the up to 0.7 px
  // its coordinates move to level 0's pixel centres).
  for (const auto& k : part.keypoints) {
    const float e = 31.f * std::pow(s.orb_scale_factor, static_cast<float>(k.octave)) - 0.7f;
    EXPECT_TRUE(k.pt.x >= e && k.pt.y >= e && k.pt.x < img.cols - e && k.pt.y < img.rows - e)
        << k.pt << " at level " << k.octave;
  }
  ASSERT_GT(level0, 30);
  EXPECT_GE(level0_same, 0.98 * level0) << level0_same << " of " << level0;
  for (int l = 1; l < s.orb_levels; ++l) {
    ASSERT_GT(upper_whole[l], 30) << "level " << l;
    EXPECT_NEAR(upper_part[l], upper_whole[l], 0.2 * upper_whole[l]) << "level " << l;
  }
  // No region: no keypoint, and descriptors of the detector's kind.
  const Features none = fx.detect_in(img, {});
  EXPECT_EQ(none.size(), 0);
  EXPECT_EQ(none.descriptors.type(), whole.descriptors.type());
  EXPECT_EQ(none.descriptors.cols, whole.descriptors.cols);
}
