// New landmarks.
// Multi-UAV (paper section 5.2): a point seen by two cameras at the same instant is triangulated
// linearly from both projections with the a posteriori camera positions (eq. 47-51), and the state
// is augmented with the covariance of that function of the camera states and both pixels
// (eq. 52), cross-covariances included.
// Single-UAV baseline: undelayed inverse-depth initialisation from one pixel (Montiel et al. 2006).
// A cooperative pair with too little parallax for eq. 52's linearisation can instead become an
// inverse-depth landmark anchored at the first camera and corrected at once with the second pixel.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

#include "slam/measurement_models.hpp"
#include "slam/settings.hpp"
#include "slam/state.hpp"

namespace wingman::slam {

struct Triangulation {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  // d point / d (x_c^a, x_c^b, uv_a, uv_b): 3 x 10.
  Eigen::Matrix<double, 3, 10> J = Eigen::Matrix<double, 3, 10>::Zero();
  double parallax_rad = 0;
  double reprojection_px = 0;  // the larger of the two
};

// eq. 49-51: linear triangulation x = D^+ b from two pixels (distortion removed first), with its
// analytic Jacobian. Nothing when a pixel cannot be undistorted or D is rank deficient.
std::optional<Triangulation> triangulate_two_views(const CameraRig& cam_a, const Eigen::Vector3d& x_a,
                                                   const Eigen::Vector2d& uv_a,
                                                   const CameraRig& cam_b, const Eigen::Vector3d& x_b,
                                                   const Eigen::Vector2d& uv_b);


// The rejection reason of a pair under min_parallax_deg.
inline constexpr const char* kLowParallax = "low parallax";
// The rejection reason of a pair that triangulates nearer than min_depth_m.
inline constexpr const char* kTooClose = "too close";

// Triangulates, checks depth, parallax and reprojection, and augments the state (eq. 52).
// Returns the new landmark's id, or the reason it was rejected.
struct InitOutcome {
  std::optional<LandmarkId> id;
  std::string rejected_because;
};
InitOutcome initialise_cooperative(FilterState& s, int cam_a, const CameraRig& commanded_a,
                                   const Eigen::Vector2d& uv_a, int cam_b,
                                   const CameraRig& commanded_b,
                                   const Eigen::Vector2d& uv_b, const InitialisationSettings& cfg,
                                   const MeasurementNoiseSettings& noise);


// Inverse-depth parameters of the ray through uv from a camera at x_c, with d y / d(x_c, uv)
// (6 x 5; rho does not depend on them).
Vector6d inverse_depth_from_pixel(const CameraRig& cam, const Eigen::Vector3d& x_c,
                                  const Eigen::Vector2d& uv, double rho,
                                  Eigen::Matrix<double, 6, 5>* J = nullptr);
InitOutcome initialise_inverse_depth(FilterState& s, int cam, const CameraRig& commanded,
                                     const Eigen::Vector2d& uv, const InitialisationSettings& cfg,
                                     const MeasurementNoiseSettings& noise);

// A cooperative pair whose parallax is too small for a Euclidean landmark (eq. 52 linearises the
// triangulation, which is poor at low parallax): the inverse-depth landmark of camera a's pixel,
// then an EKF update with camera b's pixel of the same instant. Inverse depth keeps that update
// nearly linear (Montiel et al. 2006), so the second view fixes rho as far as the baseline allows;
// the update's chi^2 gate (the epipolar test) rejects a pair the landmark cannot explain, and the
// landmark is then removed again.
InitOutcome initialise_cooperative_inverse_depth(FilterState& s, int cam_a, const CameraRig& commanded_a,
                                                 const Eigen::Vector2d& uv_a, int cam_b,
                                                 const CameraRig& commanded_b,
                                                 const Eigen::Vector2d& uv_b,
                                                 const InitialisationSettings& cfg,
                                                 const MeasurementNoiseSettings& noise,
                                                 double gate_probability);

// Converts inverse-depth landmarks whose linearity index (seen from camera `cam`) is below the
// threshold; returns how many were converted.
int convert_linear_landmarks(FilterState& s, int cam, double threshold);

}  // namespace wingman::slam
