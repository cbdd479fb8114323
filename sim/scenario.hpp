// The scenario model, sim's part of a run (docs/design.md, settings): truth, sensors, noise and
// world, loaded from one YAML file by load_scenarios(). Defaults are the paper's section 7 setup;
// the YAML overrides them. The sections other modules define are kept unread in settings_layers
// (app/config/run_config.hpp composes them).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "geometry/camera.hpp"
#include "geometry/settings.hpp"
#include "sim/camera_sensor.hpp"
#include "sim/control_spec.hpp"
#include "sim/sensors.hpp"
#include "sim/trajectory.hpp"
#include "sim/world.hpp"

namespace wingman::sim {

struct SettingsLayer;  // sim/yaml_input.hpp


// Synthetic: projections of a point field with the paper's noise; Rendered: rendered frames
// through the vision frontend (app/).
enum class MeasurementMode { Synthetic, Rendered };
const char* to_string(MeasurementMode m);

// The lead's path (docs/scenario.md, trajectories): the lemniscate of eq. 66, a line of constant
// velocity, timed waypoints, or a TUM or CSV trajectory file; shifted so that it starts at
// lead.initial_position (which defaults to the path's own start for waypoints and files).
struct LeadTrajectorySpec {
  std::string type = "lemniscate";  // line, waypoints, file
  double scale = 100.0;      // m
  double omega = 0.015;      // rad/s, of the planar lemniscate
  double z_amplitude = 2.0;  // m
  double z_omega = 0.03;     // rad/s
  Eigen::Vector3d velocity{1.5, 0, 0};  // m/s, of the line
  Waypoints waypoints{};                // [t, x, y, z] rows, of `waypoints`
  OptionalPath file;                    // of `file`: next to the scenario, or absolute
  std::string format = "auto";          // tum, csv, or auto: by the file's extension
  SplineEnds ends = SplineEnds::Rest;   // of the spline through waypoints or file samples
  // The spline of `waypoints` or `file`, built by the loader (immutable, shared by copies).
  std::shared_ptr<const SplinePath> path;

  template <class V>
  void visit(V& v) {
    v.choice("type", type, {{"lemniscate", std::string("lemniscate")}, {"line", std::string("line")},
                            {"waypoints", std::string("waypoints")}, {"file", std::string("file")}});
    v("scale", scale);
    v("omega", omega);
    v("z_amplitude", z_amplitude);
    v("z_omega", z_omega);
    v("velocity", velocity);
    v("waypoints", waypoints);
    v("file", file);
    v.choice("format", format, {{"auto", std::string("auto")}, {"tum", std::string("tum")}, {"csv", std::string("csv")}});
    v.choice("ends", ends, {{"rest", SplineEnds::Rest}, {"natural", SplineEnds::Natural}});
  }
  bool spline() const { return type == "waypoints" || type == "file"; }
};

// Open-loop UAVs keep their initial offset from the lead in the world frame, or in the lead's
// heading frame: a formation that turns with the lead's direction of travel.
enum class FormationFrame { World, Heading };

struct LeadSpec {
  Eigen::Vector3d initial_position{0, 0, 0};
  LeadTrajectorySpec trajectory{};
  bool gps = true;  // the lead carries the GPS (eq. 7)
  FormationFrame formation_frame = FormationFrame::World;

  template <class V>
  void visit(V& v) {
    v("initial_position", initial_position);
    v("gps", gps);
    v.choice("formation_frame", formation_frame, {{"world", FormationFrame::World}, {"heading", FormationFrame::Heading}});
    v.section("trajectory", [&](auto& t) { trajectory.visit(t); });
  }
};

struct CameraSpec {
  double fx = 200.1, fy = 200.1, cx = 500, cy = 500;
  int width = 1000, height = 1000;
  geometry::Distortion distortion{};
  Eigen::Vector3d offset{0, 0, 0};  // d of eq. 59: camera position minus UAV position, world frame
  ShutterSpec shutter{};
  SensorSpec sensor{};

  template <class V>
  void visit(V& v) {
    v("fx", fx, geometry::gt(0));
    v("fy", fy, geometry::gt(0));
    v("cx", cx);
    v("cy", cy);
    v("width", width, geometry::in(1, 16384));
    v("height", height, geometry::in(1, 16384));
    v("distortion", distortion);  // k1 k2 p1 p2 [k3]
    v("offset", offset);
    v.section("shutter", [&](auto& x) { shutter.visit(x); });
    v.section("sensor", [&](auto& x) { sensor.visit(x); });
    v.check("sensor", !sensor.physical() || shutter.exposure > 0 || sensor.auto_exposure.enabled,
            "a physical sensor needs shutter.exposure above 0 or auto_exposure.enabled");
  }
  // s from the first row's exposure start to the last row's end: what must fit in a frame interval.
  double frame_time() const {
    const double exposure = sensor.physical() && sensor.auto_exposure.enabled
                                ? std::max(shutter.exposure, sensor.auto_exposure.max_exposure)
                                : shutter.exposure;
    return exposure + (shutter.rolling() ? shutter.line_delay * (height - 1) : 0);
  }
  geometry::PinholeCamera camera() const {
    return geometry::PinholeCamera(fx, fy, cx, cy, width, height, distortion);
  }
};

// A UAV carries every sensor unless its entry switches one off, so that the configurations of
// Table 1 have what they are defined by.
struct UavSpec {
  std::string name;  // uav1, uav2, ...
  Eigen::Vector3d initial_position{0, 0, 15};
  CameraSpec camera{};
  bool sees_lead = true;  // produces lead projections (eq. 5) when the configuration has them
  bool altimeter = true;  // eq. 8
  bool range = true;      // eq. 9, to the lead

  template <class V>
  void visit(V& v) {
    v("name", name);  // required; [a-z0-9_]+, unique, not "lead"
    v("initial_position", initial_position);
    v("sees_lead", sees_lead);
    v("altimeter", altimeter);
    v("range", range);
    v.section("camera", [&](auto& c) { camera.visit(c); });
  }
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
  // false: the paper's e_r for every camera about both axes (docs/design.md, frames and conventions). true: A sin(w t + phi)
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
  // The IMU each UAV carries in a dataset (`wingman render`, imu0/): continuous-time white noise
  // and bias random walk in Kalibr's units, defaults EuRoC's ADIS16448 figures; initial biases
  // N(0, sigma^2) per axis. The estimator does not use an IMU; datasets carry it for other
  // systems.
  struct Imu {
    double rate = 200;                                 // Hz
    double gyroscope_noise_density = 1.6968e-4;        // rad/s/sqrt(Hz)
    double gyroscope_random_walk = 1.9393e-5;          // rad/s^2/sqrt(Hz)
    double accelerometer_noise_density = 2.0e-3;       // m/s^2/sqrt(Hz)
    double accelerometer_random_walk = 3.0e-3;         // m/s^3/sqrt(Hz)
    double gyroscope_initial_bias_sigma = 2e-3;        // rad/s
    double accelerometer_initial_bias_sigma = 2e-2;    // m/s^2
  } imu;

  template <class V>
  void visit(V& v) {
    // Past these a sensor measures nothing (a pixel error larger than any image, a GPS error of
    // 10 km), and the filter's covariance can no longer stay positive definite in double precision.
    v("pixel_sigma", pixel_sigma, geometry::in(0, 1000));
    v("pixel_bias_sigma", pixel_bias_sigma, geometry::in(0, 1000));
    v("gps_sigma", gps_sigma, geometry::in(0, 1e4));
    v("altimeter_sigma", altimeter_sigma, geometry::in(0, 1e4));
    v("range_sigma", range_sigma, geometry::in(0, 1e4));
    v("ahrs_yaw_sigma", ahrs_yaw_sigma, geometry::in(0, 10));
    v("outlier_fraction", outlier_fraction, geometry::in(0, 1));
    v("cooperative_outlier_fraction", cooperative_outlier_fraction, geometry::in(0, 1));
    v("outlier_max_px", outlier_max_px, geometry::in(0, 1e5));
    v("gimbal_amplitude", gimbal_amplitude);
    v("gimbal_omega", gimbal_omega);
    v("gimbal_random_phase", gimbal_random_phase);
    v.section("motion", [&](auto& m) {
      m("accel_sigma_lead", motion.accel_sigma_lead, geometry::in(0, 100));
      m("accel_sigma_uav", motion.accel_sigma_uav, geometry::in(0, 100));
      m("accel_sigma_common", motion.accel_sigma_common, geometry::in(0, 100));
    });
    v.section("imu", [&](auto& m) {
      m("rate", imu.rate, geometry::in(1, 10000));
      m("gyroscope_noise_density", imu.gyroscope_noise_density, geometry::in(0, 1));
      m("gyroscope_random_walk", imu.gyroscope_random_walk, geometry::in(0, 1));
      m("accelerometer_noise_density", imu.accelerometer_noise_density, geometry::in(0, 10));
      m("accelerometer_random_walk", imu.accelerometer_random_walk, geometry::in(0, 10));
      m("gyroscope_initial_bias_sigma", imu.gyroscope_initial_bias_sigma, geometry::in(0, 1));
      m("accelerometer_initial_bias_sigma", imu.accelerometer_initial_bias_sigma, geometry::in(0, 10));
    });
  }
};

// Static 3D points scattered over the ground below the flight (synthetic mode).
struct LandmarkFieldSpec {
  double density = 0.02;      // points per m^2
  double ground_height = 0.0;  // m, mean height of the ground
  double height_spread = 2.0;  // m, heights uniform in ground_height +- spread/2
  double margin = 60.0;        // m, beyond the flight's horizontal extent

  template <class V>
  void visit(V& v) {
    v("density", density, geometry::gt(0));
    v("ground_height", ground_height);
    v("height_spread", height_spread, geometry::ge(0));
    v("margin", margin, geometry::ge(0));
  }
};

// What is wrong with a window [from, to) of a phase or an outage (to must exceed from), a phase's
// name, or a phase's add and remove lists (the index of a sensor in both, else -1); "" when
// nothing is.
std::string window_problem(double from, double to);
std::string phase_name_problem(const std::string& name);
int added_and_removed(const std::vector<Sensor>& add, const std::vector<Sensor>& remove);

// A time window with a configuration; `add` and `remove` adjust its preset.
struct Phase {
  std::string name;
  double t_start = 0, t_end = 0;
  Config config = Config::C1;
  std::vector<Sensor> add, remove;
  std::string source;   // its key path in the file ("phases[1]"); empty for the default phase
  int source_line = 0;  // 1-based line of its entry; 0 for the default phase

  static Phase list_item(std::size_t i) {
    Phase p;
    p.name = "phase" + std::to_string(i + 1);
    return p;
  }
  template <class V>
  void visit(V& v) {
    v("name", name);
    v.check("name", phase_name_problem(name).empty(), phase_name_problem(name));
    v.required("from");
    v("from", t_start, geometry::ge(0));
    v.required("to");
    v("to", t_end);
    v.check("to", window_problem(t_start, t_end).empty(), window_problem(t_start, t_end));
    v.required("config");
    v("config", config);
    v("add", add);
    v("remove", remove);
    const int both = added_and_removed(add, remove);
    v.check("remove[" + std::to_string(both) + "]", both < 0,
            both < 0 ? "" : std::string("sensor '") + to_string(remove[static_cast<std::size_t>(both)]) +
                                "' is both added and removed");
  }
};
inline constexpr geometry::ListNames kPhaseList{"phases", "phase", 1};

// A sensor switched off for a window; agent empty means every agent carrying it.
struct Outage {
  Sensor sensor = Sensor::Gps;
  double t_start = 0, t_end = 0;
  std::string agent;

  template <class V>
  void visit(V& v) {
    v.required("sensor");
    v("sensor", sensor);
    v.required("from");
    v("from", t_start, geometry::ge(0));
    v.required("to");
    v("to", t_end);
    v.check("to", window_problem(t_start, t_end).empty(), window_problem(t_start, t_end));
    v.optional("agent", agent);
  }
};
inline constexpr geometry::ListNames kOutageList{"outages", "outage", 0};


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
  ControlSpec control{};  // enabled: closed loop (section 6)
  WorldSpec world{};  // what `wingman render` draws (sim/world.hpp)
  // Where the world section named its files, by key path ("world.lead.model"): 1-based line and
  // column; keys left at their defaults are absent (sim/assets.hpp, check_world_files).
  std::map<std::string, std::pair<int, int>> world_file_keys;
  // The YAML of the sections other modules define (estimator:, frontend:, the controller's keys
  // of control:), the base's first and then the variant's, for app/ to read into those modules'
  // own settings structs.
  std::vector<std::shared_ptr<const SettingsLayer>> settings_layers;

  double dt() const { return 1.0 / rate; }
  int num_steps() const;  // steps after t = 0
  // Index of the phase containing t, or -1.
  int phase_at(double t) const;
  // Whether a sensor kind is fed at time t for an agent ("lead" or a UAV name).
  bool sensor_active(Sensor s, double t, const std::string& agent) const;
  int uav_index(const std::string& name) const;  // -1 when absent
  std::string uav_names() const;                  // "uav1, uav2", for messages
  bool closed_loop() const { return control.enabled; }
};

// A malformed scenario: the message names file:line and the key.
class ScenarioError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Loads and validates the scenario's own sections (sim's: truth, sensors, noise, world); the
// sections other modules define are kept in settings_layers, unread (app/config/run_config.hpp reads them). A file with `variants:` yields one Scenario per variant
// (each the base with that variant's overrides); otherwise exactly one.
// A scenario file is refused past this size, before it is parsed.
inline constexpr std::size_t kMaxScenarioBytes = std::size_t{4} << 20;
std::vector<Scenario> load_scenarios(const std::string& path);
// Same, from YAML text; `origin` stands for the file name in messages.
std::vector<Scenario> parse_scenarios(const std::string& yaml_text, const std::string& origin);

}  // namespace wingman::sim
