// The filter state of paper eq. 2 and its covariance: x = [x_h, v_h, x_c^1, v_c^1, ..., x_a^i],
// for any number of cameras, optionally with each gimbal's pointing error (two angles per camera,
// after the agents and before the landmarks) when the filter estimates it instead of treating it
// as white noise, and optionally one acceleration every agent shares (after the gimbal angles: the
// formation's common manoeuvre as a Gauss-Markov process). Landmarks are Euclidean (3 parameters,
// eq. 2) or inverse depth (6 parameters [x0 y0 z0 theta phi rho], Montiel et al. 2006) for the
// single-UAV baseline, either optionally followed by the constant pixel offsets of the other
// cameras that observed it.
#pragma once

#include <Eigen/Core>
#include <bit>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "geometry/pose.hpp"

namespace wingman::slam {

using LandmarkId = geometry::LandmarkId;

enum class LandmarkKind { Euclidean, InverseDepth };

// A landmark's pixel offsets: the constant offset from the anchor camera's (the camera that
// initialised it, whose own offset the point absorbs) at which each other camera's detector puts
// the landmark's corner, the same way in every frame, so that it is not read as a disagreement
// between the cameras' poses (docs/results.md, "Pixel errors that persist along a track").
// A camera's two offsets become states when it first observes the landmark: until then they are
// N(0, sigma^2 I) and independent of everything (nothing else depends on them), so stating them
// then, with that prior, is exact, and the state does not carry every camera's offsets for every
// landmark.
struct PixelOffsets {
  int anchor_cam = -1;        // -1: the landmark carries no pixel offsets
  std::uint64_t cams = 0;     // bit c: camera c's offsets are states (in camera order)
  double sigma = 0;           // prior std of each offset (px)
};

struct LandmarkSlot {
  LandmarkId id = -1;
  LandmarkKind kind = LandmarkKind::Euclidean;
  int offset = 0;  // index of its first parameter in x
  PixelOffsets offsets;  // the stated ones follow the point's parameters
  int base_dim() const { return kind == LandmarkKind::Euclidean ? 3 : 6; }
  int dim() const { return base_dim() + 2 * std::popcount(offsets.cams); }
  // Index in x of camera cam's two pixel offsets, or -1 (none: the anchor, not stated, or none).
  int pixel_offset(int cam) const {
    if (!stated(cam)) return -1;
    const std::uint64_t below = (std::uint64_t{1} << cam) - 1;
    return offset + base_dim() + 2 * std::popcount(offsets.cams & below);
  }
  // Variance of each of camera cam's offsets while they are not states (sigma^2: they are added
  // to the pixel noise), or 0 (stated, the anchor, or no offsets).
  double unstated_offset_variance(int cam) const {
    if (offsets.anchor_cam < 0 || cam == offsets.anchor_cam || cam < 0 || stated(cam)) return 0;
    return offsets.sigma * offsets.sigma;
  }

 private:
  bool stated(int cam) const { return cam >= 0 && cam < 64 && (offsets.cams >> cam & 1) != 0; }
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
  // covariance with the existing state (dim x n), `cov` its own covariance. With
  // offsets.anchor_cam >= 0, value also holds the offsets of the cameras in offsets.cams after
  // the point, two per camera in camera order.
  LandmarkId add_landmark(LandmarkKind kind, const Eigen::VectorXd& value,
                          const Eigen::MatrixXd& cross, const Eigen::MatrixXd& cov,
                          const PixelOffsets& offsets = {});
  // States the pixel offsets of the (landmark, camera) pairs given that are not states yet:
  // zero, with their prior sigma^2 I, independent of everything. One rebuild of x and P for all.
  // Pairs whose landmark has no offsets, or whose camera is its anchor, are skipped.
  void state_pixel_offsets(const std::vector<std::pair<LandmarkId, int>>& pairs);
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
