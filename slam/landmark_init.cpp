#include "slam/landmark_init.hpp"

#include <Eigen/Dense>
#include <cmath>

#include "slam/ekf_update.hpp"
#include "slam/inverse_depth.hpp"
#include "slam/visual_update.hpp"

namespace wingman::slam {

namespace {
constexpr double kPi = 3.14159265358979323846;

// Ideal (undistorted) pixel of a measured pixel, and d ideal / d measured.
Eigen::Vector2d ideal_pixel(const geometry::PinholeCamera& cam, const Eigen::Vector2d& uv,
                            Eigen::Matrix2d* J) {
  const Eigen::Vector2d xn = cam.unproject_normalised(uv);
  const Eigen::Matrix2d F = Eigen::Vector2d(cam.fx(), cam.fy()).asDiagonal();
  if (J) {
    Eigen::Matrix2d Jd;
    cam.distort_normalised(xn, &Jd);
    *J = F * Jd.inverse();
  }
  return F * xn + Eigen::Vector2d(cam.cx(), cam.cy());
}
}  // namespace

std::optional<Triangulation> triangulate_two_views(const CameraRig& cam_a, const Eigen::Vector3d& x_a,
                                                   const Eigen::Vector2d& uv_a,
                                                   const CameraRig& cam_b, const Eigen::Vector3d& x_b,
                                                   const Eigen::Vector2d& uv_b) {
  const CameraRig* rigs[2] = {&cam_a, &cam_b};
  const Eigen::Vector3d* xs[2] = {&x_a, &x_b};
  const Eigen::Vector2d* uvs[2] = {&uv_a, &uv_b};
  // eq. 50-51 with M = K R [I | -x_c]: each row r of D satisfies r X = r x_c, so b = D x_c.
  Eigen::Matrix<double, 4, 3> D;
  Eigen::Vector4d b;
  Eigen::Matrix3d A[2];
  Eigen::Vector2d ideal[2];
  Eigen::Matrix2d J_ideal[2];
  for (int c = 0; c < 2; ++c) {
    A[c] = rigs[c]->model.K() * rigs[c]->R_CW;
    ideal[c] = ideal_pixel(rigs[c]->model, *uvs[c], &J_ideal[c]);
    for (int k = 0; k < 2; ++k) {
      const Eigen::RowVector3d row = A[c].row(2) * ideal[c](k) - A[c].row(k);
      D.row(2 * c + k) = row;
      b(2 * c + k) = row * (*xs[c]);
    }
  }
  const Eigen::Matrix3d G = D.transpose() * D;
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(G);
  if (!lu.isInvertible() || lu.rcond() < 1e-12) return std::nullopt;
  const Eigen::Matrix3d Gi = lu.inverse();
  Triangulation t;
  t.point = Gi * D.transpose() * b;  // eq. 49
  const Eigen::Vector4d e = b - D * t.point;

  // d X = G^-1 [dD^T e + D^T (db - dD X)], evaluated per parameter.
  for (int c = 0; c < 2; ++c) {
    const Eigen::Matrix<double, 2, 3> Dc = D.middleRows<2>(2 * c);
    t.J.block<3, 3>(0, 3 * c) = Gi * Dc.transpose() * Dc;  // camera position
    Eigen::Matrix<double, 3, 2> d_ideal;
    for (int k = 0; k < 2; ++k) {
      const Eigen::Vector3d a3 = A[c].row(2).transpose();
      const double de_dp = a3.dot(*xs[c] - t.point);
      d_ideal.col(k) = Gi * (a3 * e(2 * c + k) + D.row(2 * c + k).transpose() * de_dp);
    }
    t.J.block<3, 2>(0, 6 + 2 * c) = d_ideal * J_ideal[c];
  }

  const Eigen::Vector3d ra = (x_a - t.point).normalized(), rb = (x_b - t.point).normalized();
  t.parallax_rad = std::acos(std::clamp(ra.dot(rb), -1.0, 1.0));
  for (int c = 0; c < 2; ++c) {
    auto uv = project_point(*rigs[c], *xs[c], t.point);
    t.reprojection_px = std::max(t.reprojection_px, uv ? (*uv - *uvs[c]).norm() : INFINITY);
  }
  return t;
}

namespace {
// A new landmark's covariance with the state and its own (eq. 52), from the Jacobians of its
// parameters with respect to the state blocks it depends on (columns `col`) and its pixel noise.
struct StateDependence {
  int col;
  Eigen::MatrixXd J;  // rows: landmark parameters; cols: the block's dimension
};
std::pair<Eigen::MatrixXd, Eigen::MatrixXd> augmented_covariance(
    const FilterState& s, const std::vector<StateDependence>& deps, const Eigen::MatrixXd& pixel_cov) {
  Eigen::MatrixXd cross = Eigen::MatrixXd::Zero(pixel_cov.rows(), s.dim());
  for (const auto& d : deps) cross.noalias() += d.J * s.P.middleRows(d.col, d.J.cols());
  Eigen::MatrixXd cov = pixel_cov;
  for (const auto& d : deps) cov.noalias() += cross.middleCols(d.col, d.J.cols()) * d.J.transpose();
  return {std::move(cross), std::move(cov)};
}

// A new landmark's parameters followed by the pixel offsets of the cameras in `cams`
// (LandmarkSlot::pixel_offset): zero, prior sigma^2 I, independent of the state and of the
// parameters.
struct WithOffsets {
  Eigen::VectorXd value;
  Eigen::MatrixXd cross, cov;
};
WithOffsets append_pixel_offsets(const FilterState& s, const Eigen::VectorXd& value,
                                 const Eigen::MatrixXd& cross, const Eigen::MatrixXd& cov,
                                 const PixelOffsets& offsets) {
  const int b = static_cast<int>(value.size()), d = b + 2 * std::popcount(offsets.cams);
  WithOffsets w{Eigen::VectorXd::Zero(d), Eigen::MatrixXd::Zero(d, s.dim()),
                offsets.sigma * offsets.sigma * Eigen::MatrixXd::Identity(d, d)};
  w.value.head(b) = value;
  w.cross.topRows(b) = cross;
  w.cov.topLeftCorner(b, b) = cov;
  return w;
}
}  // namespace

InitOutcome initialise_cooperative(FilterState& s, int cam_a, const CameraRig& commanded_a,
                                   const Eigen::Vector2d& uv_a, int cam_b,
                                   const CameraRig& commanded_b, const Eigen::Vector2d& uv_b,
                                   const InitialisationSettings& cfg,
                                   const MeasurementNoiseSettings& noise) {
  const CameraRig rig_a = estimated_rig(s.x, s.gimbal(cam_a), commanded_a);
  const CameraRig rig_b = estimated_rig(s.x, s.gimbal(cam_b), commanded_b);
  const int pa = FilterState::cam_pos(cam_a), pb = FilterState::cam_pos(cam_b);
  const Eigen::Vector3d x_a = s.x.segment<3>(pa), x_b = s.x.segment<3>(pb);
  auto t = triangulate_two_views(rig_a, x_a, uv_a, rig_b, x_b, uv_b);
  if (!t) return {std::nullopt, "degenerate"};
  const Eigen::Vector3d pC_a = rig_a.R_CW * (t->point - x_a), pC_b = rig_b.R_CW * (t->point - x_b);
  if (pC_a.z() <= 0 || pC_b.z() <= 0) return {std::nullopt, "negative depth"};
  if (pC_a.z() < cfg.min_depth_m || pC_b.z() < cfg.min_depth_m) return {std::nullopt, kTooClose};
  if (t->parallax_rad < cfg.min_parallax_deg * kPi / 180) return {std::nullopt, kLowParallax};
  if (!(t->reprojection_px <= cfg.max_reprojection_px)) return {std::nullopt, "reprojection"};

  // eq. 52: P_new = J diag(P, R) J^T with J = [d/dx_c^a, d/dx_c^b | d/d(uv_a, uv_b)].
  const Eigen::Matrix<double, 3, 2> Jza = t->J.block<3, 2>(0, 6), Jzb = t->J.block<3, 2>(0, 8);
  std::vector<StateDependence> deps = {{pa, t->J.block<3, 3>(0, 0)}, {pb, t->J.block<3, 3>(0, 3)}};
  // An estimated gimbal error turns the observed ray as a pixel shift would:
  // d uv = -(d uv / d a) d a, with d uv / d a taken along the observed pixel's ray.
  auto ray = [](const CameraRig& rig, const Eigen::Vector2d& uv) {
    const Eigen::Vector2d xn = rig.model.unproject_normalised(uv);
    return Eigen::Vector3d(xn.x(), xn.y(), 1.0);
  };
  if (const int g = s.gimbal(cam_a); g >= 0)
    deps.push_back({g, -Jza * pixel_gimbal_jacobian(rig_a.model, s.x(g), ray(rig_a, uv_a))});
  if (const int g = s.gimbal(cam_b); g >= 0)
    deps.push_back({g, -Jzb * pixel_gimbal_jacobian(rig_b.model, s.x(g), ray(rig_b, uv_b))});
  const Eigen::Matrix3d pixel_cov = Jza * pixel_covariance(rig_a, pC_a, noise.pixel_sigma.value) * Jza.transpose() +
                                    Jzb * pixel_covariance(rig_b, pC_b, noise.pixel_sigma.value) * Jzb.transpose();
  const auto [cross, cov] = augmented_covariance(s, deps, pixel_cov);
  if (!(noise.pixel_offset_sigma.value > 0)) return {s.add_landmark(LandmarkKind::Euclidean, t->point, cross, cov), ""};

  // With pixel offsets: the point was triangulated from uv_b - o_b with o_b ~ N(0, sigma^2 I), so
  // d point / d o_b = -Jzb. Camera b's offsets are states from here on; the other cameras' are
  // stated when they first observe the point.
  const double var = noise.pixel_offset_sigma.value * noise.pixel_offset_sigma.value;
  const PixelOffsets offsets{cam_a, std::uint64_t{1} << cam_b, noise.pixel_offset_sigma.value};
  auto w = append_pixel_offsets(s, t->point, cross, cov, offsets);
  const int ob = 3;  // camera b's offsets, the only ones, right after the point
  w.cov.topLeftCorner<3, 3>() += var * Jzb * Jzb.transpose();
  w.cov.block<3, 2>(0, ob) = -var * Jzb;
  w.cov.block<2, 3>(ob, 0) = -var * Jzb.transpose();
  return {s.add_landmark(LandmarkKind::Euclidean, w.value, w.cross, w.cov, offsets), ""};
}

Vector6d inverse_depth_from_pixel(const CameraRig& cam, const Eigen::Vector3d& x_c,
                                  const Eigen::Vector2d& uv, double rho,
                                  Eigen::Matrix<double, 6, 5>* J) {
  const Eigen::Vector2d xn = cam.model.unproject_normalised(uv);
  const Eigen::Vector3d ray_W = cam.R_CW.transpose() * Eigen::Vector3d(xn.x(), xn.y(), 1.0);
  Eigen::Matrix<double, 2, 3> Jang;
  const Eigen::Vector2d ang = inverse_depth_angles(ray_W, &Jang);
  Vector6d y;
  y << x_c, ang, rho;
  if (J) {
    Eigen::Matrix2d Jd;
    cam.model.distort_normalised(xn, &Jd);  // d uv / d xn
    J->setZero();
    J->block<3, 3>(0, 0).setIdentity();
    J->block<2, 2>(3, 3) = Jang * cam.R_CW.transpose().leftCols<2>() * Jd.inverse();
  }
  return y;
}

InitOutcome initialise_inverse_depth(FilterState& s, int cam, const CameraRig& commanded,
                                     const Eigen::Vector2d& uv, const InitialisationSettings& cfg,
                                     const MeasurementNoiseSettings& noise) {
  const CameraRig rig = estimated_rig(s.x, s.gimbal(cam), commanded);
  const int pc = FilterState::cam_pos(cam);
  Eigen::Matrix<double, 6, 5> J;
  const Vector6d y = inverse_depth_from_pixel(rig, s.x.segment<3>(pc), uv, cfg.inverse_depth_rho, &J);
  // The anchor is the camera position: it inherits the camera's rows of P.
  std::vector<StateDependence> deps = {{pc, J.leftCols<3>()}};
  const Eigen::Matrix<double, 6, 2> Juv = J.rightCols<2>();
  const Eigen::Vector2d xn = rig.model.unproject_normalised(uv);
  const Eigen::Vector3d ray_C(xn.x(), xn.y(), 1.0);
  if (const int g = s.gimbal(cam); g >= 0)
    deps.push_back({g, -Juv * pixel_gimbal_jacobian(rig.model, s.x(g), ray_C)});
  Eigen::Matrix<double, 6, 6> pixel_cov = Juv * pixel_covariance(rig, ray_C, noise.pixel_sigma.value) * Juv.transpose();
  pixel_cov(5, 5) = cfg.inverse_depth_sigma * cfg.inverse_depth_sigma;  // the depth prior, independent of the state
  const auto [cross, cov] = augmented_covariance(s, deps, pixel_cov);
  if (!(noise.pixel_offset_sigma.value > 0) || s.num_cameras() < 2)
    return {s.add_landmark(LandmarkKind::InverseDepth, y, cross, cov), ""};
  // The other cameras' offsets are stated when they first observe it (this pixel has none).
  return {s.add_landmark(LandmarkKind::InverseDepth, y, cross, cov, {cam, 0, noise.pixel_offset_sigma.value}), ""};
}

InitOutcome initialise_cooperative_inverse_depth(FilterState& s, int cam_a, const CameraRig& commanded_a,
                                                 const Eigen::Vector2d& uv_a, int cam_b,
                                                 const CameraRig& commanded_b,
                                                 const Eigen::Vector2d& uv_b,
                                                 const InitialisationSettings& cfg,
                                                 const MeasurementNoiseSettings& noise,
                                                 double gate_probability) {
  InitOutcome r = initialise_inverse_depth(s, cam_a, commanded_a, uv_a, cfg, noise);
  if (!r.id) return r;
  s.state_pixel_offsets({{*r.id, cam_b}});
  const LandmarkSlot* lm = s.find(*r.id);
  const int rho = lm->offset + 5;
  // One iterated-EKF step: camera b's projection is linearised at the pair's triangulated inverse
  // depth rather than at the prior's, whose pixel can be tens of pixels off; the prior mean stays
  // (the innovation is taken as z - h(x_t) - H (x - x_t)), so the pixel is not counted twice.
  double rho_lin = s.x(rho);
  const CameraRig rig_a = estimated_rig(s.x, s.gimbal(cam_a), commanded_a);
  const CameraRig rig_b = estimated_rig(s.x, s.gimbal(cam_b), commanded_b);
  const Eigen::Vector3d x_a = s.x.segment<3>(FilterState::cam_pos(cam_a));
  if (auto t = triangulate_two_views(rig_a, x_a, uv_a, rig_b, s.x.segment<3>(FilterState::cam_pos(cam_b)), uv_b))
    if (const double d = (t->point - x_a).norm(); d > 0 && (rig_a.R_CW * (t->point - x_a)).z() > 0)
      rho_lin = 1.0 / d;
  const double rho_prior = s.x(rho);
  s.x(rho) = rho_lin;
  std::optional<Measurement> m = landmark_measurement(s, *lm, cam_b, commanded_b, uv_b, noise.pixel_sigma.value);
  s.x(rho) = rho_prior;
  if (m)
    for (const auto& b : m->blocks)
      if (b.col == lm->offset) m->h += b.H.col(5) * (rho_prior - rho_lin);
  const bool compatible = m && update_with_gated_measurements(s, {*m}, gate_probability).front();
  lm = s.find(*r.id);
  if (compatible && s.x(lm->offset + 5) > 0) return r;
  s.remove_landmark(*r.id);
  return {std::nullopt, compatible ? "negative depth" : "second view incompatible"};
}

int convert_linear_landmarks(FilterState& s, int cam, double threshold) {
  const Eigen::Vector3d x_c = s.x.segment<3>(FilterState::cam_pos(cam));
  std::vector<LandmarkId> ready;
  for (const auto& lm : s.landmarks()) {
    if (lm.kind != LandmarkKind::InverseDepth) continue;
    const Vector6d y = s.x.segment<6>(lm.offset);
    const double sigma_rho = std::sqrt(std::max(0.0, s.P(lm.offset + 5, lm.offset + 5)));
    if (y(5) > 0 && linearity_index(y, sigma_rho, x_c) < threshold) ready.push_back(lm.id);
  }
  for (LandmarkId id : ready) {
    const LandmarkSlot* lm = s.find(id);
    Eigen::Matrix<double, 3, 6> J;
    const Eigen::Vector3d p = inverse_depth_to_point(s.x.segment<6>(lm->offset), &J);
    s.convert_to_euclidean(id, p, J);
  }
  return static_cast<int>(ready.size());
}

}  // namespace wingman::slam
