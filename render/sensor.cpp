#include "render/sensor.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "render/linear_light.hpp"
#include "sim/rng.hpp"

namespace wingman::render {
namespace {

constexpr float kPoissonBelow = 30;    // e-: exact Poisson below, its normal limit above

double dn_max(const sim::SensorSpec& s) { return std::ldexp(1.0, s.bits) - 1; }

// A Poisson count of mean m (below kPoissonBelow) by inversion of its distribution at uniform u:
// about m steps of a product and a sum, where std::poisson_distribution sets up a rejection
// sampler (logarithms, lgamma) at every call.
int poisson_count(float m, double u) {
  double p = std::exp(-static_cast<double>(m)), cdf = p;
  int k = 0;
  while (u > cdf && k < 4 * static_cast<int>(kPoissonBelow)) {
    ++k;
    p *= m / k;
    cdf += p;
  }
  return k;
}

}  // namespace

SensorModel::SensorModel(const sim::SensorSpec& sensor, double exposure_s, const geometry::PinholeCamera& cam,
                         std::uint64_t seed, const std::string& camera)
    : spec_(sensor), rng_(sim::make_stream(seed, "sensor/" + camera)) {
  next_.exposure_s = spec_.initial_exposure(exposure_s);
  next_.gain = spec_.gain;
  if (!physical()) return;
  const double top = dn_max(spec_);
  to_output_.resize(static_cast<std::size_t>(top) + 1);
  for (std::size_t d = 0; d < to_output_.size(); ++d)
    to_output_[d] = cv::saturate_cast<std::uint8_t>(255 * std::pow(d / top, 1 / spec_.gamma));
  // The fixed pattern: drawn once per camera, the same in every frame.
  std::mt19937_64 fixed = sim::make_stream(seed, "sensor_pattern/" + camera);
  std::normal_distribution<double> n01(0, 1);
  pixel_gain_.create(cam.height(), cam.width(), CV_32F);
  dark_offset_.create(cam.height(), cam.width(), CV_32F);
  for (int r = 0; r < cam.height(); ++r)
    for (int c = 0; c < cam.width(); ++c) {
      const Eigen::Vector2d xn = cam.unproject_normalised(Eigen::Vector2d(c, r));
      const double cos2 = 1 / (1 + xn.squaredNorm());
      const double vignette = 1 - spec_.vignetting * (1 - cos2 * cos2);
      pixel_gain_.at<float>(r, c) = static_cast<float>(vignette * std::max(0.0, 1 + spec_.prnu * n01(fixed)));
      dark_offset_.at<float>(r, c) = static_cast<float>(spec_.dsnu * n01(fixed));
    }
}

double SensorModel::electrons(double linear, double pixel_gain, const Exposure& e) const {
  return linear * pixel_gain * spec_.full_well * (e.exposure_s / spec_.reference_exposure) +
         spec_.dark_current * e.exposure_s;
}

double SensorModel::mean_dn(double linear, double pixel_gain, const Exposure& e) const {
  return e.gain * dn_max(spec_) / spec_.full_well * electrons(linear, pixel_gain, e);
}

double SensorModel::variance_dn(double linear, double pixel_gain, const Exposure& e) const {
  const double k = e.gain * dn_max(spec_) / spec_.full_well;
  return k * k * (electrons(linear, pixel_gain, e) + spec_.read_noise * spec_.read_noise);
}

Exposure SensorModel::apply(Frame& f) {
  const Exposure used = next_;
  if (!physical()) return used;
  const auto top = static_cast<float>(dn_max(spec_)), k = static_cast<float>(used.gain * dn_max(spec_) / spec_.full_well);
  const auto ratio = static_cast<float>(spec_.full_well * used.exposure_s / spec_.reference_exposure);
  const auto dark = static_cast<float>(spec_.dark_current * used.exposure_s);
  const auto read = static_cast<float>(spec_.read_noise), read2 = read * read;
  const auto& to_linear = linear_of_8bit();
  // One normal draw a value: shot noise (the Poisson count's normal limit) and read noise are
  // independent normals, so their sum is one of variance mean + read^2.
  cv::Mat z(f.rgb.size(), CV_32FC3);
  cv::RNG(rng_()).fill(z, cv::RNG::NORMAL, 0, 1);
  std::vector<float> mean(static_cast<std::size_t>(f.rgb.cols) * 3), e(mean.size());
  for (int r = 0; r < f.rgb.rows; ++r) {
    auto* px = f.rgb.ptr<std::uint8_t>(r);
    const auto* zr = z.ptr<float>(r);
    const auto* g = pixel_gain_.ptr<float>(r);
    const auto* d = dark_offset_.ptr<float>(r);
    const int n = f.rgb.cols * 3;
    for (int c = 0; c < f.rgb.cols; ++c)
      for (int ch = 0; ch < 3; ++ch) mean[3 * c + ch] = to_linear[px[3 * c + ch]] * (g[c] * ratio) + (dark + d[c]);
    for (int i = 0; i < n; ++i) {  // vectorised: no branch, no call
      const float m = std::max(0.f, mean[i]);
      mean[i] = m;
      e[i] = m + std::sqrt(m + read2) * zr[i];
    }
    // Few electrons: the exact Poisson count, drawn in the values' order.
    for (int i = 0; i < n; ++i)
      if (mean[i] < kPoissonBelow)
        e[i] = static_cast<float>(poisson_count(mean[i], static_cast<double>(rng_() >> 11) * 0x1p-53)) + read * zr[i];
    for (int i = 0; i < n; ++i) {
      const float dn = std::clamp(e[i] * k + 0.5f, 0.f, top);  // truncated: rounded, never negative
      px[i] = to_output_[static_cast<std::size_t>(dn)];
    }
  }
  update_auto_exposure(f.rgb);
  return used;
}

void SensorModel::update_auto_exposure(const cv::Mat& rgb) {
  const auto& ae = spec_.auto_exposure;
  if (!ae.enabled) return;
  cv::Mat grey;
  cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
  const double m = std::max(1e-3, cv::mean(grey)[0] / 255.0);
  // The output's grey is signal^(1/gamma): the signal must change by (target/m)^gamma.
  const double total = next_.exposure_s * next_.gain * std::pow(ae.target / m, spec_.gamma * ae.rate);
  next_.exposure_s = std::clamp(total / spec_.gain, ae.min_exposure, ae.max_exposure);
  next_.gain = std::clamp(total / next_.exposure_s, spec_.gain, ae.max_gain);
}

}  // namespace wingman::render
