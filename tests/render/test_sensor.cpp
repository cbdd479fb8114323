// The sensor model against its own equations (EMVA 1288): mean and variance of the digital number
// grow with the signal as shot noise says; auto-exposure settles on its target with lag; the
// fixed pattern is fixed; vignetting follows cos^4; the ideal sensor changes nothing.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>

#include "render/sensor.hpp"

namespace wingman::render {
namespace {

const geometry::PinholeCamera kCam(200, 200, 199.5, 149.5, 400, 300);

Frame flat(int level) {
  Frame f;
  f.rgb = cv::Mat(kCam.height(), kCam.width(), CV_8UC3, cv::Scalar::all(level));
  return f;
}

sim::SensorSpec physical() {
  sim::SensorSpec s;
  s.model = sim::SensorSpec::Model::Physical;
  return s;
}

TEST(Sensor, ShotNoiseVarianceGrowsWithTheSignalAsTheModelSays) {
  sim::SensorSpec s = physical();
  s.bits = 8;
  s.gamma = 1;  // the output is the digital number itself
  s.prnu = 0, s.dsnu = 0, s.dark_current = 0;
  s.full_well = 2000;
  s.read_noise = 3;
  for (int level : {40, 90, 150, 210}) {
    SensorModel m(s, s.reference_exposure, kCam, 1, "cam");
    Frame f = flat(level);
    const Exposure e = m.apply(f);
    cv::Scalar mean, sd;
    cv::meanStdDev(f.rgb.reshape(1), mean, sd);
    const double linear = std::pow(level / 255.0, 2.2);
    const double want_mean = m.mean_dn(linear, 1, e);
    const double want_var = m.variance_dn(linear, 1, e) + 1.0 / 12;  // + quantisation
    EXPECT_NEAR(mean[0], want_mean, 0.05) << "level " << level;
    EXPECT_NEAR(sd[0] * sd[0] / want_var, 1.0, 0.03) << "level " << level << ": var " << sd[0] * sd[0]
                                                     << ", model " << want_var;
  }
}

TEST(Sensor, AutoExposureSettlesOnItsTargetWithLag) {
  sim::SensorSpec s = physical();
  s.auto_exposure.enabled = true;
  s.auto_exposure.target = 0.5;
  s.auto_exposure.rate = 0.3;
  SensorModel m(s, 0.0005, kCam, 3, "cam");  // starts far too dark
  double first = 0, last = 0, previous_error = 1;
  for (int k = 0; k < 40; ++k) {
    Frame f = flat(100);
    m.apply(f);
    cv::Mat grey;
    cv::cvtColor(f.rgb, grey, cv::COLOR_RGB2GRAY);
    const double mean = cv::mean(grey)[0] / 255;
    if (k == 0) first = mean;
    if (k < 10) {
      EXPECT_LT(std::abs(mean - 0.5), previous_error + 1e-3) << "frame " << k;  // closes in, no overshoot
      previous_error = std::abs(mean - 0.5);
    }
    last = mean;
  }
  EXPECT_LT(first, 0.3);  // lag: the first frames are still dark
  EXPECT_NEAR(last, 0.5, 0.01);
  EXPECT_GE(m.next().exposure_s, s.auto_exposure.min_exposure);
  EXPECT_LE(m.next().exposure_s, s.auto_exposure.max_exposure);
}

TEST(Sensor, AutoExposureRaisesTheGainOnlyOnceTheExposureIsAtItsMaximum) {
  sim::SensorSpec s = physical();
  s.auto_exposure.enabled = true;
  s.auto_exposure.max_exposure = 0.004;
  SensorModel m(s, 0.004, kCam, 3, "cam");
  for (int k = 0; k < 60; ++k) {
    Frame f = flat(25);  // a dark scene
    m.apply(f);
  }
  EXPECT_DOUBLE_EQ(m.next().exposure_s, 0.004);
  EXPECT_GT(m.next().gain, 2);
}

TEST(Sensor, FixedPatternRepeatsWhileTheNoiseDoesNot) {
  sim::SensorSpec s = physical();
  s.read_noise = 0, s.dark_current = 0, s.prnu = 0.05;
  s.full_well = 1e7;  // shot noise far below a grey level
  SensorModel m(s, s.reference_exposure, kCam, 5, "cam");
  Frame a = flat(180), b = flat(180);
  m.apply(a);
  m.apply(b);
  cv::Scalar mean, sd;
  cv::meanStdDev(a.rgb.reshape(1), mean, sd);
  EXPECT_GT(sd[0], 1.0);  // PRNU shows
  EXPECT_LT(cv::norm(a.rgb, b.rgb, cv::NORM_INF), 2);
  // Another camera has another pattern; the same camera and seed the same one.
  SensorModel other(s, s.reference_exposure, kCam, 5, "other"), again(s, s.reference_exposure, kCam, 5, "cam");
  Frame c = flat(180), d = flat(180);
  other.apply(c);
  again.apply(d);
  EXPECT_GT(cv::norm(a.rgb, c.rgb, cv::NORM_INF), 2);
  EXPECT_EQ(cv::norm(a.rgb, d.rgb, cv::NORM_INF), 0);
}

TEST(Sensor, VignettingDarkensTheCornersByTheCosineFourthLaw) {
  sim::SensorSpec s = physical();
  s.read_noise = 0, s.dark_current = 0, s.prnu = 0, s.dsnu = 0, s.full_well = 1e7, s.bits = 16;
  s.vignetting = 1;
  s.gamma = 1;
  SensorModel m(s, s.reference_exposure, kCam, 1, "cam");
  Frame f = flat(200);
  m.apply(f);
  const Eigen::Vector2d xn = kCam.unproject_normalised({0, 0});
  const double cos2 = 1 / (1 + xn.squaredNorm());
  const double centre = f.rgb.at<cv::Vec3b>(150, 200)[0], corner = f.rgb.at<cv::Vec3b>(0, 0)[0];
  EXPECT_NEAR(corner / centre, cos2 * cos2, 0.01);
}

TEST(Sensor, TheIdealSensorLeavesTheImageAsRendered) {
  SensorModel m(sim::SensorSpec{}, 0, kCam, 1, "cam");
  Frame f = flat(77);
  f.rgb.at<cv::Vec3b>(5, 5) = {1, 2, 3};
  const cv::Mat before = f.rgb.clone();
  const Exposure e = m.apply(f);
  EXPECT_EQ(cv::norm(f.rgb, before, cv::NORM_INF), 0);
  EXPECT_EQ(e.exposure_s, 0);
  EXPECT_EQ(e.gain, 1);
}

}  // namespace
}  // namespace wingman::render
