// Plain descriptor matching (vision/descriptor_match.hpp) between two views of the textured plane.
#include <gtest/gtest.h>

#include <set>

#include "vision/descriptor_match.hpp"
#include "vision/labelling.hpp"
#include "vision_test_support.hpp"

namespace wingman::vision {
namespace {

using test::PlaneScene;
using test::view_at;

TEST(DescriptorMatch, RatioAndMutualCheckKeepMostlyTrueOneToOneMatches) {
  const PlaneScene scene;
  const CameraView va = view_at({0, 0, 15}), vb = view_at({1.5, 0.8, 15.2}, 0.12);
  FeatureSettings fs;
  fs.max_features = 500;
  const FeatureExtractor fx(fs);
  const Features a = fx.detect(scene.render(va)), b = fx.detect(scene.render(vb));
  const auto matches = match_descriptors(a, b);
  ASSERT_GT(matches.size(), 150u);
  const cv::Mat da = scene.depth(va), db = scene.depth(vb);
  std::set<int> used_b;
  int correct = 0;
  for (const auto& m : matches) {
    EXPECT_TRUE(used_b.insert(m.trainIdx).second) << "keypoint of B matched twice";
    const auto l = label_pixel_pair(a.pixel(m.queryIdx), va.camera, va.pose, da,
                                    b.pixel(m.trainIdx), vb.camera, vb.pose, db);
    correct += l.label == Label::Inlier;
  }
  EXPECT_GT(correct, 0.9 * static_cast<double>(matches.size()));
  for (std::size_t i = 1; i < matches.size(); ++i) EXPECT_LE(matches[i - 1].distance, matches[i].distance);
  // Without the ratio test and the mutual check, more matches and fewer of them right.
  const auto loose = match_descriptors(a, b, {1.0, false});
  EXPECT_GT(loose.size(), matches.size());
}

TEST(DescriptorMatch, EmptyImageGivesNoMatchesAndBadRatioIsRefused) {
  const Features none;
  EXPECT_TRUE(match_descriptors(none, none).empty());
  EXPECT_THROW(match_descriptors(none, none, {1.5, true}), std::invalid_argument);
}

}  // namespace
}  // namespace wingman::vision
