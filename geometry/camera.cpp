#include "geometry/camera.hpp"

#include <Eigen/Dense>

namespace wingman::geometry {

PinholeCamera::PinholeCamera(double fx, double fy, double cx, double cy, int width, int height,
                             Distortion dist)
    : fx_(fx), fy_(fy), cx_(cx), cy_(cy), width_(width), height_(height), dist_(dist) {}

Eigen::Matrix3d PinholeCamera::K() const {
  Eigen::Matrix3d K;
  K << fx_, 0, cx_, 0, fy_, cy_, 0, 0, 1;
  return K;
}

Eigen::Vector2d PinholeCamera::distort_normalised(const Eigen::Vector2d& xn,
                                                  Eigen::Matrix2d* J) const {
  const double x = xn.x(), y = xn.y();
  if (dist_.is_zero()) {
    if (J) *J = Eigen::Vector2d(fx_, fy_).asDiagonal();
    return {fx_ * x + cx_, fy_ * y + cy_};
  }
  const auto& d = dist_;
  const double r2 = x * x + y * y;
  const double radial = 1 + d.k1 * r2 + d.k2 * r2 * r2 + d.k3 * r2 * r2 * r2;
  const double xd = x * radial + 2 * d.p1 * x * y + d.p2 * (r2 + 2 * x * x);
  const double yd = y * radial + d.p1 * (r2 + 2 * y * y) + 2 * d.p2 * x * y;
  if (J) {
    const double drad_dr2 = d.k1 + 2 * d.k2 * r2 + 3 * d.k3 * r2 * r2;
    const double dxd_dx = radial + x * drad_dr2 * 2 * x + 2 * d.p1 * y + d.p2 * 6 * x;
    const double dxd_dy = x * drad_dr2 * 2 * y + 2 * d.p1 * x + d.p2 * 2 * y;
    const double dyd_dx = y * drad_dr2 * 2 * x + d.p1 * 2 * x + 2 * d.p2 * y;
    const double dyd_dy = radial + y * drad_dr2 * 2 * y + d.p1 * 6 * y + 2 * d.p2 * x;
    *J << fx_ * dxd_dx, fx_ * dxd_dy, fy_ * dyd_dx, fy_ * dyd_dy;
  }
  return {fx_ * xd + cx_, fy_ * yd + cy_};
}

std::optional<Eigen::Vector2d> PinholeCamera::project(const Eigen::Vector3d& p_C,
                                                      Eigen::Matrix<double, 2, 3>* J,
                                                      double min_depth) const {
  const double z = p_C.z();
  if (!(z > min_depth)) return std::nullopt;
  const Eigen::Vector2d xn(p_C.x() / z, p_C.y() / z);
  Eigen::Matrix2d Jd;
  const Eigen::Vector2d uv = distort_normalised(xn, J ? &Jd : nullptr);
  if (J) {
    Eigen::Matrix<double, 2, 3> Jn;
    Jn << 1 / z, 0, -p_C.x() / (z * z), 0, 1 / z, -p_C.y() / (z * z);
    *J = Jd * Jn;
  }
  return uv;
}

Eigen::Vector2d PinholeCamera::unproject_normalised(const Eigen::Vector2d& uv) const {
  Eigen::Vector2d target((uv.x() - cx_) / fx_, (uv.y() - cy_) / fy_);
  if (dist_.is_zero()) return target;
  // Gauss-Newton on distort_normalised(x) = uv, starting from the undistorted guess.
  Eigen::Vector2d xn = target;
  for (int it = 0; it < 20; ++it) {
    Eigen::Matrix2d J;
    const Eigen::Vector2d r = distort_normalised(xn, &J) - uv;
    if (r.squaredNorm() < 1e-20) break;
    xn -= J.lu().solve(r);
  }
  return xn;
}

Eigen::Vector3d PinholeCamera::bearing(const Eigen::Vector2d& uv) const {
  const Eigen::Vector2d xn = unproject_normalised(uv);
  return Eigen::Vector3d(xn.x(), xn.y(), 1.0).normalized();
}

bool PinholeCamera::in_image(const Eigen::Vector2d& uv, double margin) const {
  // Pixel centres span [0, w-1]; the image covers [-0.5, w-0.5].
  return uv.x() >= -0.5 + margin && uv.x() <= width_ - 0.5 - margin && uv.y() >= -0.5 + margin &&
         uv.y() <= height_ - 0.5 - margin;
}

}  // namespace wingman::geometry
