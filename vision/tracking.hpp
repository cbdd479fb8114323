// Tracking map landmarks in a new frame: each landmark is searched for only inside the gate of its
// predicted projection (Mahalanobis d^2 <= gate under its innovation covariance S), by descriptor
// distance with a ratio test; one candidate per landmark, one landmark per keypoint. Acceptance is
// the estimator's (1-point RANSAC and chi^2 gating); this only proposes candidates.
#pragma once

#include "geometry/settings.hpp"

#include <Eigen/Core>
#include <vector>

#include "vision/descriptor_store.hpp"
#include "vision/features.hpp"

namespace wingman::vision {

// A landmark predicted in one camera's image: slam's landmarks_in_view(cam) gives exactly these.
struct LandmarkPrediction {
  LandmarkId id = -1;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  Eigen::Matrix2d S = Eigen::Matrix2d::Identity();  // innovation covariance H P H^T + R, px^2
};

struct TrackingSettings {
  // Search gate on d^2 = r^T S^-1 r. 9 is the "3-sigma ellipse" (d = 3; it holds 98.9 % of a 2-D
  // Gaussian); chi2_quantile(0.9973, 2) = 11.8 gives the 1-D 3-sigma probability instead.
  double gate_d2 = 9.0;
  // Lowe's ratio: best < ratio * second best among the keypoints inside the gate.
  double ratio = 0.8;
  // Largest accepted descriptor distance; 0 takes default_tracking_distance.
  double max_distance = 0;
  // Also compare with the landmark's latest accepted descriptor. Off: a refreshed descriptor lets
  // a track follow a corner that slides along an object's silhouette as the view changes, which
  // the filter then follows too (docs/results.md, rendered outliers).
  bool match_latest_descriptor = false;
  // Keypoints closer than this to the best one are the same corner at another pyramid level and do
  // not count as its second best.
  double duplicate_radius_px = 2.0;
  // Caps the search when S is huge (a freshly initialised landmark); 0 = no cap.
  double max_search_radius_px = 150.0;

  void validate() const;  // throws std::invalid_argument naming the bad value

  // The frontend: section's tracking: map.
  template <class V>
  void visit(V& v) {
    v("gate_d2", gate_d2, geometry::gt(0));
    v("ratio", ratio, geometry::in(0, 1, true, false));
    v("max_search_radius_px", max_search_radius_px, geometry::ge(0));
    v("max_distance", max_distance, geometry::ge(0));
    v("match_latest_descriptor", match_latest_descriptor);
  }
};

struct TrackCandidate {
  LandmarkId id = -1;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();  // the keypoint's pixel
  int keypoint = -1;                             // index in Features
  double distance = 0;                           // descriptor distance
  double d2 = 0;                                 // Mahalanobis d^2 from the prediction
};

struct TrackingResult {
  std::vector<TrackCandidate> candidates;  // sorted by landmark id
  std::vector<bool> keypoint_used;         // per keypoint of the frame
  int searched = 0;           // predictions with a stored descriptor
  int no_descriptor = 0;      // predictions whose id is not in the store
  int empty_gate = 0;         // no keypoint inside the gate
  int too_far = 0;            // best descriptor distance above max_distance
  int ambiguous = 0;          // failed the ratio test
  int lost_conflict = 0;      // another landmark took the same keypoint with a smaller distance
};

// Tracking's default max_distance: 0.15 of the bits of a binary descriptor (38 of ORB's 256),
// tighter than cross matching's default_max_descriptor_distance because the landmark's anchor
// descriptor is compared with a view up to tens of seconds later; 250 for float descriptors.
double default_tracking_distance(const cv::Mat& descriptors);

// Half-widths (u, v) of the box around the gate r^T S^-1 r <= gate_d2, capped at
// max_search_radius_px: where tracking looks for a landmark, and so where active search detects.
Eigen::Vector2d gate_half_extent(const Eigen::Matrix2d& S, const TrackingSettings& settings);

TrackingResult track_landmarks(const std::vector<LandmarkPrediction>& predictions,
                               const Features& frame, const DescriptorStore& store,
                               const TrackingSettings& settings = {});

// Keypoints free for new landmarks: not used by tracking and at least min_separation_px from every
// predicted landmark, so that a point already in the map is not initialised a second time.
std::vector<int> free_keypoints(const Features& frame, const std::vector<bool>& keypoint_used,
                                const std::vector<LandmarkPrediction>& predictions,
                                double min_separation_px = 8.0);

}  // namespace wingman::vision
