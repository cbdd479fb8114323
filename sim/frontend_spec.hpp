// The `frontend:` section of a scenario: which features the vision frontend detects and how it
// tracks and cross-matches them (rendered measurements only). sim never includes vision/, so the
// values are plain here and app/ maps them onto vision's settings.
#pragma once

#include <string>

namespace wingman::sim {

struct FrontendSpec {
  // orb | akaze | sift | gftt_orb (Shi-Tomasi corners described with ORB).
  std::string detector = "orb";
  int max_features = 1000;         // per frame, after bucketing
  int grid_cols = 8, grid_rows = 8;  // bucketing grid
  int orb_fast_threshold = 12;
  int orb_levels = 4;
  double orb_scale_factor = 1.2;
  double akaze_threshold = 0.0005;
  double sift_contrast = 0.02;
  double gftt_quality = 0.005, gftt_min_distance_px = 5.0;
  // Tracking: search inside d^2 <= gate_d2 of the predicted projection, Lowe's ratio.
  double tracking_gate_d2 = 9.0;
  double tracking_ratio = 0.8;
  double max_search_radius_px = 150.0;
  double tracking_max_distance = 0;         // descriptor distance; 0 = the descriptor's default
  bool tracking_match_latest = false;       // also compare with the latest accepted descriptor
  // Cross-UAV matching for cooperative initialisation.
  double cross_ratio = 0.8;
  double max_epipolar_px = 5.0;
  double max_reprojection_px = 5.0;
  // Diagnostic ablation, never for reported figures: every correspondence the frontend got right
  // (ground-truth label inlier; a detected lead within the match radius) reaches the estimator at
  // its exact true projection instead of its measured pixel. Data association, wrong matches and
  // what is found stay the frontend's, so the run separates the estimator's error from the pixel
  // noise of detection (docs/pipeline_rendered.md).
  bool oracle_pixels = false;
};

}  // namespace wingman::sim
