#include "vision/learned_lead_detector.hpp"

#include <algorithm>
#include <filesystem>
#include <opencv2/imgproc.hpp>

namespace wingman::vision {

namespace {

constexpr int kStride = 4;

std::string shape_text(const cv::Mat& m) {
  std::string s;
  for (int i = 0; i < m.dims; ++i) s += (i ? " x " : "") + std::to_string(m.size[i]);
  return s;
}

}  // namespace

void LearnedLeadSettings::validate() const {
  if (!(threshold > 0 && threshold < 1))
    throw std::invalid_argument("learned lead detector: threshold must be in (0, 1), got " + std::to_string(threshold));
  if (window_half_px < 16)
    throw std::invalid_argument("learned lead detector: window_half_px must be >= 16, got " +
                                std::to_string(window_half_px));
}

LearnedLeadDetector::LearnedLeadDetector(const std::string& onnx_path, const LearnedLeadSettings& settings)
    : cfg_(settings) {
  cfg_.validate();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(onnx_path, ec)) throw LeadModelError(onnx_path + ": weights file not found");
  try {
    net_ = cv::dnn::readNetFromONNX(onnx_path);
  } catch (const cv::Exception& e) {
    throw LeadModelError(onnx_path + ": not an ONNX network OpenCV can read (" + e.msg + ")");
  }
  if (net_.empty()) throw LeadModelError(onnx_path + ": the network is empty");
  // The shapes, by running it once on a 64 x 96 grey image.
  cv::Mat out;
  try {
    const int shape[] = {1, 1, 64, 96};
    net_.setInput(cv::Mat(4, shape, CV_32F, cv::Scalar(0)));
    out = net_.forward();
  } catch (const cv::Exception& e) {
    throw LeadModelError(onnx_path + ": the network does not take a 1 x 1 x H x W grey image (" + e.msg + ")");
  }
  if (out.dims != 4 || out.size[0] != 1 || out.size[1] != 3 || out.size[2] != 64 / kStride ||
      out.size[3] != 96 / kStride)
    throw LeadModelError(onnx_path + ": expected an output of 1 x 3 x 16 x 24 for a 64 x 96 image, got " +
                         shape_text(out));
}

std::pair<double, Eigen::Vector2d> LearnedLeadDetector::peak(const cv::Mat& grey, const cv::Rect& region) const {
  cv::Mat input;
  grey(region).convertTo(input, CV_32F);
  const cv::Mat blob = cv::dnn::blobFromImage(input);
  cv::Mat maps;
  {
    const std::lock_guard lock(mutex_);
    net_.setInput(blob);
    maps = net_.forward().clone();
  }
  const int rows = maps.size[2], cols = maps.size[3];
  const cv::Mat heat(rows, cols, CV_32F, maps.ptr<float>(0, 0));
  double best = 0;
  cv::Point at;
  cv::minMaxLoc(heat, nullptr, &best, nullptr, &at);
  const float x = maps.ptr<float>(0, 1)[at.y * cols + at.x], y = maps.ptr<float>(0, 2)[at.y * cols + at.x];
  return {best, Eigen::Vector2d(region.x + kStride * (at.x + x) - 0.5, region.y + kStride * (at.y + y) - 0.5)};
}

namespace {

// A region a multiple of the stride in size, inside an image of `size`.
cv::Rect fit(cv::Rect r, cv::Size size) {
  r &= cv::Rect(0, 0, size.width, size.height);
  r.width -= r.width % kStride;
  r.height -= r.height % kStride;
  return r;
}

}  // namespace

std::optional<cv::Rect> LearnedLeadDetector::window(cv::Size size, const Eigen::Vector2d& predicted) const {
  const int h = cfg_.window_half_px;
  const int x0 = std::clamp(static_cast<int>(std::lround(predicted.x())) - h, 0, std::max(0, size.width - 2 * h));
  const int y0 = std::clamp(static_cast<int>(std::lround(predicted.y())) - h, 0, std::max(0, size.height - 2 * h));
  const cv::Rect w = fit({x0, y0, 2 * h, 2 * h}, size);
  if (w.width >= 16 && w.height >= 16) return w;
  return std::nullopt;
}

std::optional<LeadDetection> LearnedLeadDetector::detect(const cv::Mat& image,
                                                         const std::optional<Eigen::Vector2d>& predicted) {
  return find(image, predicted, true);
}

std::optional<LeadDetection> LearnedLeadDetector::detect_in_window(const cv::Mat& image,
                                                                   const Eigen::Vector2d& predicted) {
  if (!window(image.size(), predicted))
    throw std::logic_error("LearnedLeadDetector::detect_in_window: the image is smaller than the window");
  return find(image, predicted, false);
}

std::optional<LeadDetection> LearnedLeadDetector::find(const cv::Mat& image,
                                                       const std::optional<Eigen::Vector2d>& predicted,
                                                       bool whole_image) {
  cv::Mat grey = lead_search_grey(image, "LearnedLeadDetector::detect");
  std::optional<std::pair<double, Eigen::Vector2d>> found;
  if (predicted) {
    if (const auto w = window(grey.size(), *predicted)) {
      const auto p = peak(grey, *w);
      if (p.first >= cfg_.threshold) found = p;
    }
  }
  if (!found && whole_image) {
    const cv::Rect whole = fit({0, 0, grey.cols, grey.rows}, grey.size());
    if (whole.width < 16 || whole.height < 16) return std::nullopt;
    const auto p = peak(grey, whole);
    if (p.first >= cfg_.threshold) found = p;
  }
  if (!found) return std::nullopt;
  LeadDetection d;
  d.source = LeadSource::Learned;
  d.uv = found->second;
  d.confidence = found->first;
  return d;
}

}  // namespace wingman::vision
