// The lead found by its motion, with no marker and no learned weights. The team flies with the
// lead, so the ground slides under the cameras while the lead keeps its place in the image. Each
// frame, a homography fitted (RANSAC) to corners tracked from the previous frame (pyramidal
// Lucas-Kanade) carries the ground from frame to frame; earlier frames warped onto the current one
// by the chained homographies, chosen so that the ground has moved by 1, 2, ... `references`
// times `step_px` under the predicted lead, give the background as their per-pixel median (the
// lead, moving against the ground, is in fewer than half of them). What differs from that
// background is what does not follow the ground: the lead, its shadow, and what stands out of the
// ground plane (parallax). The blob nearest the prediction (without one: the largest) is the lead,
// at its centroid.
//
// Limits: a team that hovers, or moves slower than `references` x `step_px` over `history`
// frames, gives no background, and nothing is detected; a lead that stops on the ground while the
// team moves follows the ground and is not seen; its shadow moves with it and pulls the centroid;
// tall objects (trees, buildings) move against the ground plane too, and only the prediction
// tells them from the lead. The detector keeps its camera's earlier frames: one per camera, frames
// in order.
#pragma once

#include <Eigen/Core>
#include <deque>
#include <opencv2/core.hpp>
#include <optional>

#include "vision/lead_detector.hpp"

namespace wingman::vision {

struct MotionLeadSettings {
  // Frames are searched at 1 / downscale of their size.
  int downscale = 2;
  // The ground's shift between the current frame and its nearest reference (full-size px); the
  // j-th reference has moved by at least j step_px. The median is the ground's wherever the lead
  // covers fewer than half the references: a lead up to (references - 1) / 2 step_px long.
  double step_px = 24;
  // Earlier frames whose median is the background (at least 3); all are needed.
  int references = 5;
  // How many earlier frames are kept to choose them from.
  int history = 90;
  // A pixel differs from the background by at least this many grey levels, and by 4 times the
  // frame's median difference (noise, aliasing, parallax).
  double threshold = 18;
  // A blob of at least this area (full-size px^2) can be the lead.
  double min_area_px = 40;
  // With a prediction, the lead is the blob whose centroid is nearest it and at most this far.
  int window_half_px = 96;

  void validate() const;  // throws std::invalid_argument naming the bad value
};

class MotionLeadDetector final : public LeadFinder {
 public:
  explicit MotionLeadDetector(const MotionLeadSettings& settings = {});
  // `image`: 8-bit grey (or BGR, turned grey), the camera's next frame, all of the same size.
  std::optional<LeadDetection> detect(const cv::Mat& image,
                                      const std::optional<Eigen::Vector2d>& predicted = std::nullopt) override;
  const MotionLeadSettings& settings() const { return cfg_; }
  // The last frame's motion mask (downscaled; 255: differs from the background), for inspection.
  const cv::Mat& motion_mask() const { return mask_; }

 private:
  struct Earlier {
    cv::Mat grey;       // downscaled
    cv::Mat to_current;  // 3 x 3 CV_64F: this frame's pixels to the current one's (the ground)
  };
  // The ground's homography from the previous frame to `grey`; false if it cannot be fitted.
  bool track_ground(const cv::Mat& grey, cv::Mat& H) const;
  // The references' indices into earlier_ (nearest first): all `references` of them, or none.
  std::vector<int> references(const cv::Point2d& at) const;
  cv::Mat background(const std::vector<int>& refs, cv::Mat& valid) const;
  std::optional<LeadDetection> blob(const std::optional<Eigen::Vector2d>& predicted) const;

  MotionLeadSettings cfg_;
  std::deque<Earlier> earlier_;  // newest first
  cv::Mat previous_;             // the last frame, downscaled
  cv::Mat last_step_ = cv::Mat::eye(3, 3, CV_64F);  // the ground's last frame-to-frame homography
  cv::Mat mask_;
};

}  // namespace wingman::vision
