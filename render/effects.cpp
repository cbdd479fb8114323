#include "render/effects.hpp"

#include <opencv2/imgproc.hpp>

#include "sim/rng.hpp"

namespace wingman::render {

ImageEffects::ImageEffects(const sim::ImageEffectsSpec& spec, std::uint64_t seed,
                           const std::string& camera)
    : spec_(spec), rng_(sim::make_stream(seed, "image_effects/" + camera)) {}

bool ImageEffects::active() const {
  return spec_.exposure_gain != 1 || spec_.exposure_variation > 0 || spec_.blur_sigma > 0 ||
         spec_.noise_sigma > 0;
}

void ImageEffects::apply(Frame& f) {
  if (!active()) return;
  double gain = spec_.exposure_gain;
  if (spec_.exposure_variation > 0)
    gain *= std::max(0.0, 1 + std::normal_distribution<double>(0, spec_.exposure_variation)(rng_));
  cv::Mat img;
  f.rgb.convertTo(img, CV_32FC3, gain);
  if (spec_.blur_sigma > 0) cv::GaussianBlur(img, img, cv::Size(0, 0), spec_.blur_sigma);
  if (spec_.noise_sigma > 0) {
    cv::Mat noise(img.size(), img.type());
    cv::RNG cvrng(rng_());
    cvrng.fill(noise, cv::RNG::NORMAL, 0, spec_.noise_sigma);
    img += noise;
  }
  img.convertTo(f.rgb, CV_8UC3);  // saturates
}

}  // namespace wingman::render
