// Atmospheric haze over distance (world.light.haze_visibility): each pixel's radiance is
// attenuated by exp(-beta r) over its range r and the airlight (the sky's colour) fills in the rest,
// beta = 3.912 / visibility (Koschmieder: 2 % contrast left at the visibility). Exact per pixel
// from the rendered metric depth; applied in linear light, before the sensor; sky pixels keep the
// sky's colour.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "geometry/camera.hpp"
#include "render/renderer.hpp"

namespace wingman::render {

class Haze {
 public:
  Haze(const geometry::PinholeCamera& cam, double visibility_m, const Eigen::Vector3d& airlight_rgb);
  void apply(Frame& f) const;
  // The fraction of a surface's radiance that reaches the camera from range r.
  double transmission(double range_m) const;

 private:
  cv::Mat ray_length_;  // CV_32F: range over depth, per pixel
  double beta_;
  Eigen::Vector3d airlight_;  // linear RGB
};

}  // namespace wingman::render
