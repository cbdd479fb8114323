// Synthetic views for the vision tests: the aerial texture in assets/ laid on the ground plane
// z = 0 and imaged exactly by pinhole cameras (a plane maps to the image by a homography, so
// cv::warpPerspective renders it), with the matching z-depth image.
#pragma once

#include <Eigen/Dense>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <string>

#include "geometry/camera.hpp"
#include "geometry/rotation.hpp"
#include "vision/cross_match.hpp"
#include "vision/features.hpp"

namespace wingman::vision {
// How gtest prints a detector parameter (by name, not as a number).
inline void PrintTo(DetectorKind k, std::ostream* os) { *os << to_string(k); }
}  // namespace wingman::vision

namespace wingman::vision::test {

inline cv::Mat aerial_texture() {
  static const cv::Mat tex = [] {
    const std::string path = std::string(WINGMAN_SOURCE_DIR) + "/assets/aerial/freetown_drone_nadir.jpg";
    cv::Mat m = cv::imread(path, cv::IMREAD_COLOR);
    if (m.empty()) throw std::runtime_error("cannot read " + path);
    return m;
  }();
  return tex;
}

// 640 x 480, f = 300 px: at 15 m one image pixel is 5 cm on the ground, like one texture pixel.
inline geometry::PinholeCamera test_camera() { return {300, 300, 319.5, 239.5, 640, 480}; }

// The texture covers the plane z = 0 centred on the world origin, `m` metres per texture pixel;
// texture pixel centre (s, t) is at x = (s - (W-1)/2) m, y = -(t - (H-1)/2) m.
struct PlaneScene {
  cv::Mat texture = aerial_texture();
  double m = 0.05;

  Eigen::Matrix3d texture_to_image(const CameraView& v) const {
    const Eigen::Vector3d c = v.pose.position;
    Eigen::Matrix3d M;
    M << m, 0, -m * (texture.cols - 1) / 2.0 - c.x(), 0, -m, m * (texture.rows - 1) / 2.0 - c.y(), 0, 0, -c.z();
    return v.camera.K() * v.pose.R_CW * M;
  }
  cv::Mat render(const CameraView& v) const {
    const Eigen::Matrix3d H = texture_to_image(v);
    cv::Mat Hcv(3, 3, CV_64F);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) Hcv.at<double>(r, c) = H(r, c);
    cv::Mat img;
    cv::warpPerspective(texture, img, Hcv, cv::Size(v.camera.width(), v.camera.height()), cv::INTER_LINEAR,
                        cv::BORDER_REFLECT);
    return img;
  }
  // z-depth (metres, CV_32F) of the plane in every pixel.
  cv::Mat depth(const CameraView& v) const {
    cv::Mat d(v.camera.height(), v.camera.width(), CV_32F);
    for (int y = 0; y < d.rows; ++y)
      for (int x = 0; x < d.cols; ++x) {
        const auto p = ground_point(v, {double(x), double(y)});
        d.at<float>(y, x) = p ? static_cast<float>(v.pose.to_camera(*p).z()) : 0.f;
      }
    return d;
  }
  // Where a pixel's ray meets the plane.
  static std::optional<Eigen::Vector3d> ground_point(const CameraView& v, const Eigen::Vector2d& uv) {
    const Eigen::Vector2d xn = v.camera.unproject_normalised(uv);
    const Eigen::Vector3d dW = v.pose.R_CW.transpose() * Eigen::Vector3d(xn.x(), xn.y(), 1);
    if (dW.z() >= -1e-9) return std::nullopt;
    const double lambda = -v.pose.position.z() / dW.z();
    return v.pose.position + lambda * dW;
  }
};

// A nadir camera yawed by `yaw` and tilted by `tilt` about its own x axis.
inline CameraView view_at(const Eigen::Vector3d& position, double yaw = 0, double tilt = 0) {
  CameraView v;
  v.camera = test_camera();
  v.pose.position = position;
  v.pose.R_CW = geometry::rot_x(tilt) * geometry::nadir_R_CW() * geometry::rot_z(yaw).transpose();
  return v;
}

}  // namespace wingman::vision::test
