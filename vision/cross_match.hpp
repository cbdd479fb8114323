// Cross-UAV matching for cooperative initialisation: free features of two cameras at the same
// instant are matched by descriptor (mutual best plus ratio test), then checked against the
// epipolar geometry of the estimated camera poses and by reprojection after linear triangulation
// (positive depth in both cameras). The survivors are spread over the images up to the number of
// landmarks each camera still needs; slam's initialise_from_matches takes their pixel pairs.
#pragma once

#include "geometry/pose.hpp"
#include "geometry/settings.hpp"

#include <Eigen/Core>
#include <vector>

#include "geometry/camera.hpp"
#include "vision/features.hpp"

namespace wingman::vision {

// Camera pose as docs/design.md, frames and conventions writes it: p_C = R_CW (p_W - position).
using CameraPose = geometry::CameraPose;

struct CameraView {
  geometry::PinholeCamera camera;
  CameraPose pose;
};

// The geometry of one pixel pair under the two (estimated) poses.
struct PairGeometry {
  // Symmetric point-to-epipolar-line distance, the larger of the two images, in undistorted
  // pixels (normalised distance times the focal length).
  double epipolar_px = 0;
  bool triangulated = false;      // the linear system had a finite solution
  Eigen::Vector3d point_W = Eigen::Vector3d::Zero();
  double depth_a = 0, depth_b = 0;  // z in each camera frame
  double reprojection_px = 0;       // larger of the two reprojection errors (with distortion)
  double parallax_rad = 0;          // angle between the two rays at the point
};

// Epipolar distance, DLT triangulation (normalised undistorted coordinates, world frame),
// depths, reprojection errors and parallax of a pixel pair.
PairGeometry evaluate_pair(const Eigen::Vector2d& uv_a, const CameraView& a, const Eigen::Vector2d& uv_b,
                           const CameraView& b);

struct CrossMatchSettings {
  double ratio = 0.8;          // Lowe's ratio, in both directions
  double max_distance = 0;     // <= 0: default_max_descriptor_distance
  // The poses are estimates: at 15 m with f = 200 px, 0.3 m of relative position error moves the
  // epipolar line by about 4 px, hence more than the 1-2 px a perfect pose would need.
  double max_epipolar_px = 5.0;
  double max_reprojection_px = 5.0;
  double min_depth = 0.5;      // m, in both cameras
  double min_parallax_deg = 0; // slam applies its own parallax test; 0 leaves it to slam

  void validate() const;  // throws std::invalid_argument naming the bad value

  // The frontend: section's cross_matching: map (min_parallax_deg follows the estimator's).
  template <class V>
  void visit(V& v) {
    v("ratio", ratio, geometry::in(0, 1, true, false));
    v("max_epipolar_px", max_epipolar_px, geometry::gt(0));
    v("max_reprojection_px", max_reprojection_px, geometry::gt(0));
  }
};

enum class PairVerdict { Accepted, Epipolar, NotTriangulated, Depth, Parallax, Reprojection };
PairVerdict check_pair(const PairGeometry& g, const CrossMatchSettings& settings);

struct CrossMatchCandidate {
  int keypoint_a = -1, keypoint_b = -1;
  Eigen::Vector2d uv_a = Eigen::Vector2d::Zero(), uv_b = Eigen::Vector2d::Zero();
  double distance = 0;  // descriptor distance
  PairGeometry geometry;
};

struct CrossMatchResult {
  std::vector<CrossMatchCandidate> matches;  // accepted, best descriptor distance first
  int descriptor_matches = 0;  // mutual best pairs passing ratio and distance
  int rejected_epipolar = 0, rejected_triangulation = 0, rejected_depth = 0, rejected_parallax = 0,
      rejected_reprojection = 0;
};

// Matches the listed keypoints of `fa` (indices free_a, e.g. from free_keypoints) against the
// listed ones of `fb`; an empty list matches nothing (all_keypoints lists every one).
CrossMatchResult match_across(const Features& fa, const std::vector<int>& free_a, const CameraView& a,
                              const Features& fb, const std::vector<int>& free_b, const CameraView& b,
                              const CrossMatchSettings& settings = {});

std::vector<int> all_keypoints(const Features& f);

// Landmarks a camera still needs to reach `target` in view.
inline int landmarks_needed(int target, int in_view) { return in_view >= target ? 0 : target - in_view; }

struct SpreadSettings {
  int grid_cols = 4, grid_rows = 4;
  double min_separation_px = 20;  // from each other and from existing landmarks, in both images
};

// Picks up to `needed` matches spread over both images: repeatedly the best-ranked match (input
// order) in the pair of grid cells (one per image) holding the fewest landmarks so far, counting
// the existing landmarks' pixels (e.g. the predictions of landmarks_in_view).
std::vector<CrossMatchCandidate> select_spread(const std::vector<CrossMatchCandidate>& matches, int needed,
                                               const geometry::PinholeCamera& cam_a,
                                               const std::vector<Eigen::Vector2d>& existing_a,
                                               const geometry::PinholeCamera& cam_b,
                                               const std::vector<Eigen::Vector2d>& existing_b,
                                               const SpreadSettings& settings = {});

}  // namespace wingman::vision
