// Gated tracking on a synthetic aerial view: landmarks from a first view are found in a second view
// from their predicted projections and innovation covariances.
#include <gtest/gtest.h>

#include <numbers>
#include <random>
#include <set>

#include "vision/tracking.hpp"
#include "vision_test_support.hpp"

using namespace wingman::vision;
using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {

struct Landmarks {
  std::vector<Vector3d> points;  // index = id
  DescriptorStore store;
};

// Landmarks from the features of view a (their rays met with the ground plane).
Landmarks make_landmarks(const Features& f, const CameraView& a) {
  Landmarks L;
  for (int i = 0; i < f.size(); ++i) {
    const auto p = test::PlaneScene::ground_point(a, f.pixel(i));
    if (!p) continue;
    L.store.add(static_cast<LandmarkId>(L.points.size()), f.descriptors.row(i), 0);
    L.points.push_back(*p);
  }
  return L;
}

// Predictions in view b: the true projection moved by `offset(rng)`, with covariance S.
template <class Offset>
std::vector<LandmarkPrediction> predict(const Landmarks& L, const CameraView& b, const Eigen::Matrix2d& S,
                                        Offset offset) {
  std::vector<LandmarkPrediction> out;
  for (std::size_t id = 0; id < L.points.size(); ++id) {
    const auto uv = b.camera.project(b.pose.to_camera(L.points[id]));
    if (!uv || !b.camera.in_image(*uv, 20)) continue;
    out.push_back({static_cast<LandmarkId>(id), *uv + offset(), S});
  }
  return out;
}

Vector2d truth(const Landmarks& L, const CameraView& b, LandmarkId id) {
  return *b.camera.project(b.pose.to_camera(L.points[id]));
}

}  // namespace

class TrackEveryDetector : public ::testing::TestWithParam<DetectorKind> {};

// Yaw 1 rad between the views as well: the descriptors must be rotation invariant (GFTT corners get
// their orientation in features.cpp).
TEST_P(TrackEveryDetector, FindsAtLeast90PercentCorrectCorrespondencesFromGoodPredictions) {
  const test::PlaneScene scene;
  for (double yaw : {0.12, 1.0}) {
  SCOPED_TRACE("yaw " + std::to_string(yaw));
  const CameraView a = test::view_at({0, 0, 15}), b = test::view_at({1.5, 0.8, 15.8}, yaw, 0.03);
  FeatureSettings fs;
  fs.kind = GetParam();
  fs.max_features = 600;
  const FeatureExtractor fx(fs);
  const Features fa = fx.detect(scene.render(a)), fb = fx.detect(scene.render(b));
  const Landmarks L = make_landmarks(fa, a);

  // Prediction error N(0, 2^2) per axis plus 1.5 px detection noise: S = (4 + 2.25) I.
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0, 2.0);
  const auto preds = predict(L, b, 6.25 * Eigen::Matrix2d::Identity(), [&] { return Vector2d(n(rng), n(rng)); });
  ASSERT_GE(preds.size(), 300u);
  const TrackingResult r = track_landmarks(preds, fb, L.store);

  int correct = 0;
  std::set<int> kps;
  for (const auto& c : r.candidates) {
    correct += (c.uv - truth(L, b, c.id)).norm() <= 3.0;
    EXPECT_LE(c.d2, 9.0);
    EXPECT_TRUE(kps.insert(c.keypoint).second) << "keypoint used twice";
    EXPECT_TRUE(r.keypoint_used[c.keypoint]);
  }
  const double found = double(r.candidates.size()) / preds.size();
  const double precision = double(correct) / std::max<std::size_t>(1, r.candidates.size());
  EXPECT_GE(found, 0.4) << to_string(fs.kind) << ": " << r.candidates.size() << " of " << preds.size();
  EXPECT_GE(precision, 0.9) << to_string(fs.kind);
  EXPECT_EQ(r.searched, static_cast<int>(preds.size()));
  }
}

INSTANTIATE_TEST_SUITE_P(Vision, TrackEveryDetector,
                         ::testing::Values(DetectorKind::Orb, DetectorKind::Akaze, DetectorKind::Sift,
                                           DetectorKind::GfttOrb),
                         [](const auto& info) { return to_string(info.param); });

TEST(Tracking, LandmarksPredictedFarOutsideTheirEllipseAreNotMatchedToTheirTrueFeature) {
  const test::PlaneScene scene;
  const CameraView a = test::view_at({0, 0, 15}), b = test::view_at({1.0, 0.5, 15.5}, 0.05);
  const FeatureExtractor fx;
  const Features fa = fx.detect(scene.render(a)), fb = fx.detect(scene.render(b));
  const Landmarks L = make_landmarks(fa, a);
  // 40 px off in a random direction, S = 16 I: the gate (d <= 3) reaches 12 px.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> ang(0, 2 * std::numbers::pi);
  const auto preds = predict(L, b, 16 * Eigen::Matrix2d::Identity(), [&] {
    const double t = ang(rng);
    return Vector2d(40 * std::cos(t), 40 * std::sin(t));
  });
  ASSERT_GE(preds.size(), 300u);
  const TrackingResult r = track_landmarks(preds, fb, L.store);
  for (const auto& c : r.candidates) {
    EXPECT_GT((c.uv - truth(L, b, c.id)).norm(), 20.0);
    EXPECT_LE(c.d2, 9.0);
  }
  // What is left inside the wrong ellipses is other texture: the descriptor threshold and the
  // ratio test keep almost all of it out.
  EXPECT_LE(r.candidates.size(), preds.size() / 20) << r.candidates.size() << " of " << preds.size();

  // Same predictions with the right pixel: found again.
  const auto good = predict(L, b, 16 * Eigen::Matrix2d::Identity(), [] { return Vector2d(0, 0); });
  EXPECT_GE(track_landmarks(good, fb, L.store).candidates.size(), good.size() / 2);
}

TEST(Tracking, TheEllipseFollowsTheShapeOfS) {
  // One keypoint 10 px right of the prediction: inside an ellipse elongated along u, outside
  // the same ellipse elongated along v.
  const test::PlaneScene scene;
  const CameraView a = test::view_at({0, 0, 15});
  const Features f = FeatureExtractor().detect(scene.render(a));
  DescriptorStore store;
  store.add(1, f.descriptors.row(0), 0);
  const Vector2d pred = f.pixel(0) - Vector2d(10, 0);
  Eigen::Matrix2d S_u, S_v;
  S_u << 25, 0, 0, 1;  // d^2 = 100 / 25 = 4
  S_v << 1, 0, 0, 25;  // d^2 = 100
  const auto ru = track_landmarks({{1, pred, S_u}}, f, store);
  ASSERT_EQ(ru.candidates.size(), 1u);
  EXPECT_EQ(ru.candidates[0].keypoint, 0);
  EXPECT_NEAR(ru.candidates[0].d2, 4.0, 1e-3);
  EXPECT_TRUE(track_landmarks({{1, pred, S_v}}, f, store).candidates.empty());
}

TEST(Tracking, OneLandmarkPerKeypointTheCloserDescriptorWins) {
  const test::PlaneScene scene;
  const CameraView a = test::view_at({0, 0, 15});
  const Features f = FeatureExtractor().detect(scene.render(a));
  cv::Mat near = f.descriptors.row(5).clone();
  near.at<uchar>(0, 0) ^= 0x0F;  // 4 bits away
  DescriptorStore store;
  store.add(10, near, 0);
  store.add(11, f.descriptors.row(5), 0);  // exact
  const Eigen::Matrix2d S = 4 * Eigen::Matrix2d::Identity();
  const auto r = track_landmarks({{10, f.pixel(5), S}, {11, f.pixel(5), S}}, f, store);
  ASSERT_EQ(r.candidates.size(), 1u);
  EXPECT_EQ(r.candidates[0].id, 11);
  EXPECT_EQ(r.lost_conflict, 1);
}

// A track whose accepted descriptors drifted away from its anchor (a corner sliding along a
// silhouette) is lost by default; match_latest_descriptor keeps it.
TEST(Tracking, ADescriptorThatLeftItsAnchorIsNotTrackedUnlessLatestIsAllowed) {
  const test::PlaneScene scene;
  const CameraView a = test::view_at({0, 0, 15});
  const Features f = FeatureExtractor().detect(scene.render(a));
  cv::Mat anchor = f.descriptors.row(5).clone();
  for (int b = 0; b < 6; ++b) anchor.at<uchar>(0, b) ^= 0xFF;  // 48 bits from the keypoint
  DescriptorStore store;
  store.add(10, anchor, 0);
  store.observe(10, f.descriptors.row(5), 3);
  const Eigen::Matrix2d S = 4 * Eigen::Matrix2d::Identity();
  TrackingSettings cfg;
  EXPECT_DOUBLE_EQ(default_tracking_distance(f.descriptors), 38.4);
  auto r = track_landmarks({{10, f.pixel(5), S}}, f, store, cfg);
  EXPECT_TRUE(r.candidates.empty());
  EXPECT_EQ(r.too_far, 1);
  cfg.max_distance = 64;  // the old default, 0.25 of the bits: the anchor alone matches again
  r = track_landmarks({{10, f.pixel(5), S}}, f, store, cfg);
  ASSERT_EQ(r.candidates.size(), 1u);
  cfg.max_distance = 0;
  cfg.match_latest_descriptor = true;
  r = track_landmarks({{10, f.pixel(5), S}}, f, store, cfg);
  ASSERT_EQ(r.candidates.size(), 1u);
  EXPECT_EQ(r.candidates[0].keypoint, 5);
  EXPECT_EQ(r.candidates[0].distance, 0);
}

TEST(Tracking, UnknownIdsAreSkippedAndFreeKeypointsAvoidLandmarks) {
  const test::PlaneScene scene;
  const Features f = FeatureExtractor().detect(scene.render(test::view_at({0, 0, 15})));
  DescriptorStore store;
  store.add(1, f.descriptors.row(0), 0);
  const auto r = track_landmarks({{1, f.pixel(0), 4 * Eigen::Matrix2d::Identity()},
                                  {99, f.pixel(1), 4 * Eigen::Matrix2d::Identity()}},
                                 f, store);
  EXPECT_EQ(r.no_descriptor, 1);
  ASSERT_EQ(r.candidates.size(), 1u);
  const auto free = free_keypoints(f, r.keypoint_used, {{99, f.pixel(1), Eigen::Matrix2d::Identity()}}, 8.0);
  for (int k : free) {
    EXPECT_NE(k, 0);
    EXPECT_GE((f.pixel(k) - f.pixel(1)).norm(), 8.0);
  }
  int expected = 0;
  for (int k = 1; k < f.size(); ++k) expected += (f.pixel(k) - f.pixel(1)).norm() >= 8.0;
  EXPECT_EQ(static_cast<int>(free.size()), expected);
  EXPECT_THROW(free_keypoints(f, std::vector<bool>(3), {}), std::invalid_argument);
}

TEST(DescriptorStore, KeepsInitialAndLatestAndAges) {
  cv::Mat d0 = cv::Mat::zeros(1, 32, CV_8U), d1 = cv::Mat::zeros(1, 32, CV_8U), q = cv::Mat::zeros(1, 32, CV_8U);
  d1.setTo(0xFF);
  q.setTo(0xFF);
  q.at<uchar>(0, 0) = 0;
  DescriptorStore s;
  s.add(1, d0, 0);
  s.add(2, d0, 0);
  EXPECT_EQ(s.distance(1, q, cv::NORM_HAMMING), 248);
  s.observe(1, d1, 5);
  EXPECT_EQ(s.distance(1, q, cv::NORM_HAMMING), 248);  // the anchor only, unless asked
  EXPECT_EQ(s.distance(1, q, cv::NORM_HAMMING, true), 8);  // the latest is closer
  EXPECT_EQ(s.find(1)->observations, 1);
  EXPECT_LT(s.distance(7, q, cv::NORM_HAMMING), 0);
  EXPECT_EQ(s.prune(10, 6), std::vector<LandmarkId>{2});  // 1 was seen at 5, 2 only at 0
  EXPECT_TRUE(s.contains(1));
  s.remove(std::vector<LandmarkId>{1});
  EXPECT_EQ(s.size(), 0u);
  EXPECT_THROW(s.add(3, cv::Mat::zeros(2, 32, CV_8U), 0), std::invalid_argument);
}
