// Haze over distance against Koschmieder's law: 2 % of a surface's radiance is left at the
// visibility, the airlight fills in the rest, range (not depth) decides it, the sky is untouched.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "render/haze.hpp"
#include "render/linear_light.hpp"

namespace wingman::render {
namespace {

TEST(Haze, SurfacesFadeIntoTheAirlightWithRangeAsKoschmiederSays) {
  const geometry::PinholeCamera cam(100, 100, 49.5, 49.5, 100, 100);
  const Eigen::Vector3d sky(0.62, 0.74, 0.88);
  const Haze haze(cam, 1000, sky);
  EXPECT_NEAR(haze.transmission(1000), 0.02, 1e-3);
  Frame f;
  f.rgb = cv::Mat(100, 100, CV_8UC3, cv::Scalar::all(200));
  f.depth = cv::Mat(100, 100, CV_32F, cv::Scalar(500.0f));
  f.depth.at<float>(10, 10) = 0;  // sky
  haze.apply(f);
  auto expect = [&](double range, int ch) {
    const double t = std::exp(-3.912 * range / 1000);
    return 255 * std::pow(std::pow(200 / 255.0, 2.2) * t + std::pow(sky[ch], 2.2) * (1 - t), 1 / 2.2);
  };
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(f.rgb.at<cv::Vec3b>(50, 50)[ch], expect(500 * std::sqrt(1 + 2 * 0.005 * 0.005), ch), 0.6);
  // A corner pixel's ray is longer than its depth: 500 m deep is sqrt(1 + 0.495^2 * 2) * 500 m away.
  const double corner = 500 * std::sqrt(1 + 2 * 0.495 * 0.495);
  EXPECT_NEAR(f.rgb.at<cv::Vec3b>(0, 0)[2], expect(corner, 2), 0.6);
  EXPECT_NE(f.rgb.at<cv::Vec3b>(0, 0)[2], f.rgb.at<cv::Vec3b>(50, 50)[2]);
  EXPECT_EQ(f.rgb.at<cv::Vec3b>(10, 10), cv::Vec3b(200, 200, 200));
}

TEST(LinearLight, EncodingByItsStepsIsTheGammaCurveRounded) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-0.1, 1.1);
  for (int i = 0; i < 200000; ++i) {
    const double lin = u(rng);
    ASSERT_EQ(encode_linear(lin), cv::saturate_cast<std::uint8_t>(255 * std::pow(std::max(lin, 0.0), 1 / kRenderedGamma)))
        << lin;
  }
  for (int v = 0; v < 256; ++v) EXPECT_EQ(encode_linear(linear_of_8bit()[v]), v);
}

}  // namespace
}  // namespace wingman::render
