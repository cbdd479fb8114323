#include "geometry/rotation.hpp"

#include <Eigen/Geometry>

namespace wingman::geometry {

Eigen::Matrix3d nadir_R_CW() { return Eigen::Vector3d(1, -1, -1).asDiagonal(); }

Eigen::Matrix3d axis_angle(const Eigen::Vector3d& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}
Eigen::Matrix3d rot_x(double a) { return axis_angle(Eigen::Vector3d::UnitX(), a); }
Eigen::Matrix3d rot_y(double a) { return axis_angle(Eigen::Vector3d::UnitY(), a); }
Eigen::Matrix3d rot_z(double a) { return axis_angle(Eigen::Vector3d::UnitZ(), a); }

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

Eigen::Matrix3d gimbal_error(double e) { return rot_x(e) * rot_y(e); }

Eigen::Vector4d quaternion_xyzw(const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond q(R);
  return {q.x(), q.y(), q.z(), q.w()};
}

}  // namespace wingman::geometry
