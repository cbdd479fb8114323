// Pinhole camera with radial-tangential distortion (the paper's eq. 3 and 5; docs/design.md, frames and conventions).
// Pixel convention is OpenCV's: (0,0) is the centre of the top-left pixel, u = fx x/z + cx
// before distortion. Jacobians are analytic; tests/geometry checks them numerically.
#pragma once

#include <Eigen/Core>
#include <optional>

namespace wingman::geometry {

struct Distortion {
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;
  bool is_zero() const { return k1 == 0 && k2 == 0 && p1 == 0 && p2 == 0 && k3 == 0; }
};

class PinholeCamera {
 public:
  PinholeCamera() = default;
  PinholeCamera(double fx, double fy, double cx, double cy, int width, int height,
                Distortion dist = {});

  double fx() const { return fx_; }
  double fy() const { return fy_; }
  double cx() const { return cx_; }
  double cy() const { return cy_; }
  int width() const { return width_; }
  int height() const { return height_; }
  const Distortion& distortion() const { return dist_; }
  Eigen::Matrix3d K() const;

  // Projects a point given in the camera frame. Returns nothing behind the camera (z <= min_depth).
  // When J is given it receives d(u,v)/d(p_C), 2x3.
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& p_C,
                                         Eigen::Matrix<double, 2, 3>* J = nullptr,
                                         double min_depth = 1e-6) const;

  // Normalised image coordinates -> distorted pixel, with d(u,v)/d(xn,yn) when J is given.
  Eigen::Vector2d distort_normalised(const Eigen::Vector2d& xn,
                                     Eigen::Matrix2d* J = nullptr) const;
  // Pixel -> normalised undistorted coordinates (iterative inverse of the distortion).
  Eigen::Vector2d unproject_normalised(const Eigen::Vector2d& uv) const;
  // Unit bearing in the camera frame through a pixel.
  Eigen::Vector3d bearing(const Eigen::Vector2d& uv) const;

  bool in_image(const Eigen::Vector2d& uv, double margin = 0.0) const;

 private:
  double fx_ = 200.1, fy_ = 200.1, cx_ = 500, cy_ = 500;
  int width_ = 1000, height_ = 1000;
  Distortion dist_{};
};

}  // namespace wingman::geometry
