// The lead found as it is, with no marker: a small fully convolutional network (trained by
// tools/train_lead_detector.py on Wingman's own rendered frames, run by OpenCV's dnn module) maps a
// grey image to three maps at a quarter of its size: the probability that x_h's projection lies in
// each 4 x 4 cell, and where in the cell (x, y in [0, 1)); x_h is at u = 4 (column + x) - 0.5,
// v = 4 (row + y) - 0.5. With a prediction, a window around it is searched first, then the whole
// frame.
#pragma once

#include <Eigen/Core>
#include <mutex>
#include <opencv2/dnn.hpp>
#include <optional>
#include <stdexcept>
#include <string>

#include "vision/lead_detector.hpp"

namespace wingman::vision {

struct LearnedLeadSettings {
  // A peak at or above this probability is the lead.
  double threshold = 0.3;
  // With a prediction, the square of side 2 window_half_px around it is searched first.
  int window_half_px = 96;

  void validate() const;  // throws std::invalid_argument naming the bad value
};

// A weights file that cannot be read, or a network whose input or output is not the expected one.
class LeadModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class LearnedLeadDetector final : public LeadFinder {
 public:
  // Loads and checks the ONNX file: one grey input of any size divisible by 4, one output of
  // 1 x 3 x H/4 x W/4. Throws LeadModelError naming the file.
  LearnedLeadDetector(const std::string& onnx_path, const LearnedLeadSettings& settings = {});
  // `image`: 8-bit grey (or BGR, turned grey).
  std::optional<LeadDetection> detect(const cv::Mat& image,
                                      const std::optional<Eigen::Vector2d>& predicted = std::nullopt) override;
  std::optional<cv::Rect> window(cv::Size size, const Eigen::Vector2d& predicted) const override;
  std::optional<LeadDetection> detect_in_window(const cv::Mat& image, const Eigen::Vector2d& predicted) override;
  const LearnedLeadSettings& settings() const { return cfg_; }

 private:
  std::optional<LeadDetection> find(const cv::Mat& image, const std::optional<Eigen::Vector2d>& predicted,
                                    bool whole_image);
  // The strongest cell of the network's maps over `region` of grey: probability and pixel.
  std::pair<double, Eigen::Vector2d> peak(const cv::Mat& grey, const cv::Rect& region) const;
  LearnedLeadSettings cfg_;
  mutable cv::dnn::Net net_;  // forward() is not const
  mutable std::mutex mutex_;  // one forward at a time
};

}  // namespace wingman::vision
