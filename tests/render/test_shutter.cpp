// The shutter's composition against analytic answers, with a band renderer that draws a known
// pattern at each instant (no GL): an edge moving at constant speed blurs into the integral of its
// coverage over the exposure; under a rolling shutter every row is drawn at its own time; depth is
// the mid-exposure instant's.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "render/shutter.hpp"

namespace wingman::render {
namespace {

// The coverage of pixel column c (its centre at c, spanning c +- 0.5) by the white half x < edge.
double coverage(double edge, int c) { return std::clamp(edge - (c - 0.5), 0.0, 1.0); }

// The mean over an exposure of coverage as the edge runs from e0 to e1 (the integral of a clamped
// ramp: F(s) = 0, s^2 / 2, s - 1/2 below 0, on [0, 1], above 1).
double blurred(double e0, double e1, int c) {
  auto F = [](double s) { return s <= 0 ? 0.0 : s <= 1 ? s * s / 2 : s - 0.5; };
  const double s0 = e0 - (c - 0.5), s1 = e1 - (c - 0.5);
  return (F(s1) - F(s0)) / (s1 - s0);
}

std::uint8_t encode(double linear) { return cv::saturate_cast<std::uint8_t>(255 * std::pow(linear, 1 / 2.2)); }

// An edge at x = x0 + v t over rows [row0, row0 + rows), antialiased in linear light.
BandRenderer moving_edge(double x0, double v, int width, std::vector<double>* times = nullptr) {
  return [=](double dt, int, int rows) {
    if (times) times->push_back(dt);
    Frame f;
    f.rgb.create(rows, width, CV_8UC3);
    f.depth = cv::Mat(rows, width, CV_32F, cv::Scalar(static_cast<float>(10 + dt)));
    for (int c = 0; c < width; ++c) {
      const std::uint8_t g = encode(coverage(x0 + v * dt, c));
      for (int r = 0; r < rows; ++r) f.rgb.at<cv::Vec3b>(r, c) = {g, g, g};
    }
    return f;
  };
}

TEST(Shutter, MotionBlurOfAMovingEdgeIsItsCoverageIntegratedOverTheExposure) {
  sim::ShutterSpec s;
  s.exposure = 0.01;
  s.subframes = 255;
  const double x0 = 40.3, v = 2000;  // px/s: a 20 px smear
  const Frame f = expose(s, s.exposure, 80, 4, moving_edge(x0, v, 80));
  int smeared = 0;
  for (int c = 0; c < 80; ++c) {
    const double want = blurred(x0 - v * s.exposure / 2, x0 + v * s.exposure / 2, c);
    const double got = std::pow(f.rgb.at<cv::Vec3b>(2, c)[0] / 255.0, 2.2);
    EXPECT_NEAR(got, want, 0.006) << "column " << c;
    smeared += want > 0.02 && want < 0.98;
  }
  EXPECT_GE(smeared, 19);  // the ramp spans the 20 px the edge travels
  EXPECT_LE(smeared, 21);
}

TEST(Shutter, NoExposureIsOneRenderOfTheWholeFrameAtTheFramesTime) {
  sim::ShutterSpec s;
  std::vector<double> times;
  const Frame f = expose(s, 0, 30, 5, moving_edge(10, 1000, 30, &times));
  ASSERT_EQ(times.size(), 1u);
  EXPECT_EQ(times[0], 0);
  EXPECT_EQ(f.rgb.rows, 5);
}

TEST(Shutter, RollingShutterDrawsEachRowAtItsOwnTimeAroundTheMiddleRow) {
  sim::ShutterSpec s;
  s.type = sim::ShutterSpec::Type::Rolling;
  s.line_delay = 1e-4;
  s.rows_per_band = 1;
  std::vector<double> times;
  const int h = 9;
  const Frame f = expose(s, 0, 50, h, moving_edge(20, 5000, 50, &times));
  ASSERT_EQ(times.size(), static_cast<std::size_t>(h));
  for (int r = 0; r < h; ++r) {
    EXPECT_NEAR(times[r], (r - 4) * 1e-4, 1e-15);
    // Row r's edge sits where the edge was at its time: 0.5 px further per row.
    double sum = 0;
    for (int c = 0; c < 50; ++c) sum += std::pow(f.rgb.at<cv::Vec3b>(r, c)[0] / 255.0, 2.2);
    EXPECT_NEAR(sum, 20 + 5000 * times[r] + 0.5, 0.02) << "row " << r;
  }
  s.readout = sim::ShutterSpec::Readout::BottomToTop;
  EXPECT_NEAR(row_time(s, 0, h), 4e-4, 1e-15);
  EXPECT_NEAR(row_time(s, 8, h), -4e-4, 1e-15);
}

TEST(Shutter, BandsShareOneTimeAndDepthIsTheMidExposureInstants) {
  sim::ShutterSpec s;
  s.type = sim::ShutterSpec::Type::Rolling;
  s.line_delay = 1e-4;
  s.rows_per_band = 4;
  s.exposure = 0.002;
  s.subframes = 3;
  std::vector<double> times;
  const Frame f = expose(s, s.exposure, 10, 10, moving_edge(5, 100, 10, &times));
  // Bands of rows 0-3, 4-7, 8-9; three instants each, the middle instant's bands drawn first.
  ASSERT_EQ(times.size(), 9u);
  EXPECT_NEAR(times[0], row_time(s, 1.5, 10), 1e-15);  // the first band's middle instant
  EXPECT_NEAR(times[3], row_time(s, 1.5, 10) - s.exposure / 3, 1e-15);
  EXPECT_NEAR(times[2], row_time(s, 8.5, 10), 1e-15);
  EXPECT_NEAR(f.depth.at<float>(0, 0), 10 + row_time(s, 1.5, 10), 1e-5);
  EXPECT_NEAR(f.depth.at<float>(9, 0), 10 + row_time(s, 8.5, 10), 1e-5);
}

TEST(Shutter, ImagesFollowThePredictedImageMotion) {
  sim::ShutterSpec s;
  s.subframes = 9;
  s.subframe_motion_px = 0.5;
  EXPECT_EQ(subframes_for(s, 0), 1);
  EXPECT_EQ(subframes_for(s, 0.24), 1);   // under half a step: one image
  EXPECT_EQ(subframes_for(s, 0.3), 1);    // one step
  EXPECT_EQ(subframes_for(s, 0.9), 3);    // two steps, made odd
  EXPECT_EQ(subframes_for(s, 2.4), 5);
  EXPECT_EQ(subframes_for(s, 40), 9);     // at most `subframes`
  s.subframe_motion_px = 0;
  EXPECT_EQ(subframes_for(s, 0), 9);      // 0: always `subframes`
}

// Adaptive blur against a fixed 9-image reference: an edge smearing 3 px takes 7 images, within
// 0.01 of the reference in linear light and 4 grey levels (the 9-image frame itself is within
// 0.006 in linear light of the exact integral; test above).
TEST(Shutter, AdaptiveImagesMatchANineImageReferenceWithinFourGreyLevels) {
  sim::ShutterSpec s;
  s.exposure = 0.01;
  s.subframes = 9;
  const BandRenderer edge = moving_edge(40.3, 300, 80);  // 3 px over the exposure
  const Frame reference = expose(s, s.exposure, 80, 4, edge);
  int drawn = 0;
  const Frame adaptive = expose(
      s.exposure,
      [&](double dt) {
        ++drawn;
        return edge(dt, 0, 4);
      },
      [&](const Frame&) { return subframes_for(s, 3.0); });
  EXPECT_EQ(drawn, 7);
  // 7 steps of 0.43 px against 9 of 0.33 px: the staircases differ by under 1 % in linear light,
  // which the gamma turns into up to 4 grey levels in the darkest pixels of the ramp.
  double worst_linear = 0;
  for (int c = 0; c < 80; ++c)
    worst_linear = std::max(worst_linear, std::abs(std::pow(adaptive.rgb.at<cv::Vec3b>(2, c)[0] / 255.0, 2.2) -
                                                   std::pow(reference.rgb.at<cv::Vec3b>(2, c)[0] / 255.0, 2.2)));
  EXPECT_LT(worst_linear, 0.01);
  EXPECT_LE(cv::norm(adaptive.rgb, reference.rgb, cv::NORM_INF), 4);
  EXPECT_GT(cv::norm(adaptive.rgb, expose(0, [&](double dt) { return edge(dt, 0, 4); }, nullptr).rgb, cv::NORM_INF),
            40);  // the blur is there
}

}  // namespace
}  // namespace wingman::render
