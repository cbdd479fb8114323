#include "slam/measurement_models.hpp"

#include <cmath>

#include <Eigen/Geometry>

#include "geometry/rotation.hpp"

namespace wingman::slam {

std::optional<Eigen::Vector2d> project_point(const CameraRig& cam, const Eigen::Vector3d& x_c,
                                             const Eigen::Vector3d& x_a,
                                             Eigen::Matrix<double, 2, 3>* J_xc,
                                             Eigen::Matrix<double, 2, 3>* J_xa) {
  const Eigen::Vector3d p_C = cam.R_CW * (x_a - x_c);  // eq. 4
  Eigen::Matrix<double, 2, 3> Jp;
  const bool want = J_xc || J_xa;
  auto uv = cam.model.project(p_C, want ? &Jp : nullptr);  // eq. 3
  if (!uv) return std::nullopt;
  if (want) {
    const Eigen::Matrix<double, 2, 3> JR = Jp * cam.R_CW;
    if (J_xa) *J_xa = JR;
    if (J_xc) *J_xc = -JR;
  }
  return uv;
}

std::optional<Eigen::Vector2d> project_inverse_depth(const CameraRig& cam,
                                                     const Eigen::Vector3d& x_c, const Vector6d& y,
                                                     Eigen::Matrix<double, 2, 3>* J_xc,
                                                     Eigen::Matrix<double, 2, 6>* J_y) {
  const double rho = y(5);
  Eigen::Matrix<double, 3, 2> Jm;
  const Eigen::Vector3d m = inverse_depth_direction(y(3), y(4), &Jm);
  const Eigen::Vector3d d = y.head<3>() - x_c;
  // The projection is invariant to scale, so project rho * (point - x_c) and never divide by rho.
  const Eigen::Vector3d p_C = cam.R_CW * (rho * d + m);
  Eigen::Matrix<double, 2, 3> Jp;
  const bool want = J_xc || J_y;
  auto uv = cam.model.project(p_C, want ? &Jp : nullptr);
  if (!uv) return std::nullopt;
  if (want) {
    const Eigen::Matrix<double, 2, 3> JR = Jp * cam.R_CW;
    if (J_xc) *J_xc = -rho * JR;
    if (J_y) {
      J_y->leftCols<3>() = rho * JR;
      J_y->middleCols<2>(3) = JR * Jm;
      J_y->col(5) = JR * d;
    }
  }
  return uv;
}

double range_model(const Eigen::Vector3d& x_h, const Eigen::Vector3d& x_q,
                   Eigen::Matrix<double, 1, 3>* J_xh, Eigen::Matrix<double, 1, 3>* J_xq) {
  const Eigen::Vector3d d = x_h - x_q;
  const double r = d.norm();
  if (J_xh) *J_xh = d.transpose() / r;
  if (J_xq) *J_xq = -d.transpose() / r;
  return r;
}

Eigen::Matrix<double, 2, 2> pixel_rotation_jacobian(const geometry::PinholeCamera& model,
                                                    const Eigen::Vector3d& p_C) {
  Eigen::Matrix<double, 2, 3> Jp;
  model.project(p_C, &Jp);
  // d((I + [w]x) p) / dw = -[p]x; keep the columns of rotations about x and y.
  Eigen::Matrix<double, 3, 2> dp;
  dp << 0, p_C.z(), -p_C.z(), 0, p_C.y(), -p_C.x();
  return Jp * dp;
}

CameraRig estimated_rig(const Eigen::VectorXd& x, int gimbal_col, const CameraRig& cam) {
  if (gimbal_col < 0) return cam;
  CameraRig rig = cam;
  rig.R_CW = geometry::rot_x(x(gimbal_col)) * geometry::rot_y(x(gimbal_col + 1)) * cam.R_CW;
  rig.orientation_sigma = 0;
  return rig;
}

Eigen::Matrix2d pixel_gimbal_jacobian(const geometry::PinholeCamera& model, double a_x,
                                      const Eigen::Vector3d& p_C) {
  Eigen::Matrix<double, 2, 3> Jp;
  model.project(p_C, &Jp);
  Eigen::Matrix<double, 3, 2> dp;
  dp.col(0) = Eigen::Vector3d::UnitX().cross(p_C);
  dp.col(1) = Eigen::Vector3d(0, std::cos(a_x), std::sin(a_x)).cross(p_C);
  return Jp * dp;
}

Eigen::Matrix2d pixel_covariance(const CameraRig& cam, const Eigen::Vector3d& p_C, double sigma_px) {
  Eigen::Matrix2d R = sigma_px * sigma_px * Eigen::Matrix2d::Identity();
  if (cam.orientation_sigma > 0) {
    const Eigen::Matrix2d V = pixel_rotation_jacobian(cam.model, p_C);
    R += cam.orientation_sigma * cam.orientation_sigma * V * V.transpose();
  }
  return R;
}

namespace {
// The gimbal's pointing error: a Jacobian block on its states when the filter estimates it,
// otherwise noise shared by the camera's projections of this instant.
void attach_orientation(Measurement& m, const FilterState& s, int cam_index, const CameraRig& cam,
                        const Eigen::Vector3d& p_C) {
  if (const int g = s.gimbal(cam_index); g >= 0) {
    m.blocks.push_back({g, pixel_gimbal_jacobian(cam.model, s.x(g), p_C)});
    return;
  }
  if (cam.orientation_sigma <= 0) return;
  m.camera = cam_index;
  m.orientation_sigma = cam.orientation_sigma;
  m.V = pixel_rotation_jacobian(cam.model, p_C);
}

SmallSq isotropic(int dim, double sigma) {
  SmallSq R(dim, dim);
  R.setIdentity();
  R.diagonal().setConstant(sigma * sigma);
  return R;
}
}  // namespace

std::optional<Measurement> landmark_measurement(const FilterState& s, const LandmarkSlot& lm,
                                                int cam_index, const CameraRig& rig,
                                                const Eigen::Vector2d& z, double sigma_px) {
  const CameraRig cam = estimated_rig(s.x, s.gimbal(cam_index), rig);
  const Eigen::Vector3d x_c = s.x.segment<3>(FilterState::cam_pos(cam_index));
  Measurement m;
  m.z = z;
  m.R = isotropic(2, sigma_px);
  Eigen::Matrix<double, 2, 3> J_xc;
  if (lm.kind == LandmarkKind::Euclidean) {
    Eigen::Matrix<double, 2, 3> J_xa;
    auto uv = project_point(cam, x_c, s.x.segment<3>(lm.offset), &J_xc, &J_xa);
    if (!uv) return std::nullopt;
    m.h = *uv;
    m.blocks.push_back({lm.offset, J_xa});
    attach_orientation(m, s, cam_index, cam, cam.R_CW * (s.x.segment<3>(lm.offset) - x_c));
  } else {
    Eigen::Matrix<double, 2, 6> J_y;
    const Vector6d y = s.x.segment<6>(lm.offset);
    auto uv = project_inverse_depth(cam, x_c, y, &J_xc, &J_y);
    if (!uv) return std::nullopt;
    m.h = *uv;
    m.blocks.push_back({lm.offset, J_y});
    // The rotation Jacobian is scale invariant: the scaled point rho (x0 - x_c) + m will do.
    attach_orientation(m, s, cam_index, cam,
                       cam.R_CW * (y(5) * (y.head<3>() - x_c) + inverse_depth_direction(y(3), y(4))));
  }
  m.blocks.push_back({FilterState::cam_pos(cam_index), J_xc});
  if (const int o = lm.pixel_offset(cam_index); o >= 0) {  // uv = projection + this camera's offset
    m.h += s.x.segment<2>(o);
    m.blocks.push_back({o, Eigen::Matrix2d::Identity()});
  } else {  // an offset not yet a state: zero mean, independent of everything, so noise
    m.R.diagonal().array() += lm.unstated_offset_variance(cam_index);
  }
  return m;
}

std::optional<Measurement> lead_projection_measurement(const FilterState& s, int cam_index,
                                                       const CameraRig& rig,
                                                       const Eigen::Vector2d& z, double sigma_px) {
  const CameraRig cam = estimated_rig(s.x, s.gimbal(cam_index), rig);
  Eigen::Matrix<double, 2, 3> J_xc, J_xh;
  auto uv = project_point(cam, s.x.segment<3>(FilterState::cam_pos(cam_index)),
                          s.x.segment<3>(FilterState::lead_pos()), &J_xc, &J_xh);  // eq. 5-6
  if (!uv) return std::nullopt;
  Measurement m;
  m.z = z;
  m.h = *uv;
  m.R = isotropic(2, sigma_px);
  m.blocks.push_back({FilterState::lead_pos(), J_xh});
  m.blocks.push_back({FilterState::cam_pos(cam_index), J_xc});
  attach_orientation(m, s, cam_index, cam,
                     cam.R_CW * (s.x.segment<3>(FilterState::lead_pos()) -
                                       s.x.segment<3>(FilterState::cam_pos(cam_index))));
  return m;
}

Measurement gps_measurement(const FilterState& s, const Eigen::Vector3d& z, double sigma) {
  Measurement m;  // eq. 7
  m.z = z;
  m.h = s.x.segment<3>(FilterState::lead_pos());
  m.R = isotropic(3, sigma);
  m.blocks.push_back({FilterState::lead_pos(), Eigen::Matrix3d::Identity()});
  return m;
}

Measurement altimeter_measurement(const FilterState& s, int cam_index, const CameraRig& cam,
                                  double z, double sigma) {
  Measurement m;  // eq. 8, on the UAV's altitude: camera height minus the offset
  m.z = SmallVec::Constant(1, z);
  m.h = SmallVec::Constant(1, s.x(FilterState::cam_pos(cam_index) + 2) - cam.offset.z());
  m.R = isotropic(1, sigma);
  m.blocks.push_back({FilterState::cam_pos(cam_index), Eigen::RowVector3d(0, 0, 1)});
  return m;
}

Measurement range_measurement(const FilterState& s, int cam_index, const CameraRig& cam, double z,
                              double sigma) {
  Eigen::Matrix<double, 1, 3> J_xh, J_xq;
  const double r = range_model(s.x.segment<3>(FilterState::lead_pos()),
                               s.x.segment<3>(FilterState::cam_pos(cam_index)) - cam.offset, &J_xh,
                               &J_xq);  // eq. 9
  Measurement m;
  m.z = SmallVec::Constant(1, z);
  m.h = SmallVec::Constant(1, r);
  m.R = isotropic(1, sigma);
  m.blocks.push_back({FilterState::lead_pos(), J_xh});
  m.blocks.push_back({FilterState::cam_pos(cam_index), J_xq});
  return m;
}

std::optional<Eigen::Vector2d> predict_landmark_pixel(const FilterState& s, const Eigen::VectorXd& x,
                                                      const LandmarkSlot& lm, int cam_index,
                                                      const CameraRig& rig) {
  const CameraRig cam = estimated_rig(x, s.gimbal(cam_index), rig);
  const Eigen::Vector3d x_c = x.segment<3>(FilterState::cam_pos(cam_index));
  auto uv = lm.kind == LandmarkKind::Euclidean ? project_point(cam, x_c, x.segment<3>(lm.offset))
                                                : project_inverse_depth(cam, x_c, x.segment<6>(lm.offset));
  if (const int o = lm.pixel_offset(cam_index); uv && o >= 0) *uv += x.segment<2>(o);
  return uv;
}

}  // namespace wingman::slam
