// Rotations and the frame conventions of docs/design.md, frames and conventions: world W is z-up, camera C is OpenCV's
// (x right, y down, z forward), so a nadir camera has R_CW = diag(1, -1, -1).
#pragma once

#include <Eigen/Core>

namespace wingman::geometry {

// R_CW of a camera looking straight down with its x axis along world +x.
Eigen::Matrix3d nadir_R_CW();
// Rotation about a unit axis by an angle (Rodrigues).
Eigen::Matrix3d axis_angle(const Eigen::Vector3d& axis, double angle);
Eigen::Matrix3d rot_x(double a);
Eigen::Matrix3d rot_y(double a);
Eigen::Matrix3d rot_z(double a);
// Skew-symmetric matrix [v]x.
Eigen::Matrix3d skew(const Eigen::Vector3d& v);
// Gimbal error of docs/design.md, frames and conventions: a small rotation about the camera's x and y axes, applied in the
// camera frame: R_CW_true = gimbal_error(e) * R_CW.
Eigen::Matrix3d gimbal_error(double e);
// Quaternion (x, y, z, w) of a rotation matrix, as TUM files write it.
Eigen::Vector4d quaternion_xyzw(const Eigen::Matrix3d& R);

}  // namespace wingman::geometry
