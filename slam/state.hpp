// The filter state of paper eq. 2 and its covariance: x = [x_h, v_h, x_c^1, v_c^1, ..., x_a^i],
// for any number of cameras, optionally with each gimbal's pointing error (two angles per camera,
// after the agents and before the landmarks) when the filter estimates it instead of treating it
// as white noise, and optionally one acceleration every agent shares (after the gimbal angles: the
// formation's common manoeuvre as a Gauss-Markov process). Landmarks are Euclidean (3 parameters,
// eq. 2) or inverse depth (6 parameters [x0 y0 z0 theta phi rho], Montiel et al. 2006) for the
// single-UAV baseline, either optionally followed by the other cameras' constant pixel offsets.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "geometry/pose.hpp"

namespace wingman::slam {

using LandmarkId = geometry::LandmarkId;

enum class LandmarkKind { Euclidean, InverseDepth };

struct LandmarkSlot {
  LandmarkId id = -1;
  LandmarkKind kind = LandmarkKind::Euclidean;
  int offset = 0;  // index of its first parameter in x
  // Optional pixel offsets after the point's parameters: two per camera other than the anchor
  // (the camera that initialised it, whose own constant detector offset the point absorbs), so
  // that a detector that puts the landmark's corner a little off in each camera, the same way in
  // every frame, is not read as a disagreement between the cameras' poses (docs/results.md,
  // "Pixel errors that persist along a track").
  int anchor_cam = -1;
  int extra = 0;
  int base_dim() const { return kind == LandmarkKind::Euclidean ? 3 : 6; }
  int dim() const { return base_dim() + extra; }
  // Index in x of camera cam's two pixel offsets, or -1 (none: the anchor, or no offsets).
  int pixel_offset(int cam) const {
    if (extra == 0 || cam == anchor_cam || cam < 0) return -1;
    const int k = cam < anchor_cam ? cam : cam - 1;
    return 2 * k + 2 <= extra ? offset + base_dim() + 2 * k : -1;
  }
};

class FilterState {
 public:
  explicit FilterState(int num_cameras, bool gimbal_states = false, bool common_acceleration = false);

  Eigen::VectorXd x;
  Eigen::MatrixXd P;

  int num_cameras() const { return num_cameras_; }
  static constexpr int lead_pos() { return 0; }
  static constexpr int lead_vel() { return 3; }
  static int cam_pos(int j) { return 6 + 6 * j; }
  static int cam_vel(int j) { return 9 + 6 * j; }
  int kinematic_dim() const { return 6 + 6 * num_cameras_; }  // lead and cameras, pos + vel
  // First of camera j's two gimbal angles (about its x and y axes), or -1 when not estimated.
  int gimbal(int j) const { return gimbal_states_ ? kinematic_dim() + 2 * j : -1; }
  bool has_gimbal_states() const { return gimbal_states_; }
  // First of the three components of the shared acceleration, or -1 when not estimated.
  int common_acceleration() const {
    return common_accel_ ? kinematic_dim() + (gimbal_states_ ? 2 * num_cameras_ : 0) : -1;
  }
  int agent_dim() const {
    return kinematic_dim() + (gimbal_states_ ? 2 * num_cameras_ : 0) + (common_accel_ ? 3 : 0);
  }
  int dim() const { return static_cast<int>(x.size()); }

  const std::vector<LandmarkSlot>& landmarks() const { return landmarks_; }
  const LandmarkSlot* find(LandmarkId id) const;

  // Appends a landmark (state augmentation, eq. 52): `value` its parameters, `cross` its
  // covariance with the existing state (dim x n), `cov` its own covariance.
  // With anchor_cam >= 0, value also holds 2 (num_cameras - 1) pixel offsets after the point.
  LandmarkId add_landmark(LandmarkKind kind, const Eigen::VectorXd& value,
                          const Eigen::MatrixXd& cross, const Eigen::MatrixXd& cov, int anchor_cam = -1);
  // Deletes a landmark's rows and columns.
  void remove_landmark(LandmarkId id);
  // Replaces an inverse-depth landmark by its Euclidean form: value xyz and J = d xyz / d y.
  void convert_to_euclidean(LandmarkId id, const Eigen::Vector3d& xyz,
                            const Eigen::Matrix<double, 3, 6>& J);
  // Euclidean position of any landmark (inverse depth converted, eq. of Montiel et al.).
  Eigen::Vector3d landmark_position(const LandmarkSlot& s) const;

 private:
  int num_cameras_;
  bool gimbal_states_;
  bool common_accel_;
  std::vector<LandmarkSlot> landmarks_;
  LandmarkId next_id_ = 0;
};

}  // namespace wingman::slam
