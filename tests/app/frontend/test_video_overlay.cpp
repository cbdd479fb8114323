// --video's frames: the cameras side by side at half size, each labelled with its UAV, the time and
// the phase, and under them a legend showing every mark in the colour the tiles use.
#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/core.hpp>

#include "app/frontend/video_overlay.hpp"
#include "app/app_test_support.hpp"

namespace wingman::app::test {
namespace {

// Pixels of `img` within 40 of the BGR colour, summed over every channel's distance.
int count_near(const cv::Mat& img, const cv::Vec3b& bgr) {
  int n = 0;
  for (int r = 0; r < img.rows; ++r)
    for (int c = 0; c < img.cols; ++c) {
      const cv::Vec3b p = img.at<cv::Vec3b>(r, c);
      if (std::abs(p[0] - bgr[0]) + std::abs(p[1] - bgr[1]) + std::abs(p[2] - bgr[2]) < 40) ++n;
    }
  return n;
}

TEST(VideoOverlay, TilesSitAboveALegendOfEveryMark) {
  TempDir tmp;
  // Two cameras 400 px wide: the video is as wide as one paper camera at half size (500 px).
  const geometry::PinholeCamera cam(100, 100, 200, 150, 400, 300);
  VideoOverlay video((tmp / "v.avi").string(), {cam, cam}, {"uav1", "uav2"}, 10);
  EXPECT_EQ(video.size(), cv::Size(400, 150 + kLegendHeight));

  render::Frame grey{cv::Mat(300, 400, CV_8UC3, cv::Scalar(90, 90, 90)), cv::Mat()};
  const VisionFrontend::Marks none;
  const cv::Mat out = video.compose({{&grey, &none, std::nullopt}, {&grey, &none, std::nullopt}}, 12.34, "config2");
  ASSERT_EQ(out.size(), video.size());
  const cv::Mat legend = out.rowRange(150, out.rows);
  EXPECT_GT(count_near(legend, {0, 0, 255}), 5);      // tracked (red)
  EXPECT_GT(count_near(legend, {0, 200, 0}), 5);      // accepted (green)
  EXPECT_GT(count_near(legend, {0, 230, 255}), 5);    // new landmark (yellow)
  EXPECT_GT(count_near(legend, {255, 0, 255}), 5);    // lead detection (magenta)
  int bright = 0;  // the words: white, anti-aliased
  for (int r = 0; r < legend.rows; ++r)
    for (int c = 0; c < legend.cols; ++c) {
      const cv::Vec3b p = legend.at<cv::Vec3b>(r, c);
      bright += std::min({p[0], p[1], p[2]}) > 150;
    }
  EXPECT_GT(bright, 150);
  // No marks on the tiles: none of the marks' colours there.
  EXPECT_EQ(count_near(out.rowRange(0, 150), {255, 0, 255}), 0);

  EXPECT_EQ(overlay_label("uav2", 12.34, "config2"), "uav2  t = 12.3 s  config2");
  EXPECT_EQ(overlay_label("uav1", 0, ""), "uav1  t = 0.0 s");
  video.write({{&grey, &none, Eigen::Vector2d(200, 150)}, {&grey, &none, std::nullopt}}, 0.1, "config1");
}

}  // namespace
}  // namespace wingman::app::test
