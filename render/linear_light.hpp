// How the renderer's 8-bit colour encodes radiance: a gamma of 2.2. The shutter, the haze and the
// sensor work in linear light and go through this one table.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

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

// The 8-bit value of linear radiance `lin`: saturate_cast(255 lin^(1 / 2.2)), without a pow: the
// value at the start of lin's bin of a fine table, stepped up past the linear values where that
// rounding steps up (once or not at all but near black, where the steps crowd).
inline std::uint8_t encode_linear(double lin) {
  constexpr int kBins = 1 << 14;
  struct Tables {
    std::array<double, 256> steps{};  // steps[v]: the least linear value that encodes to v + 1
    std::array<std::uint8_t, kBins> start{};
  };
  static const Tables t = [] {
    Tables x;
    for (int v = 0; v < 255; ++v) x.steps[v] = std::pow((v + 0.5) / 255.0, kRenderedGamma);
    x.steps[255] = INFINITY;
    int v = 0;
    for (int b = 0; b < kBins; ++b) {
      while (static_cast<double>(b) / kBins >= x.steps[v]) ++v;
      x.start[b] = static_cast<std::uint8_t>(v);
    }
    return x;
  }();
  if (!(lin > 0)) return 0;
  if (lin >= 1) return 255;
  int v = t.start[static_cast<int>(lin * kBins)];
  while (lin >= t.steps[v]) ++v;
  return static_cast<std::uint8_t>(v);
}

}  // namespace wingman::render
