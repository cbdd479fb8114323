#include "render/haze.hpp"

#include <cmath>

#include "render/linear_light.hpp"

namespace wingman::render {

Haze::Haze(const geometry::PinholeCamera& cam, double visibility_m, const Eigen::Vector3d& airlight_rgb)
    : beta_(3.912 / visibility_m), airlight_(airlight_rgb.array().pow(kRenderedGamma)) {
  ray_length_.create(cam.height(), cam.width(), CV_32F);
  for (int r = 0; r < cam.height(); ++r)
    for (int c = 0; c < cam.width(); ++c)
      ray_length_.at<float>(r, c) =
          static_cast<float>(std::sqrt(1 + cam.unproject_normalised(Eigen::Vector2d(c, r)).squaredNorm()));
}

double Haze::transmission(double range_m) const { return std::exp(-beta_ * range_m); }

void Haze::apply(Frame& f) const {
  const auto& to_linear = linear_of_8bit();
  for (int r = 0; r < f.rgb.rows; ++r) {
    auto* px = f.rgb.ptr<cv::Vec3b>(r);
    const auto* z = f.depth.ptr<float>(r);
    const auto* k = ray_length_.ptr<float>(r);
    for (int c = 0; c < f.rgb.cols; ++c) {
      if (!(z[c] > 0)) continue;  // the sky
      const double t = transmission(z[c] * k[c]);
      for (int ch = 0; ch < 3; ++ch) {
        const double lin = to_linear[px[c][ch]] * t + airlight_[ch] * (1 - t);
        px[c][ch] = encode_linear(lin);
      }
    }
  }
}

}  // namespace wingman::render
