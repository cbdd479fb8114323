// The estimator's noise that a scenario leaves `auto` (slam/settings.hpp), derived before the run
// from what the scenario says, never from a run's truth or labels:
// - process noise from the path flown: the common acceleration from the lead's nominal curve, each
//   agent's own from how its nominal curve departs from the lead's (a formation that turns with
//   the lead), plus noise.motion's random accelerations and, in closed loop, the disturbance;
// - pixel noise from the truth's noise: section (synthetic) or from the frontend noise model for
//   the frontend's detector (rendered).
// Each derived value keeps a line saying where it came from, which config.yaml prints.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "app/config/run_config.hpp"
#include "eval/metrics/consistency.hpp"
#include "eval/metrics/run_record.hpp"
#include "vision/noise_model.hpp"

namespace wingman::app {

// Accelerations are bounded over windows of eval::kAccelerationWindowS (5 s): a turn of a waypoint
// path lasts a few seconds; the RMS over such a window, at its worst over the run, covers the
// turn without spreading it over the straight legs around it (eval::windowed_rms_bound).
// The least white acceleration an agent is given (m/s^2): a curve that does not accelerate still
// flies a little off its constant-velocity model (the gimbal's error, the discrete steps), and a
// filter with no process noise stops listening to its measurements.
inline constexpr double kAccelerationFloor = 0.05;

void derive_process_noise(RunConfig& cfg);
// `model_path` names the model in the derived values' origin. Throws std::invalid_argument when
// the model has no figures for the frontend's detector.
void derive_pixel_noise(RunConfig& cfg, const vision::FrontendNoiseModel& model, const std::string& model_path);

// Reads a frontend noise model file (sim::ScenarioError naming file:line:col and the key for a
// malformed one, an unknown detector or a calibrated detector missing a figure).
vision::FrontendNoiseModel read_noise_model(const std::string& path);
// The noise of the correspondences the filter accepted (label inliers with a true projection), by
// track of a camera and a landmark of at least kMinTrackObservations: the scatter about each
// track's mean (white) and the track means (constant offsets).
inline constexpr int kMinTrackObservations = 10;
vision::DetectorNoise track_noise(const std::vector<eval::TrackedCorrespondence>& corr);
// Writes one, as `wingman calibrate-frontend` does.
std::string noise_model_yaml(const vision::FrontendNoiseModel& model);

}  // namespace wingman::app
