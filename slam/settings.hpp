// The estimator's settings: the `estimator:` section of a scenario, defined here once. Each group
// is the section's map of the same name; its defaults are the values the shipped scenes are tuned
// with (docs/scenario.md lists them, and a test checks the two agree).
#pragma once

#include <cstdint>
#include <string>

#include "geometry/settings.hpp"

namespace wingman::slam {

using geometry::ge;
using geometry::gt;
using geometry::in;

// Multi: every UAV's camera in one filter (the paper's method). Single: one UAV's camera, the
// single-UAV baseline.
enum class EstimatorMode { MultiUav, SingleUav };
const char* to_string(EstimatorMode m);

// White accelerations of the constant-velocity model (eq. 34), m/s^2. `auto` (the default): from
// what the scenario flies (app/config/derived_noise.hpp): the common part from the lead's accelerations,
// each agent's own from its departure from them (a formation that turns with the lead, the noise
// of noise.motion, the closed loop's disturbance).
struct ProcessNoiseSettings {
  geometry::AutoNumber accel_sigma_lead{0.05}, accel_sigma_uav{0.05};
  // An acceleration every agent shares (formation flight), on top of each agent's own.
  geometry::AutoNumber accel_sigma_common{0.3};
  // Both > 0: the shared acceleration is a state, Gauss-Markov (Singer) with this std (m/s^2)
  // and correlation time (s), instead of white.
  double common_state_sigma = 0, common_state_time_constant = 0;
  bool common_acceleration_state() const { return common_state_sigma > 0 && common_state_time_constant > 0; }

  template <class V>
  void visit(V& v) {
    v("accel_sigma_lead", accel_sigma_lead, in(0, 100));
    v("accel_sigma_uav", accel_sigma_uav, in(0, 100));
    v("accel_sigma_common", accel_sigma_common, in(0, 100));
    v.section("common_acceleration_state", [&](auto& c) {
      c("sigma", common_state_sigma, ge(0));
      c("time_constant", common_state_time_constant, ge(0));
    });
  }
};

// The noise the filter assumes (R); it may differ from the truth's (the scenario's noise:).
struct MeasurementNoiseSettings {
  // px, per axis. `auto` (the default): synthetic runs take the truth's noise.pixel_sigma (the
  // sensor's specification), rendered runs the frontend noise model's figure for the detector.
  geometry::AutoNumber pixel_sigma{3.0};
  // > 0: every landmark carries, as states, the constant pixel offset from the camera that
  // initialised it of each other camera once that camera observes it, prior sigma this (px per
  // axis); 0: pixel errors are white. `auto`: synthetic
  // runs take sqrt(2) noise.pixel_bias_sigma (the difference of two cameras' offsets), rendered
  // runs the frontend noise model's.
  geometry::AutoNumber pixel_offset_sigma{0.0};
  // px, per axis, of the lead's pixel (x_h's projection). `auto`: pixel_sigma for a marker or a
  // panel (and in synthetic runs, where it stays `auto`); a marker-free detector's own figure
  // (frontend.learned_lead.pixel_sigma, frontend.motion_lead.pixel_sigma).
  geometry::AutoNumber lead_pixel_sigma{0.0};
  // The lead's sigma in use: pixel_sigma while lead_pixel_sigma is an `auto` no run resolved.
  double lead_sigma() const {
    return lead_pixel_sigma.automatic && lead_pixel_sigma.source.empty() ? pixel_sigma.value : lead_pixel_sigma.value;
  }
  double gps_sigma = 1.5, altimeter_sigma = 0.5, range_sigma = 0.5;  // m
  // Gimbal pointing error about the camera's x and y axes (rad). 0.028 is the rms of the paper
  // scenes' truth error 0.04 sin(0.3 t); 0 trusts R_CW exactly.
  double orientation_sigma = 0.028;
  // Its correlation time (s). > 0: each camera's error is a Gauss-Markov state; 0: white noise,
  // marginalised in every update.
  double orientation_time_constant = 20.0;
  bool gimbal_state() const { return orientation_sigma > 0 && orientation_time_constant > 0; }

  template <class V>
  void visit(V& v) {
    // The same ranges as the truth's noise (sim/scenario.hpp), for the same reason.
    // An assumed sigma of 0 would make the innovation covariance singular: the filter's sigmas
    // are > 0 (the truth's may be 0, a perfect sensor).
    v("pixel_sigma", pixel_sigma, in(0, 1000, true));
    v("pixel_offset_sigma", pixel_offset_sigma, in(0, 1000));
    v("lead_pixel_sigma", lead_pixel_sigma, in(0, 1000, true));
    v("gps_sigma", gps_sigma, in(0, 1e4, true));
    v("altimeter_sigma", altimeter_sigma, in(0, 1e4, true));
    v("range_sigma", range_sigma, in(0, 1e4, true));
    v("orientation_sigma", orientation_sigma, in(0, 1));
    v("orientation_time_constant", orientation_time_constant, ge(0));
  }
};

// The agents' initial uncertainty (the paper: known exactly).
struct InitialSigmaSettings {
  double position = 1e-3, velocity = 1e-3;  // m, m/s
  // false: the filter starts at the truth exactly. true: at the truth plus a draw of these sigmas
  // (seeded), so that the initial error is a sample of the initial covariance, as a Monte Carlo
  // NEES test assumes.
  bool draw = false;

  template <class V>
  void visit(V& v) {
    v("position", position, ge(0));
    v("velocity", velocity, ge(0));
    v("draw", draw);
  }
};

// Robustness of the updates: a chi^2 gate on each innovation, then 1-point RANSAC (Civera et al.
// 2010) over the landmark correspondences.
struct GatingSettings {
  double probability = 0.999;
  bool one_point_ransac = true;
  double ransac_inlier_px = 6.0;  // low-innovation inlier threshold
  double ransac_success_probability = 0.99;
  int ransac_max_hypotheses = 100;

  template <class V>
  void visit(V& v) {
    v("probability", probability, in(0, 1, true, true));
    v("one_point_ransac", one_point_ransac);
    v("ransac_inlier_px", ransac_inlier_px, gt(0));
    v("ransac_success_probability", ransac_success_probability, in(0, 1));
    v("ransac_max_hypotheses", ransac_max_hypotheses, in(1, 100000));
  }
};

struct MapSettings {
  // The filter's map holds at most max_landmarks; 0: max_landmarks_per_camera for each camera in
  // the filter, so that the cap grows with the team (a run's configuration prints it resolved).
  int max_landmarks = 0;
  int max_landmarks_per_camera = 75;
  int target_per_camera = 25;  // new landmarks while a camera sees fewer
  // The cap for a filter of `cameras` cameras.
  int landmark_cap(int cameras) const {
    return max_landmarks > 0 ? max_landmarks : max_landmarks_per_camera * cameras;
  }
  int max_misses = 5;          // consecutive predicted-visible frames without an accepted match
  double image_margin_px = 10.0;

  template <class V>
  void visit(V& v) {
    // The filter's covariance grows as (6 max_landmarks)^2 doubles: 2000 is 1.2 GB a copy.
    v("max_landmarks", max_landmarks, in(0, 2000));
    v("max_landmarks_per_camera", max_landmarks_per_camera, in(1, 2000));
    v("target_per_camera", target_per_camera, in(1, 2000));
    v("max_misses", max_misses, ge(1));
    v("image_margin_px", image_margin_px, ge(0));
  }
};

// New landmarks: cooperative (eq. 47-52) from two cameras' pixels, inverse depth from one.
struct InitialisationSettings {
  double min_parallax_deg = 8.0;
  double max_reprojection_px = 10.0;
  // A pair that triangulates nearer than this to either camera (m, along its optical axis) is a
  // wrong match; 0 keeps every point in front of both cameras.
  double min_depth_m = 0.0;
  // A pair under min_parallax_deg becomes an inverse-depth landmark anchored at the first camera
  // and corrected with the second pixel, instead of being rejected.
  bool low_parallax_inverse_depth = true;
  // Multi-UAV: a camera that cooperative matching leaves under target_per_camera initialises the
  // rest from its own pixels in inverse depth, as the single-UAV baseline does. Not the paper's
  // method (section 5.2 initialises cooperatively only), so off by default.
  bool monocular_fill = false;
  // Undelayed inverse-depth initialisation (Montiel et al. 2006, Civera et al. 2008), 1/m.
  double inverse_depth_rho = 0.05, inverse_depth_sigma = 0.04;
  double linearity_threshold = 0.1;  // an inverse-depth landmark under it becomes Euclidean

  template <class V>
  void visit(V& v) {
    v("min_parallax_deg", min_parallax_deg, in(0, 90, false, true));
    v("max_reprojection_px", max_reprojection_px, gt(0));
    v("min_depth_m", min_depth_m, ge(0));
    v("low_parallax_inverse_depth", low_parallax_inverse_depth);
    v("monocular_fill", monocular_fill);
    v("inverse_depth_rho", inverse_depth_rho, gt(0));
    v("inverse_depth_sigma", inverse_depth_sigma, ge(0));
    v("linearity_threshold", linearity_threshold, gt(0));
  }
};

// What a run does when the filter breaks down numerically (slam/health.hpp): stop with an error
// and write nothing, or record the failure in metrics.json and write the steps before it.
enum class OnNumericalFailure { Stop, Record };

struct EstimatorSettings {
  // Default: multi with two UAVs or more, single with one (the scenario reader decides).
  EstimatorMode mode = EstimatorMode::MultiUav;
  OnNumericalFailure on_numerical_failure = OnNumericalFailure::Stop;
  std::string single_uav = "uav1";  // whose camera the single-UAV baseline uses
  ProcessNoiseSettings process_noise{};
  MeasurementNoiseSettings measurement_noise{};
  InitialSigmaSettings initial_sigma{};
  GatingSettings gating{};
  MapSettings map{};
  InitialisationSettings initialisation{};

  template <class V>
  void visit(V& v) {
    v.choice("mode", mode, {{"multi", EstimatorMode::MultiUav}, {"single", EstimatorMode::SingleUav}});
    v("single_uav", single_uav);
    v.choice("on_numerical_failure", on_numerical_failure,
             {{"stop", OnNumericalFailure::Stop}, {"record", OnNumericalFailure::Record}});
    v.section("process_noise", [&](auto& s) { process_noise.visit(s); });
    v.section("measurement_noise", [&](auto& s) { measurement_noise.visit(s); });
    v.section("initial_sigma", [&](auto& s) { initial_sigma.visit(s); });
    v.section("gating", [&](auto& s) { gating.visit(s); });
    v.section("map", [&](auto& s) { map.visit(s); });
    v.section("initialisation", [&](auto& s) { initialisation.visit(s); });
  }
};

}  // namespace wingman::slam
