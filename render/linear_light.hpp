// How the renderer's 8-bit colour encodes radiance: a gamma of 2.2. The shutter, the haze and the
// sensor work in linear light and go through this one table.
#pragma once

#include <array>
#include <cmath>

namespace wingman::render {

inline constexpr double kRenderedGamma = 2.2;

// Linear radiance (0-1) of each 8-bit value.
inline const std::array<float, 256>& linear_of_8bit() {
  static const std::array<float, 256> lut = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) t[i] = static_cast<float>(std::pow(i / 255.0, kRenderedGamma));
    return t;
  }();
  return lut;
}

}  // namespace wingman::render
