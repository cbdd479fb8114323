// The scenario model (DESIGN.md §8): everything one run needs, loaded from one YAML file by
// load_scenario(). Defaults are the paper's section 7 setup; the YAML overrides them.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "geometry/camera.hpp"
#include "sim/control_spec.hpp"
#include "sim/frontend_spec.hpp"
#include "sim/world.hpp"

namespace wingman::sim {

// Measurement kinds a configuration switches on or off (Table 1).
enum class Sensor { Landmarks, LeadProjection, Altimeter, Range, Gps };
const char* to_string(Sensor s);
std::optional<Sensor> sensor_from_string(const std::string& s);

// Table 1 presets; Integrated feeds everything available at that instant.
enum class Config { C1, C2, C3, Integrated };
const char* to_string(Config c);
// The sensor set of a configuration preset.
std::vector<Sensor> sensors_of(Config c);

enum class EstimatorMode { MultiUav, SingleUav };
const char* to_string(EstimatorMode m);

// Synthetic: projections of a point field with the paper's noise; Rendered: rendered frames
// through the vision frontend (app/).
enum class MeasurementMode { Synthetic, Rendered };
const char* to_string(MeasurementMode m);

// Lead trajectory of eq. 66, shifted so that it starts at `initial_position`.
struct LeadTrajectorySpec {
  std::string type = "lemniscate";  // or "line": constant velocity
  double scale = 100.0;      // m
  double omega = 0.015;      // rad/s, of the planar lemniscate
  double z_amplitude = 2.0;  // m
  double z_omega = 0.03;     // rad/s
  Eigen::Vector3d velocity{1.5, 0, 0};  // m/s, of the line
};

struct LeadSpec {
  Eigen::Vector3d initial_position{0, 0, 0};
  LeadTrajectorySpec trajectory{};
  bool gps = true;  // the lead carries the GPS (eq. 7)
};

struct CameraSpec {
  double fx = 200.1, fy = 200.1, cx = 500, cy = 500;
  int width = 1000, height = 1000;
  geometry::Distortion distortion{};
  Eigen::Vector3d offset{0, 0, 0};  // d of eq. 59: camera position minus UAV position, world frame
  geometry::PinholeCamera camera() const {
    return geometry::PinholeCamera(fx, fy, cx, cy, width, height, distortion);
  }
};

struct UavSpec {
  std::string name;  // uav1, uav2, ...
  Eigen::Vector3d initial_position{0, 0, 15};
  CameraSpec camera{};
  bool sees_lead = false;  // produces lead projections (eq. 5) when the configuration has them
  bool altimeter = false;  // eq. 8
  bool range = false;      // eq. 9, to the lead
};

// Truth noise: what the simulated sensors add.
struct NoiseSpec {
  double pixel_sigma = 3.0;
  // A constant offset per camera and landmark (N(0, sigma^2) per axis, drawn once from the seed)
  // on top of the white pixel_sigma: a real detector puts a corner at much the same wrong spot in
  // every frame of a track (rendered frames: about half the error variance, docs/results.md).
  // 0 (the paper's white noise) by default.
  double pixel_bias_sigma = 0.0;
  double gps_sigma = 1.5;
  double altimeter_sigma = 0.5;
  double range_sigma = 0.5;
  double ahrs_yaw_sigma = 0.05;
  double outlier_fraction = 0.05;              // per camera, of the landmark correspondences
  double cooperative_outlier_fraction = 0.05;  // of the cross-UAV matches
  double outlier_max_px = 15.0;                // error norm uniform in [0, outlier_max_px]
  double gimbal_amplitude = 0.04;              // rad, e_r = A sin(w t)
  double gimbal_omega = 0.3;                   // rad/s
  // false: the paper's e_r for every camera about both axes (DESIGN.md §2). true: A sin(w t + phi)
  // with phi drawn per camera and axis from the seed, so that Monte Carlo runs see independent
  // gimbal errors, as the filter's model assumes, instead of one realisation every run.
  bool gimbal_random_phase = false;
  // Random acceleration the true agents carry on top of their curve, drawn per step from the
  // filter's own process model (eq. 34: v += a dt; agent i's a = a_common + a_i), so that a
  // Monte Carlo NEES test meets its premise: a truth that realises the noise the filter assumes.
  // All zero (the paper's deterministic eq. 66) by default.
  struct Motion {
    double accel_sigma_lead = 0, accel_sigma_uav = 0, accel_sigma_common = 0;  // m/s^2
    bool any() const { return accel_sigma_lead > 0 || accel_sigma_uav > 0 || accel_sigma_common > 0; }
  } motion;
};

// Static 3D points scattered over the ground below the flight (synthetic mode).
struct LandmarkFieldSpec {
  double density = 0.02;      // points per m^2
  double ground_height = 0.0;  // m, mean height of the ground
  double height_spread = 2.0;  // m, heights uniform in ground_height +- spread/2
  double margin = 60.0;        // m, beyond the flight's horizontal extent
};

// A time window with a configuration; `add` and `remove` adjust its preset.
struct Phase {
  std::string name;
  double t_start = 0, t_end = 0;
  Config config = Config::C1;
  std::vector<Sensor> add, remove;
};

// A sensor switched off for a window; agent empty means every agent carrying it.
struct Outage {
  Sensor sensor = Sensor::Gps;
  double t_start = 0, t_end = 0;
  std::string agent;
};

struct EstimatorSpec {
  EstimatorMode mode = EstimatorMode::MultiUav;
  std::string single_uav = "uav1";  // whose camera the single-UAV baseline uses
  // Process noise: white acceleration (eq. 34), m/s^2.
  double accel_sigma_lead = 0.05;
  double accel_sigma_uav = 0.05;
  // An acceleration every agent shares (formation flight), on top of the two above.
  double accel_sigma_common = 0;
  // > 0 (both): the shared acceleration is a state, Gauss-Markov with this std and correlation time.
  double common_accel_state_sigma = 0, common_accel_state_time_constant = 0;
  // Measurement noise the filter assumes (R); may differ from the truth's.
  double pixel_sigma = 3.0;
  // > 0: every cooperative landmark carries each other camera's constant pixel offset from the
  // camera that initialised it, prior sigma this (px per axis); 0: pixel errors are white.
  double pixel_offset_sigma = 0.0;
  double gps_sigma = 1.5;
  double altimeter_sigma = 0.5;
  double range_sigma = 0.5;
  // Gimbal pointing noise about the camera's x and y axes that the filter assumes (rad); the
  // truth's gimbal error is never given to it. 0 trusts R_CW exactly.
  double orientation_sigma = 0.0;
  // Correlation time (s) of that pointing error. > 0: the filter estimates each camera's error as
  // a Gauss-Markov state; 0: it treats it as white noise, marginalised in every update.
  double orientation_time_constant = 0.0;
  // Initial uncertainty of the agents (the paper: known exactly).
  double initial_position_sigma = 1e-3;
  double initial_velocity_sigma = 1e-3;
  // false: the filter starts at the truth exactly. true: at the truth plus a draw of those sigmas
  // (seeded), so that the initial error is a sample of the initial covariance, as a Monte Carlo
  // NEES test assumes; started exactly, the NEES sits below its bounds until the filter has
  // forgotten its exact start (docs/results.md).
  bool draw_initial_error = false;
  // Robustness.
  double gate_probability = 0.999;  // chi^2 gate on each innovation
  bool one_point_ransac = true;
  double ransac_inlier_px = 4.0;       // low-innovation inlier threshold (Civera et al. 2010)
  double ransac_success_probability = 0.99;
  int ransac_max_hypotheses = 100;
  // Map.
  int max_landmarks = 150;
  int target_landmarks_per_camera = 25;
  int max_misses = 5;  // consecutive predicted-visible frames without an accepted match
  double image_margin_px = 10.0;
  // Cooperative initialisation (eq. 47-52).
  double min_parallax_deg = 3.0;
  double max_reprojection_px = 10.0;
  // A pair that triangulates nearer than this to either camera (m, along its optical axis) is
  // rejected as a wrong match; 0 keeps every point in front of both cameras.
  double min_depth_m = 0.0;
  // A pair under min_parallax_deg becomes an inverse-depth landmark anchored at the first camera
  // and corrected with the second pixel, instead of being rejected.
  bool low_parallax_inverse_depth = false;
  // Multi-UAV: a camera that cooperative matching leaves under target_per_camera initialises the
  // rest from its own pixels in inverse depth, as the single-UAV baseline does. Not the paper's
  // method (section 5.2 initialises cooperatively only), so off by default.
  bool monocular_fill = false;
  // Single-UAV inverse-depth initialisation (Montiel et al. 2006, Civera et al. 2008).
  double inverse_depth_rho = 0.05;    // 1/m
  double inverse_depth_sigma = 0.04;  // 1/m
  double linearity_threshold = 0.1;
};

struct Scenario {
  std::string source_path;  // the YAML it came from
  std::string name;
  std::string variant;  // name of the variant this instance is, or empty
  double duration = 210.0;
  double rate = 10.0;
  std::uint64_t seed = 1;
  MeasurementMode measurements = MeasurementMode::Synthetic;
  LeadSpec lead{};
  std::vector<UavSpec> uavs;
  NoiseSpec noise{};
  LandmarkFieldSpec field{};
  std::vector<Phase> phases;
  std::vector<Outage> outages;
  EstimatorSpec estimator{};
  ControlSpec control{};  // enabled: closed loop (section 6)
  WorldSpec world{};  // what `wingman render` draws (sim/world.hpp)
  FrontendSpec frontend{};  // rendered measurements: the vision frontend's settings

  double dt() const { return 1.0 / rate; }
  int num_steps() const;  // steps after t = 0
  // Index of the phase containing t, or -1.
  int phase_at(double t) const;
  // Whether a sensor kind is fed at time t for an agent ("lead" or a UAV name).
  bool sensor_active(Sensor s, double t, const std::string& agent) const;
  int uav_index(const std::string& name) const;  // -1 when absent
  bool closed_loop() const { return control.enabled; }
};

// A malformed scenario: the message names file:line and the key.
class ScenarioError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Loads and validates a scenario. A file with `variants:` yields one Scenario per variant
// (each the base with that variant's overrides); otherwise exactly one.
std::vector<Scenario> load_scenarios(const std::string& path);
// Same, from YAML text; `origin` stands for the file name in messages.
std::vector<Scenario> parse_scenarios(const std::string& yaml_text, const std::string& origin);

}  // namespace wingman::sim
