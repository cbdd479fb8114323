// Active search (Davison's MonoSLAM): features are detected only where the step uses them —
// inside the search boxes of the landmarks the filter predicts in view (tracking's gates), and in
// the image blocks where the map needs new landmarks — instead of over the whole frame. Detection
// cost grows with the pixels it processes (ORB builds its pyramid and runs FAST everywhere it is
// given; a mask saves nothing), so the regions are cropped, never masked: docs/studies/speed.md.
#pragma once

#include "geometry/settings.hpp"

#include <opencv2/core.hpp>
#include <vector>

#include "vision/tracking.hpp"

namespace wingman::vision {

struct ActiveSearchSettings {
  // Off: the whole frame every step (the reference path for comparisons).
  bool enabled = true;
  // New landmarks come from square blocks of this side, chosen where the predictions are fewest,
  // the most central first.
  int block_px = 125;
  // How many new landmarks one block is expected to give; ceil(needed / this) blocks are opened.
  double landmarks_per_block = 3.0;
  // When the crops with their context would process more than this fraction of the frame's
  // pixels, the whole frame is cheaper and is detected instead.
  double max_fraction = 0.7;

  void validate() const;  // throws std::invalid_argument naming the bad value

  // The frontend: section's active_search: map.
  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("block_px", block_px, geometry::ge(16));
    v("landmarks_per_block", landmarks_per_block, geometry::gt(0));
    v("max_fraction", max_fraction, geometry::in(0, 1));
  }
};

struct SearchPlan {
  bool whole_frame = true;
  std::vector<cv::Rect> regions;  // disjoint; empty when whole_frame
  // Pixels the detector processes (each region with `margin` of context, clipped to the image)
  // over the frame's: 1 for the whole frame.
  double fraction = 1.0;
  int gates = 0;   // predictions whose gate box is searched
  int blocks = 0;  // blocks opened for new landmarks
};

// Where `needed` new landmarks are looked for: ceil(needed / landmarks_per_block) blocks of the
// image's block grid, those holding the fewest predictions, the most central first (a landmark near
// the centre stays in view longest, and there a cooperative pair has the most parallax).
std::vector<cv::Rect> new_landmark_blocks(cv::Size image, const std::vector<LandmarkPrediction>& predictions,
                                          int needed, const ActiveSearchSettings& settings);

// Regions for one camera's frame: each prediction's gate box (gate_half_extent), plus the blocks
// for new landmarks (new_landmark_blocks, or another camera's carried into this one); overlapping
// boxes are merged, and boxes whose merged crop costs no more than the two apart (a crop's pixels
// and a fixed cost). `margin`: the detector's context around a region
// (FeatureExtractor::crop_margin). Disabled, or costlier than max_fraction: the whole frame.
SearchPlan plan_search(cv::Size image, const std::vector<LandmarkPrediction>& predictions,
                       const std::vector<cv::Rect>& blocks, int margin, const TrackingSettings& tracking,
                       const ActiveSearchSettings& settings);

}  // namespace wingman::vision
