// The five measurement models of the paper with analytic Jacobians: landmark projection
// (eq. 3-4, Euclidean and inverse-depth landmarks), lead projection (eq. 5-6), lead GPS (eq. 7),
// altimeter (eq. 8) and range (eq. 9). Each builder returns a Measurement whose H is stored as
// a few dense blocks: a projection touches one camera and one landmark, never the whole state.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "geometry/camera.hpp"
#include "slam/inverse_depth.hpp"
#include "slam/state.hpp"

namespace wingman::slam {

// Small dynamic matrices with fixed maximum size: no heap allocation per measurement.
using SmallMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, 6>;
using SmallVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1>;
using SmallSq = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, 3>;

struct JacobianBlock {
  int col = 0;  // first state column the block touches
  SmallMat H;   // rows = measurement dimension
};

struct Measurement {
  SmallVec z, h;  // observed and predicted
  SmallSq R;      // noise covariance the filter assumes
  std::vector<JacobianBlock> blocks;
  int dim() const { return static_cast<int>(z.size()); }
  SmallVec innovation() const { return z - h; }
};

// A camera as the filter knows it: intrinsics, the gimbal's commanded R_CW (a known input) and
// which state block holds its position.
struct CameraRig {
  geometry::PinholeCamera model;
  Eigen::Matrix3d R_CW = Eigen::Matrix3d::Identity();
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  // d of eq. 59: camera minus UAV position
};

// eq. 3-4: projection of a Euclidean point; Jacobians w.r.t. camera and point positions.
std::optional<Eigen::Vector2d> project_point(const CameraRig& cam, const Eigen::Vector3d& x_c,
                                             const Eigen::Vector3d& x_a,
                                             Eigen::Matrix<double, 2, 3>* J_xc = nullptr,
                                             Eigen::Matrix<double, 2, 3>* J_xa = nullptr);
// Projection of an inverse-depth landmark: p_C ~ R_CW (rho (x0 - x_c) + m(theta, phi)).
std::optional<Eigen::Vector2d> project_inverse_depth(const CameraRig& cam,
                                                     const Eigen::Vector3d& x_c, const Vector6d& y,
                                                     Eigen::Matrix<double, 2, 3>* J_xc = nullptr,
                                                     Eigen::Matrix<double, 2, 6>* J_y = nullptr);
// eq. 9: distance between the lead and a UAV (camera position minus its offset).
double range_model(const Eigen::Vector3d& x_h, const Eigen::Vector3d& x_q,
                   Eigen::Matrix<double, 1, 3>* J_xh = nullptr,
                   Eigen::Matrix<double, 1, 3>* J_xq = nullptr);

// Builders: prediction and Jacobian at the current estimate; nothing when the point is behind
// the camera. `z` is the observation, `sigma` the filter's noise std.
std::optional<Measurement> landmark_measurement(const FilterState& s, const LandmarkSlot& lm,
                                                int cam_index, const CameraRig& cam,
                                                const Eigen::Vector2d& z, double sigma_px);
std::optional<Measurement> lead_projection_measurement(const FilterState& s, int cam_index,
                                                       const CameraRig& cam,
                                                       const Eigen::Vector2d& z, double sigma_px);
Measurement gps_measurement(const FilterState& s, const Eigen::Vector3d& z, double sigma);
Measurement altimeter_measurement(const FilterState& s, int cam_index, const CameraRig& cam,
                                  double z, double sigma);
Measurement range_measurement(const FilterState& s, int cam_index, const CameraRig& cam, double z,
                              double sigma);

// The predicted pixel of a landmark in a camera for a state vector x laid out as `s`'s, without
// building a measurement (1-point RANSAC evaluates hypotheses this way).
std::optional<Eigen::Vector2d> predict_landmark_pixel(const Eigen::VectorXd& x,
                                                      const LandmarkSlot& lm, int cam_index,
                                                      const CameraRig& cam);

}  // namespace wingman::slam
