#include "app/pipeline/camera_imaging.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/shutter.hpp"
#include "sim/world.hpp"

namespace wingman::app {

namespace {

// Camera uav's pose dt after t: its state at t carried on at constant acceleration, the gimbal's
// own rotation.
geometry::CameraPose pose_after(const sim::Truth& truth, int uav, double t, const sim::KinematicState& k, double dt) {
  return {truth.camera_R_CW(uav, t + dt), k.position + k.velocity * dt + 0.5 * k.acceleration * dt * dt};
}

// Image rows between the knots of a rolling shutter drawn in one pass (render::CameraView::rows):
// the pose's path over 16 rows is a line to within a micrometre and a microradian (a few hundred
// microseconds of constant acceleration and gimbal motion).
constexpr int kRowsPerKnot = 16;
// Pixels between the samples of the middle image that predict the exposure's image motion.
constexpr int kSmearGridPx = 25;

}  // namespace

geometry::CameraPose true_centre_pose(const sim::Truth& truth, int uav, double t) {
  return pose_after(truth, uav, t, truth.camera(uav, t), 0);
}

geometry::FramePoses true_poses(const sim::Scenario& scn, const sim::Truth& truth, int uav, double t) {
  const sim::CameraSpec& c = scn.uavs[uav].camera;
  const sim::KinematicState k = truth.camera(uav, t);
  if (!c.shutter.rolling()) return geometry::FramePoses(pose_after(truth, uav, t, k, 0));
  std::vector<geometry::CameraPose> rows(static_cast<std::size_t>(c.height));
  for (int r = 0; r < c.height; ++r)
    rows[r] = pose_after(truth, uav, t, k, render::row_time(c.shutter, r, c.height));
  return geometry::FramePoses(pose_after(truth, uav, t, k, 0), std::move(rows));
}

void describe_shutter(const sim::CameraSpec& camera, datasets::CameraInfo& info) {
  const sim::ShutterSpec& s = camera.shutter;
  info.rolling = s.rolling();
  info.exposure_s = camera.sensor.initial_exposure(s.exposure);
  info.line_delay_s = s.line_delay;
  info.top_to_bottom = s.readout == sim::ShutterSpec::Readout::TopToBottom;
  info.sensor.clear();
  const sim::SensorSpec& n = camera.sensor;
  if (!n.physical()) return;
  info.sensor = {{"full_well_e", n.full_well},       {"reference_exposure_s", n.reference_exposure},
                 {"read_noise_e", n.read_noise},     {"dark_current_e_per_s", n.dark_current},
                 {"prnu", n.prnu},                   {"dsnu_e", n.dsnu},
                 {"bits", n.bits},                   {"gamma", n.gamma},
                 {"gain", n.gain},                   {"vignetting", n.vignetting},
                 {"auto_exposure", n.auto_exposure.enabled ? 1.0 : 0.0}};
}

CameraImaging::CameraImaging(const sim::Scenario& scn, int uav)
    : scn_(scn),
      uav_(uav),
      model_(scn.uavs[uav].camera.camera()),
      haze_(scn.world.light.haze_visibility > 0
                ? std::optional<render::Haze>(std::in_place, model_, scn.world.light.haze_visibility, scn.world.image.sky)
                : std::nullopt),
      sensor_(scn.uavs[uav].camera.sensor, scn.uavs[uav].camera.shutter.exposure, model_, scn.seed,
              scn.uavs[uav].name),
      effects_(scn.world.image, scn.seed, scn.uavs[uav].name) {}

double CameraImaging::exposure() const {
  return sensor_.physical() ? sensor_.next().exposure_s : scn_.uavs[uav_].camera.shutter.exposure;
}

bool CameraImaging::instant() const {
  const auto& s = scn_.uavs[uav_].camera.shutter;
  return !s.rolling() && (exposure() == 0 || s.subframes == 1);
}

bool CameraImaging::per_pixel() const {
  return instant() && !sensor_.physical() && scn_.world.image.blur_sigma == 0 && model_.distortion().is_zero();
}

TakenFrame CameraImaging::retake(const sim::Truth& truth, double t, const Draw& draw) {
  if (!per_pixel()) throw std::logic_error("CameraImaging::retake: the camera's imaging has state of its own");
  const auto at = std::find_if(effects_before_.begin(), effects_before_.end(),
                               [&](const auto& e) { return std::abs(e.first - t) < 1e-9; });
  if (at == effects_before_.end())
    throw std::logic_error("CameraImaging::retake: no frame at t = " + std::to_string(t) + " among the last two");
  const render::ImageEffects now = effects_;
  effects_ = at->second;
  TakenFrame f = draw_frame(truth, t, draw);
  effects_ = now;
  return f;
}

TakenFrame CameraImaging::take(const sim::Truth& truth, double t, const Draw& draw) {
  effects_before_.emplace_back(t, effects_);
  if (effects_before_.size() > 2) effects_before_.pop_front();
  return draw_frame(truth, t, draw);
}

std::vector<render::RowKnot> CameraImaging::knots(const sim::Truth& truth, double t, const sim::KinematicState& k,
                                                  double dt) const {
  const sim::ShutterSpec& s = scn_.uavs[uav_].camera.shutter;
  const int h = model_.height(), n = std::max(2, (h - 2) / kRowsPerKnot + 2);
  std::vector<render::RowKnot> out(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double at = dt + render::row_time(s, (h - 1.0) * i / (n - 1), h);
    out[i] = {pose_after(truth, uav_, t, k, at), sim::lead_pose(truth, t + at, scn_.world),
              sim::uav_body_poses(truth, t + at, scn_.world)};
  }
  return out;
}

double CameraImaging::predicted_smear(const sim::Truth& truth, double t, const sim::KinematicState& k, double exposure_s,
                                      const render::Frame& middle) const {
  const sim::ShutterSpec& s = scn_.uavs[uav_].camera.shutter;
  const int w = model_.width(), h = model_.height();
  const double half = exposure_s / 2;
  double worst = 0;
  // What is in the image at either end of the exposure (a body beside the camera, far out of
  // view, sweeps across the image plane).
  const Eigen::AlignedBox2d image(Eigen::Vector2d(-0.5, -0.5), Eigen::Vector2d(w - 0.5, h - 0.5));
  auto moved = [&](const geometry::CameraPose& a, const Eigen::Vector3d& pa, const geometry::CameraPose& b,
                   const Eigen::Vector3d& pb) {
    const auto ua = model_.project(a.to_camera(pa)), ub = model_.project(b.to_camera(pb));
    if (ua && ub && (image.contains(*ua) || image.contains(*ub))) worst = std::max(worst, (*ua - *ub).norm());
  };
  // The surface in view, still: each sample pixel's point from its row's pose at mid-exposure.
  for (int v = kSmearGridPx / 2; v < h; v += kSmearGridPx) {
    const double tr = render::row_time(s, v, h);
    const geometry::CameraPose mid = pose_after(truth, uav_, t, k, tr), a = pose_after(truth, uav_, t, k, tr - half),
                               b = pose_after(truth, uav_, t, k, tr + half);
    for (int u = kSmearGridPx / 2; u < w; u += kSmearGridPx) {
      const float z = middle.depth.at<float>(v, u);
      if (!(z > 0)) continue;
      const Eigen::Vector2d xn = model_.unproject_normalised(Eigen::Vector2d(u, v));
      const Eigen::Vector3d p = mid.R_CW.transpose() * (z * xn.homogeneous()) + mid.position;
      moved(a, p, b, p);
    }
  }
  // What moves of its own: the lead (its reference point and points a height away along and
  // across it, for its turning) and the team's bodies.
  const geometry::CameraPose a = pose_after(truth, uav_, t, k, -half), b = pose_after(truth, uav_, t, k, half);
  const sim::LeadPose la = sim::lead_pose(truth, t - half, scn_.world), lb = sim::lead_pose(truth, t + half, scn_.world);
  const double r = scn_.world.lead.height;
  for (const Eigen::Vector2d& off : {Eigen::Vector2d(0, 0), Eigen::Vector2d(r, 0), Eigen::Vector2d(-r, 0),
                                     Eigen::Vector2d(0, r), Eigen::Vector2d(0, -r)}) {
    auto at = [&](const sim::LeadPose& l) {
      const double c = std::cos(l.yaw), sn = std::sin(l.yaw);
      return Eigen::Vector3d(l.position + Eigen::Vector3d(c * off.x() - sn * off.y(), sn * off.x() + c * off.y(), 0));
    };
    moved(a, at(la), b, at(lb));
  }
  const auto ba = sim::uav_body_poses(truth, t - half, scn_.world), bb = sim::uav_body_poses(truth, t + half, scn_.world);
  for (std::size_t i = 0; i < std::min(ba.size(), bb.size()); ++i) moved(a, ba[i].position, b, bb[i].position);
  return worst;
}

TakenFrame CameraImaging::draw_frame(const sim::Truth& truth, double t, const Draw& draw) {
  const sim::ShutterSpec& shutter = scn_.uavs[uav_].camera.shutter;
  const sim::KinematicState k = truth.camera(uav_, t);
  const int w = model_.width(), h = model_.height();
  // With shadows, every camera of the team at this instant bounds the sun's map: they, and the
  // bands and rows of this frame, share one (render::CameraView::shadow_views).
  std::vector<sim::KinematicState> team;
  if (scn_.world.light.shadows)
    for (std::size_t j = 0; j < scn_.uavs.size(); ++j) team.push_back(truth.camera(static_cast<int>(j), t));
  auto view_at = [&](double dt) {
    render::CameraView v{model_, pose_after(truth, uav_, t, k, dt), t + dt, sim::uav_body_poses(truth, t + dt, scn_.world)};
    for (std::size_t j = 0; j < team.size(); ++j)
      v.shadow_views.emplace_back(scn_.uavs[j].camera.camera(), pose_after(truth, static_cast<int>(j), t, team[j], dt));
    return v;
  };
  const auto band = [&](double dt, int row0, int rows) {
    return draw(view_at(dt), sim::lead_pose(truth, t + dt, scn_.world), row0, rows);
  };
  const bool one_pass = shutter.rolling() && shutter.rows_per_band == 0;
  const auto subframe = [&](double dt) {
    if (!one_pass) return render::draw_in_bands(shutter, w, h, dt, band);
    render::CameraView view = view_at(dt);
    view.rows = knots(truth, t, k, dt);
    return draw(view, sim::lead_pose(truth, t + dt, scn_.world), 0, h);
  };
  const double exposure_s = exposure();
  TakenFrame out;
  out.frame = render::expose(exposure_s, subframe, [&](const render::Frame& middle) {
    return shutter.subframes == 1 ? 1 : render::subframes_for(shutter, predicted_smear(truth, t, k, exposure_s, middle));
  });
  out.poses = true_poses(scn_, truth, uav_, t);
  if (haze_) haze_->apply(out.frame);
  out.exposure = sensor_.apply(out.frame);
  effects_.apply(out.frame);
  return out;
}

}  // namespace wingman::app
