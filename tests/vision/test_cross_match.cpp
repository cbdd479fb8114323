// Cross-UAV matching: pixel-pair geometry (epipolar distance, triangulation) with distortion, and
// matching two synthetic aerial views whose triangulated points must lie on the ground plane.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

#include "vision/cross_match.hpp"
#include "vision/features.hpp"
#include "vision/labelling.hpp"
#include "vision_test_support.hpp"

using namespace wingman::vision;
using Eigen::Vector2d;
using Eigen::Vector3d;

TEST(CrossMatch, PairGeometryIsExactForTrueCorrespondencesWithDistortion) {
  CameraView a = test::view_at({-1.5, 0, 15}, 0.0, 0.02), b = test::view_at({1.5, 0.3, 17}, 0.3, -0.03);
  a.camera = wingman::geometry::PinholeCamera(300, 300, 319.5, 239.5, 640, 480, {-0.12, 0.03, 0.001, -0.001, 0});
  b.camera = wingman::geometry::PinholeCamera(310, 305, 322, 236, 640, 480, {0.05, -0.01, 0, 0.002, 0});
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> xy(-6, 6), z(-1, 2);
  for (int i = 0; i < 50; ++i) {
    const Vector3d p(xy(rng), xy(rng), z(rng));
    const Vector2d ua = *a.camera.project(a.pose.to_camera(p)), ub = *b.camera.project(b.pose.to_camera(p));
    const PairGeometry g = evaluate_pair(ua, a, ub, b);
    EXPECT_LT(g.epipolar_px, 1e-6);
    ASSERT_TRUE(g.triangulated);
    EXPECT_LT((g.point_W - p).norm(), 1e-6);
    EXPECT_LT(g.reprojection_px, 1e-6);
    EXPECT_NEAR(g.depth_a, a.pose.to_camera(p).z(), 1e-6);
    EXPECT_GT(g.parallax_rad, 0.1);
    EXPECT_EQ(check_pair(g, {}), PairVerdict::Accepted);
    // 8 px off along the normal of the epipolar line in b: rejected by the epipolar test.
    const double eps = 1e-3;
    const Vector2d along = (*b.camera.project(b.pose.to_camera(p + eps * (p - a.pose.position))) - ub).normalized();
    const Vector2d off = ub + 8.0 * Vector2d(-along.y(), along.x());
    const PairGeometry w = evaluate_pair(ua, a, off, b);
    EXPECT_GT(w.epipolar_px, 6.0);
    EXPECT_EQ(check_pair(w, {}), PairVerdict::Epipolar);
  }
}

TEST(CrossMatch, BadSettingsThrowNamingTheValue) {
  CrossMatchSettings s;
  s.max_epipolar_px = -1;
  try {
    s.validate();
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_epipolar_px"), std::string::npos);
  }
}

namespace {
struct TwoViews {
  test::PlaneScene scene;
  CameraView a = test::view_at({-1.5, 0, 15}), b = test::view_at({1.5, 0.5, 17}, 0.2, 0.02);
  Features fa, fb;
  TwoViews() {
    FeatureSettings s;
    s.max_features = 1000;
    const FeatureExtractor fx(s);
    fa = fx.detect(scene.render(a));
    fb = fx.detect(scene.render(b));
  }
};
}  // namespace

TEST(CrossMatch, MatchesOfTwoViewsTriangulateOntoTheGroundPlane) {
  const TwoViews v;
  const CrossMatchResult r = match_across(v.fa, all_keypoints(v.fa), v.a, v.fb, all_keypoints(v.fb), v.b);
  ASSERT_GE(r.matches.size(), 80u) << "descriptor matches " << r.descriptor_matches;
  // Depth precision with a 3 m baseline at 15-17 m and f = 300 px is Z^2 / (f B) ~ 0.28 m per
  // pixel of disparity error: the median point lies within 0.25 m of the plane, 90 % within 0.6 m.
  std::vector<double> dz;
  int inliers = 0;
  const cv::Mat da = v.scene.depth(v.a), db = v.scene.depth(v.b);
  for (const auto& m : r.matches) {
    dz.push_back(std::abs(m.geometry.point_W.z()));
    EXPECT_LE(m.geometry.epipolar_px, 5.0);
    EXPECT_LE(m.geometry.reprojection_px, 5.0);
    inliers += label_pixel_pair(m.uv_a, v.a.camera, v.a.pose, da, m.uv_b, v.b.camera, v.b.pose, db).label ==
               Label::Inlier;
  }
  std::sort(dz.begin(), dz.end());
  EXPECT_LT(dz[dz.size() / 2], 0.25);
  EXPECT_LT(dz[dz.size() * 9 / 10], 0.6);
  EXPECT_GE(inliers, 0.95 * r.matches.size()) << inliers << " of " << r.matches.size();
  // Sorted by descriptor distance.
  for (std::size_t i = 1; i < r.matches.size(); ++i) EXPECT_LE(r.matches[i - 1].distance, r.matches[i].distance);

  // Injected wrong pairs (each a-pixel with another match's b-pixel): the epipolar and
  // triangulation checks reject nearly all; the few kept lie close to the true epipolar line.
  int rejected = 0;
  const int n = static_cast<int>(r.matches.size());
  for (int i = 0; i < n; ++i) {
    const auto& ma = r.matches[i];
    const auto& mb = r.matches[(i + n / 2) % n];
    rejected += check_pair(evaluate_pair(ma.uv_a, v.a, mb.uv_b, v.b), {}) != PairVerdict::Accepted;
  }
  EXPECT_GE(rejected, 0.9 * n) << rejected << " of " << n;
}

TEST(CrossMatch, StillMatchesWithEstimatedPosesAndHonoursTheFreeLists) {
  const TwoViews v;
  CameraView a = v.a, b = v.b;
  a.pose.position += Vector3d(0.15, -0.1, 0.1);  // pose estimates a filter would give
  b.pose.position += Vector3d(-0.1, 0.15, -0.1);
  std::vector<int> free_a, free_b;
  for (int i = 0; i < v.fa.size(); i += 2) free_a.push_back(i);
  for (int i = 0; i < v.fb.size(); ++i) free_b.push_back(i);
  const CrossMatchResult r = match_across(v.fa, free_a, a, v.fb, free_b, b);
  EXPECT_GE(r.matches.size(), 30u);
  for (const auto& m : r.matches) EXPECT_EQ(m.keypoint_a % 2, 0);
  EXPECT_TRUE(match_across(v.fa, {}, a, v.fb, free_b, b).matches.empty());  // nothing free in a
  EXPECT_THROW(match_across(v.fa, {v.fa.size()}, a, v.fb, free_b, b), std::invalid_argument);
  // The wrong baseline scales the triangulated depth, so check the pixels against the truth.
  const cv::Mat da = v.scene.depth(v.a), db = v.scene.depth(v.b);
  int inliers = 0;
  for (const auto& m : r.matches)
    inliers += label_pixel_pair(m.uv_a, v.a.camera, v.a.pose, da, m.uv_b, v.b.camera, v.b.pose, db).label ==
               Label::Inlier;
  EXPECT_GE(inliers, 0.95 * r.matches.size()) << inliers << " of " << r.matches.size();
}

TEST(CrossMatch, ACameraWithoutFeaturesMatchesNothingAndOtherKindsStillThrow) {
  // A featureless view (a closed-loop UAV low over blurred ground) detects nothing: its empty
  // descriptor matrix keeps the detector's type and width, so it is not read as another kind.
  const TwoViews v;
  const cv::Mat blank(480, 640, CV_8UC3, cv::Scalar(128, 128, 128));
  const Features none = FeatureExtractor().detect(blank);
  ASSERT_EQ(none.size(), 0);
  EXPECT_EQ(none.descriptors.type(), v.fb.descriptors.type());  // typed although empty
  EXPECT_EQ(none.descriptors.cols, v.fb.descriptors.cols);
  EXPECT_TRUE(match_across(none, all_keypoints(none), v.a, v.fb, all_keypoints(v.fb), v.b).matches.empty());
  EXPECT_TRUE(match_across(v.fa, all_keypoints(v.fa), v.a, none, all_keypoints(none), v.b).matches.empty());
  FeatureSettings sift;
  sift.kind = DetectorKind::Sift;
  const Features fs = FeatureExtractor(sift).detect(v.scene.render(v.b));
  EXPECT_THROW(match_across(v.fa, all_keypoints(v.fa), v.a, fs, all_keypoints(fs), v.b), std::invalid_argument);
}

TEST(CrossMatch, SelectSpreadFillsEmptyCellsFirstAndKeepsDistance) {
  std::vector<CrossMatchCandidate> ms;
  auto add = [&](double u, double v) {
    CrossMatchCandidate c;
    c.uv_a = c.uv_b = Vector2d(u, v);
    ms.push_back(c);
  };
  for (int i = 0; i < 10; ++i) add(50 + 30 * i, 50);  // top-left quadrant... and top-right
  add(100, 400);                                       // bottom-left
  add(500, 400);                                       // bottom-right
  add(505, 405);                                       // too close to the previous one
  const auto cam = test::test_camera();                // 640 x 480, 2 x 2 grid: 320 x 240 cells
  SpreadSettings s;
  s.grid_cols = s.grid_rows = 2;
  s.min_separation_px = 20;
  const auto pick = select_spread(ms, 4, cam, {}, cam, {}, s);
  ASSERT_EQ(pick.size(), 4u);
  std::set<int> cells;
  for (const auto& c : pick) cells.insert(int(c.uv_a.y() >= 240) * 2 + int(c.uv_a.x() >= 320));
  EXPECT_EQ(cells.size(), 4u);
  // Existing landmarks fill the top-left cell: a new one goes elsewhere first.
  const auto pick2 = select_spread(ms, 1, cam, {{60, 60}, {200, 100}}, cam, {{60, 60}, {200, 100}}, s);
  ASSERT_EQ(pick2.size(), 1u);
  EXPECT_FALSE(pick2[0].uv_a.x() < 320 && pick2[0].uv_a.y() < 240);
  // Never two within min_separation_px, even when more are needed than fit.
  const auto all = select_spread(ms, 100, cam, {}, cam, {}, s);
  EXPECT_EQ(all.size(), ms.size() - 1);
  EXPECT_EQ(landmarks_needed(20, 14), 6);
  EXPECT_EQ(landmarks_needed(20, 25), 0);
}
