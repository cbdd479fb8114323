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
  SmallSq R;      // independent noise covariance the filter assumes
  std::vector<JacobianBlock> blocks;
  // Shared noise: the gimbal's pointing error about the camera's x and y axes is one rotation
  // for every projection of that camera at that instant (the V R V^T of eq. 45, correlated across
  // the camera's measurements). V = d h / d(rotation about x, y); camera -1 means none.
  int camera = -1;
  double orientation_sigma = 0;
  Eigen::Matrix<double, Eigen::Dynamic, 2, 0, 3, 2> V;
  int dim() const { return static_cast<int>(z.size()); }
  SmallVec innovation() const { return z - h; }
};

// A camera as the filter knows it: intrinsics, the gimbal's commanded R_CW (a known input) and
// which state block holds its position.
struct CameraRig {
  geometry::PinholeCamera model;
  Eigen::Matrix3d R_CW = Eigen::Matrix3d::Identity();
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  // d of eq. 59: camera minus UAV position
  // Std of the gimbal's pointing error about the camera's x and y axes (rad) that the filter
  // assumes; 0 trusts R_CW exactly, as the paper's filter does.
  double orientation_sigma = 0;
};

// The camera as the filter sees it at state x: when the state holds camera j's gimbal error
// (gimbal_col >= 0), R_CW becomes R_x(a_x) R_y(a_y) R_CW, the truth's parametrisation of the error
// (docs/design.md, frames and conventions), and the error is no longer marginalised as noise (orientation_sigma = 0).
CameraRig estimated_rig(const Eigen::VectorXd& x, int gimbal_col, const CameraRig& cam);
// d uv / d(a_x, a_y) of the projection of p_C = R_x(a_x) R_y(a_y) R_CW (p_W - x_c), at p_C:
// d p_C / d a_x = [e_x]x p_C and d p_C / d a_y = [R_x(a_x) e_y]x p_C.
Eigen::Matrix2d pixel_gimbal_jacobian(const geometry::PinholeCamera& model, double a_x,
                                      const Eigen::Vector3d& p_C);

// d uv / d(small rotation of the camera about its x and y axes) at a point p_C in the camera
// frame: p_C -> (I + [w]x) p_C.
Eigen::Matrix<double, 2, 2> pixel_rotation_jacobian(const geometry::PinholeCamera& model,
                                                    const Eigen::Vector3d& p_C);
// The pixel covariance a projection at p_C carries: sigma_px^2 I + V Sigma_gimbal V^T.
Eigen::Matrix2d pixel_covariance(const CameraRig& cam, const Eigen::Vector3d& p_C, double sigma_px);

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
std::optional<Eigen::Vector2d> predict_landmark_pixel(const FilterState& s, const Eigen::VectorXd& x,
                                                      const LandmarkSlot& lm, int cam_index,
                                                      const CameraRig& cam);

}  // namespace wingman::slam
