#include "render/shutter.hpp"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>

#include "geometry/frame_poses.hpp"
#include "render/linear_light.hpp"

namespace wingman::render {
namespace {

void accumulate(const cv::Mat& rgb, cv::Mat& sum, int row0) {
  const auto& lut = linear_of_8bit();
  for (int r = 0; r < rgb.rows; ++r) {
    const auto* in = rgb.ptr<std::uint8_t>(r);
    auto* out = sum.ptr<float>(row0 + r);
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

Frame expose(const sim::ShutterSpec& s, double exposure_s, int width, int height, const BandRenderer& render) {
  const int n = exposure_s > 0 ? s.subframes : 1;
  const int band = s.rolling() ? std::min(s.rows_per_band, height) : height;
  if (n == 1 && band == height) return render(0, 0, height);
  Frame f;
  f.depth.create(height, width, CV_32F);
  f.rgb.create(height, width, CV_8UC3);
  cv::Mat sum(n > 1 ? height : 0, width, CV_32FC3, cv::Scalar::all(0));
  for (int row0 = 0; row0 < height; row0 += band) {
    const int rows = std::min(band, height - row0);
    const double t_row = row_time(s, row0 + (rows - 1) / 2.0, height);
    for (int i = 0; i < n; ++i) {
      const double dt = t_row + (n == 1 ? 0 : exposure_s * ((i + 0.5) / n - 0.5));
      const Frame part = render(dt, row0, rows);
      if (n == 1)
        part.rgb.copyTo(f.rgb.rowRange(row0, row0 + rows));
      else
        accumulate(part.rgb, sum, row0);
      if (i == n / 2) part.depth.copyTo(f.depth.rowRange(row0, row0 + rows));
    }
  }
  if (n > 1) f.rgb = encode(sum, 1.0 / n);
  return f;
}

}  // namespace wingman::render
