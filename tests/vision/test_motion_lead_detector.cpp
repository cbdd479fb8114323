// The motion detector finds what keeps its place while a textured ground slides under the camera,
// at the centroid of its moving pixels; a ground that does not move (a hovering team) gives no
// background and no detection; a ground that turns is followed by its homography; bad settings
// are refused by name.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>
#include <string>

#include "vision/motion_lead_detector.hpp"

namespace wingman::vision {
namespace {

// A ground of blurred noise, larger than a frame.
cv::Mat ground(int seed) {
  cv::Mat g(900, 1100, CV_8U);
  cv::RNG rng(seed);
  rng.fill(g, cv::RNG::UNIFORM, 40, 200);
  cv::GaussianBlur(g, g, cv::Size(0, 0), 2.0);
  return g;
}

// Frame k: the ground moved by k `step` (and turned by k `turn_deg` about the frame's centre), with
// a bright disc of radius 12 px at `lead` that moves with the camera.
cv::Mat frame(const cv::Mat& g, int k, const cv::Point2d& step, double turn_deg, const cv::Point2d& lead) {
  cv::Mat A = cv::getRotationMatrix2D({320, 240}, k * turn_deg, 1.0);
  A.at<double>(0, 2) += 200 - k * step.x;
  A.at<double>(1, 2) += 200 - k * step.y;
  cv::Mat out;
  cv::warpAffine(g, out, A, {640, 480}, cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REFLECT);
  cv::circle(out, lead, 12, cv::Scalar(250), cv::FILLED, cv::LINE_AA);
  return out;
}

TEST(MotionLeadDetector, FindsTheDiscThatKeepsItsPlaceWithin1PxOnceTheGroundHasMoved) {
  const cv::Mat g = ground(1);
  MotionLeadDetector det;
  const cv::Point2d lead(300.0, 200.0);
  int found = 0;
  for (int k = 0; k < 45; ++k) {
    const auto d = det.detect(frame(g, k, {6, 3}, 0, lead), Eigen::Vector2d(305, 196));
    // 5 references 24 px apart need 120 px of ground: 18 frames at 6.7 px a frame.
    if (k < 18) {
      EXPECT_FALSE(d) << "frame " << k;
      continue;
    }
    ASSERT_TRUE(d) << "frame " << k;
    EXPECT_NEAR(d->uv.x(), lead.x, 1.0) << "frame " << k;
    EXPECT_NEAR(d->uv.y(), lead.y, 1.0) << "frame " << k;
    EXPECT_EQ(d->source, LeadSource::Motion);
    EXPECT_NEAR(d->size_px, std::sqrt(CV_PI * 12 * 12), 4.0);
    ++found;
  }
  EXPECT_EQ(found, 27);
}

TEST(MotionLeadDetector, FollowsAGroundThatTurnsAsItMoves) {
  const cv::Mat g = ground(2);
  MotionLeadDetector det;
  const cv::Point2d lead(420.0, 260.0);
  std::optional<LeadDetection> last;
  for (int k = 0; k < 40; ++k) last = det.detect(frame(g, k, {5, -4}, 0.8, lead));
  ASSERT_TRUE(last);
  EXPECT_NEAR(last->uv.x(), lead.x, 1.0);
  EXPECT_NEAR(last->uv.y(), lead.y, 1.0);
}

TEST(MotionLeadDetector, AHoveringTeamGivesNoDetection) {
  const cv::Mat g = ground(3);
  MotionLeadDetector det;
  for (int k = 0; k < 30; ++k) EXPECT_FALSE(det.detect(frame(g, 0, {0, 0}, 0, {300, 200}))) << "frame " << k;
}

TEST(MotionLeadDetector, ABlobFartherThanTheWindowFromThePredictionIsNotTheLead) {
  const cv::Mat g = ground(4);
  MotionLeadDetector a, b;  // the same frames, two predictions
  std::optional<LeadDetection> near, far;
  for (int k = 0; k < 30; ++k) {
    const cv::Mat f = frame(g, k, {6, 3}, 0, {300, 200});
    near = a.detect(f, Eigen::Vector2d(330, 220));
    far = b.detect(f, Eigen::Vector2d(500, 400));
  }
  ASSERT_TRUE(near);
  EXPECT_FALSE(far);
}

TEST(MotionLeadDetector, SettingsOutOfRangeAreRefusedByName) {
  auto message = [](MotionLeadSettings s) {
    try {
      MotionLeadDetector d(s);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  MotionLeadSettings s;
  s.references = 2;
  EXPECT_NE(message(s).find("references"), std::string::npos);
  s = {};
  s.history = 4;
  EXPECT_NE(message(s).find("history must be >= references"), std::string::npos);
  s = {};
  s.threshold = 0;
  EXPECT_NE(message(s).find("threshold"), std::string::npos);
  EXPECT_EQ(message({}), "accepted");
}

}  // namespace
}  // namespace wingman::vision
