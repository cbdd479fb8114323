#include "app/pipeline/camera_imaging.hpp"

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

TakenFrame CameraImaging::draw_frame(const sim::Truth& truth, double t, const Draw& draw) {
  const sim::ShutterSpec& shutter = scn_.uavs[uav_].camera.shutter;
  const sim::KinematicState k = truth.camera(uav_, t);
  TakenFrame out;
  out.frame = render::expose(shutter, exposure(), model_.width(), model_.height(), [&](double dt, int row0, int rows) {
    return draw({model_, pose_after(truth, uav_, t, k, dt), t + dt, sim::uav_body_poses(truth, t + dt, scn_.world)},
                sim::lead_pose(truth, t + dt, scn_.world), row0, rows);
  });
  out.poses = true_poses(scn_, truth, uav_, t);
  if (haze_) haze_->apply(out.frame);
  out.exposure = sensor_.apply(out.frame);
  effects_.apply(out.frame);
  return out;
}

}  // namespace wingman::app
