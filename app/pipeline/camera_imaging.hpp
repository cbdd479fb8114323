// One UAV camera's imaging chain, shared by the SLAM loop's renderer and `wingman render`: the
// shutter (exposure blur, rolling shutter; render/shutter.hpp) over the true motion, the haze of the
// air (render/haze.hpp), the sensor
// (noise, response, auto-exposure; render/sensor.hpp) and the world's image effects. It returns
// the frame with the poses it was taken from (one per row under a rolling shutter), so that
// labels and datasets follow the effects exactly.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "datasets/dataset.hpp"
#include "geometry/frame_poses.hpp"
#include "render/effects.hpp"
#include "render/haze.hpp"
#include "render/renderer.hpp"
#include "render/sensor.hpp"
#include "sim/scenario.hpp"
#include "sim/truth.hpp"

namespace wingman::app {

struct TakenFrame {
  render::Frame frame;
  geometry::FramePoses poses;
  render::Exposure exposure;
};

// The poses camera `uav`'s frame at time t is taken from: the camera's state at t carried on at
// constant acceleration over the readout (a fraction of a step), the gimbal's own rotation.
geometry::FramePoses true_poses(const sim::Scenario& scn, const sim::Truth& truth, int uav, double t);
// Their centre alone: the camera's pose at t (FramePoses::centre()), without the rows.
geometry::CameraPose true_centre_pose(const sim::Truth& truth, int uav, double t);

// The shutter and sensor a dataset's cam0/sensor.yaml records.
void describe_shutter(const sim::CameraSpec& camera, datasets::CameraInfo& info);

class CameraImaging {
 public:
  // Draws rows [row0, row0 + rows) of the camera's image of the scene seen from `view` with the
  // lead at `lead` (a whole frame when rows is the image's height).
  using Draw = std::function<render::Frame(const render::CameraView& view, const render::LeadPose& lead,
                                           int row0, int rows)>;

  CameraImaging(const sim::Scenario& scn, int uav);
  // Camera `uav`'s frame at time t, drawn over the exposure and readout with the motion of
  // true_poses() and the lead's own.
  TakenFrame take(const sim::Truth& truth, double t, const Draw& draw);
  // The frame one of the last two take()s made at time t, drawn again by `draw` with the same
  // random draws of the image effects (a region frame that turned out to be needed whole, or
  // with more regions); later frames keep theirs. Only for per_pixel().
  TakenFrame retake(const sim::Truth& truth, double t, const Draw& draw);
  // A global shutter with no exposure time: one render at the frame's time, the same for every
  // run of a seed-free truth (a frame cache may hold it).
  bool instant() const;
  // An instant whose every pixel depends on its own rendered pixel alone (no blur, no physical
  // sensor, whose noise draws and auto-exposure depend on the others, no lens distortion): a
  // region of the frame is the same whether the rest is drawn or not.
  bool per_pixel() const;
  const geometry::PinholeCamera& model() const { return model_; }

 private:
  // The next frame's exposure time: the sensor's (auto-exposure's) when it is physical, the
  // shutter's otherwise.
  double exposure() const;
  TakenFrame draw_frame(const sim::Truth& truth, double t, const Draw& draw);
  // A rolling shutter's knots for a frame at t drawn in one pass at sub-frame offset dt (k: the
  // camera's state at t).
  std::vector<render::RowKnot> knots(const sim::Truth& truth, double t, const sim::KinematicState& k, double dt) const;
  // px the image moves over an exposure of exposure_s at t, at most: the surface the middle image
  // shows (its depth) reprojected from the camera's poses at the exposure's ends, and the lead and
  // the team's bodies moved along their own paths.
  double predicted_smear(const sim::Truth& truth, double t, const sim::KinematicState& k, double exposure_s,
                         const render::Frame& middle) const;

  const sim::Scenario& scn_;
  int uav_;
  geometry::PinholeCamera model_;
  std::optional<render::Haze> haze_;
  render::SensorModel sensor_;
  render::ImageEffects effects_;
  // The image effects as the last two take()s found them, with their times, for retake().
  std::deque<std::pair<double, render::ImageEffects>> effects_before_;
};

}  // namespace wingman::app
