// Sensor effects applied to a rendered colour image after readback: exposure change (a gain,
// optionally varying per frame), Gaussian blur and Gaussian sensor noise. Seeded per camera, so
// the same scenario and seed give the same images; depth is never touched.
#pragma once

#include <cstdint>
#include <random>
#include <string>

#include "render/renderer.hpp"
#include "sim/world.hpp"

namespace wingman::render {

class ImageEffects {
 public:
  ImageEffects(const sim::ImageEffectsSpec& spec, std::uint64_t seed, const std::string& camera);
  // Whether apply() changes anything.
  bool active() const;
  void apply(Frame& f);

 private:
  sim::ImageEffectsSpec spec_;
  std::mt19937_64 rng_;
};

}  // namespace wingman::render
