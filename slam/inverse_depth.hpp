// Inverse-depth landmarks for the single-UAV baseline (Montiel, Civera and Davison, RSS 2006):
// y = [x0 y0 z0 theta phi rho], point = x0 + m(theta, phi) / rho. Our direction convention
// suits a downward camera: m = [sin(theta) cos(phi), sin(phi), -cos(theta) cos(phi)] is the nadir
// ray at theta = phi = 0, and its singularity (phi = +-pi/2) is a horizontal ray, never used.
// Conversion to XYZ follows the linearity index of Civera, Davison and Montiel (T-RO 2008).
#pragma once

#include <Eigen/Core>

namespace wingman::slam {

using Vector6d = Eigen::Matrix<double, 6, 1>;

// Direction m(theta, phi) and, when J is given, dm/d(theta, phi) (3x2).
Eigen::Vector3d inverse_depth_direction(double theta, double phi,
                                        Eigen::Matrix<double, 3, 2>* J = nullptr);
// (theta, phi) of a world-frame ray, and d(theta,phi)/d ray (2x3) when J is given.
Eigen::Vector2d inverse_depth_angles(const Eigen::Vector3d& ray_W,
                                     Eigen::Matrix<double, 2, 3>* J = nullptr);
// Euclidean point of y, with d point / d y (3x6) when J is given.
Eigen::Vector3d inverse_depth_to_point(const Vector6d& y, Eigen::Matrix<double, 3, 6>* J = nullptr);
// Linearity index L_d = 4 sigma_d / d_1 |cos alpha| (Civera et al. 2008, eq. 19-20):
// sigma_rho the inverse-depth std, x_c the current camera position.
double linearity_index(const Vector6d& y, double sigma_rho, const Eigen::Vector3d& x_c);

}  // namespace wingman::slam
