// The image sensor of sim::SensorSpec: rendered radiance to the digital image a real camera
// writes, with its noise (shot, read, dark, fixed pattern), quantisation, response curve and
// vignetting, and auto-exposure that drives the next frame's exposure and gain toward a target
// brightness. Seeded per camera: the fixed pattern is drawn once, the noise per frame, so the
// same scenario and seed give the same images.
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "geometry/camera.hpp"
#include "render/renderer.hpp"
#include "sim/camera_sensor.hpp"

namespace wingman::render {

// What a frame was taken with.
struct Exposure {
  double exposure_s = 0;
  double gain = 1;
};

class SensorModel {
 public:
  // exposure_s: the shutter's (sim::SensorSpec::initial_exposure).
  SensorModel(const sim::SensorSpec& sensor, double exposure_s, const geometry::PinholeCamera& cam,
              std::uint64_t seed, const std::string& camera);
  bool physical() const { return spec_.physical(); }
  // The exposure and gain the next frame is taken with.
  const Exposure& next() const { return next_; }
  // Turns the shutter's image (f.rgb) into the sensor's, taken with next(); returns next() and
  // moves auto-exposure on. The ideal sensor returns the image as it is.
  Exposure apply(Frame& f);

  // Expected digital number (0 .. 2^bits - 1) and its variance for a pixel of linear radiance
  // `linear` (0-1, rendered white is 1) at relative gain `pixel_gain` (vignetting times PRNU),
  // before quantisation: the model the noise is drawn from (EMVA 1288, eq. 7 and 9).
  double mean_dn(double linear, double pixel_gain, const Exposure& e) const;
  double variance_dn(double linear, double pixel_gain, const Exposure& e) const;

 private:
  double electrons(double linear, double pixel_gain, const Exposure& e) const;
  void update_auto_exposure(const cv::Mat& rgb);

  sim::SensorSpec spec_;
  Exposure next_;
  cv::Mat pixel_gain_;    // CV_32F: vignetting times (1 + PRNU)
  cv::Mat dark_offset_;   // CV_32F, e-: DSNU
  std::vector<std::uint8_t> to_output_;  // the response curve: 8-bit output of each digital number
  std::mt19937_64 rng_;
};

}  // namespace wingman::render
