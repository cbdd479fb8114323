#include "render/shutter.hpp"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "geometry/frame_poses.hpp"
#include "render/linear_light.hpp"

namespace wingman::render {
namespace {

void accumulate(const cv::Mat& rgb, cv::Mat& sum) {
  const auto& lut = linear_of_8bit();
  for (int r = 0; r < rgb.rows; ++r) {
    const auto* in = rgb.ptr<std::uint8_t>(r);
    auto* out = sum.ptr<float>(r);
    for (int i = 0; i < rgb.cols * 3; ++i) out[i] += lut[in[i]];
  }
}

cv::Mat encode(const cv::Mat& sum, double scale) {
  cv::Mat lin = sum * scale, enc;
  cv::pow(cv::max(lin, 0.0), 1.0 / kRenderedGamma, enc);
  cv::Mat out;
  enc.convertTo(out, CV_8UC3, 255.0);  // rounds and saturates
  return out;
}

}  // namespace

double row_time(const sim::ShutterSpec& s, double row, int height) {
  if (!s.rolling()) return 0;
  return geometry::rolling_row_time(row, height, s.line_delay, s.readout == sim::ShutterSpec::Readout::TopToBottom);
}

int subframes_for(const sim::ShutterSpec& s, double smear_px) {
  if (s.subframe_motion_px <= 0) return s.subframes;
  if (!(smear_px >= s.subframe_motion_px / 2)) return 1;  // NaN: nothing is known to move
  const double want = std::ceil(smear_px / s.subframe_motion_px);
  const int n = static_cast<int>(std::min<double>(want, s.subframes));
  return n % 2 == 1 ? n : std::min(n + 1, s.subframes);
}

Frame draw_in_bands(const sim::ShutterSpec& s, int width, int height, double dt, const BandRenderer& band) {
  // rows_per_band 0 (one pass, which takes a whole-frame renderer) is drawn here row by row.
  const int rows_per_band = s.rolling() ? std::clamp(s.rows_per_band, 1, height) : height;
  if (rows_per_band == height) return band(dt + row_time(s, (height - 1) / 2.0, height), 0, height);
  Frame f;
  f.depth.create(height, width, CV_32F);
  f.rgb.create(height, width, CV_8UC3);
  for (int row0 = 0; row0 < height; row0 += rows_per_band) {
    const int rows = std::min(rows_per_band, height - row0);
    const Frame part = band(dt + row_time(s, row0 + (rows - 1) / 2.0, height), row0, rows);
    part.rgb.copyTo(f.rgb.rowRange(row0, row0 + rows));
    part.depth.copyTo(f.depth.rowRange(row0, row0 + rows));
  }
  return f;
}

Frame expose(double exposure_s, const SubframeRenderer& render, const SubframeCount& count) {
  Frame middle = render(0);
  const int n = exposure_s > 0 ? count(middle) : 1;
  if (n <= 1) return middle;
  // Summed in the order of the instants, the middle one in its place.
  cv::Mat sum(middle.rgb.size(), CV_32FC3, cv::Scalar::all(0));
  for (int i = 0; i < n; ++i) {
    if (i == n / 2) {
      accumulate(middle.rgb, sum);
      continue;
    }
    accumulate(render(exposure_s * ((i + 0.5) / n - 0.5)).rgb, sum);
  }
  Frame f;
  f.depth = std::move(middle.depth);
  f.rgb = encode(sum, 1.0 / n);
  return f;
}

Frame expose(const sim::ShutterSpec& s, double exposure_s, int width, int height, const BandRenderer& render) {
  return expose(
      exposure_s, [&](double dt) { return draw_in_bands(s, width, height, dt, render); },
      [&](const Frame&) { return s.subframes; });
}

}  // namespace wingman::render
