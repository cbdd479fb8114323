#include "slam/inverse_depth.hpp"

#include <cmath>

namespace wingman::slam {

Eigen::Vector3d inverse_depth_direction(double theta, double phi, Eigen::Matrix<double, 3, 2>* J) {
  const double st = std::sin(theta), ct = std::cos(theta), sp = std::sin(phi), cp = std::cos(phi);
  if (J) *J << ct * cp, -st * sp, 0, cp, st * cp, ct * sp;
  return {st * cp, sp, -ct * cp};
}

Eigen::Vector2d inverse_depth_angles(const Eigen::Vector3d& r, Eigen::Matrix<double, 2, 3>* J) {
  // theta = atan2(rx, -rz), phi = atan2(ry, sqrt(rx^2 + rz^2)).
  const double a2 = r.x() * r.x() + r.z() * r.z(), a = std::sqrt(a2), n2 = a2 + r.y() * r.y();
  if (J) {
    *J << -r.z() / a2, 0, r.x() / a2,
        -r.y() * r.x() / (a * n2), a / n2, -r.y() * r.z() / (a * n2);
  }
  return {std::atan2(r.x(), -r.z()), std::atan2(r.y(), a)};
}

Eigen::Vector3d inverse_depth_to_point(const Vector6d& y, Eigen::Matrix<double, 3, 6>* J) {
  Eigen::Matrix<double, 3, 2> Jm;
  const Eigen::Vector3d m = inverse_depth_direction(y(3), y(4), J ? &Jm : nullptr);
  const double rho = y(5);
  if (J) {
    J->leftCols<3>().setIdentity();
    J->middleCols<2>(3) = Jm / rho;
    J->col(5) = -m / (rho * rho);
  }
  return y.head<3>() + m / rho;
}

double linearity_index(const Vector6d& y, double sigma_rho, const Eigen::Vector3d& x_c) {
  const double rho = y(5);
  const Eigen::Vector3d m = inverse_depth_direction(y(3), y(4));
  const Eigen::Vector3d h = inverse_depth_to_point(y) - x_c;
  const double d1 = h.norm();
  const double sigma_d = sigma_rho / (rho * rho);
  const double cos_alpha = m.dot(h) / d1;
  return 4.0 * sigma_d / d1 * std::abs(cos_alpha);
}

}  // namespace wingman::slam
