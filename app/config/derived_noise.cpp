#include "app/config/derived_noise.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <utility>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "eval/metrics/metrics.hpp"
#include "sim/settings_yaml.hpp"
#include "sim/truth.hpp"
#include "sim/yaml_input.hpp"

namespace wingman::app {

namespace {

// The nominal curves: the scenario's truth without noise.motion's random accelerations.
struct NominalAccelerations {
  std::vector<Eigen::Vector3d> lead;
  std::vector<std::vector<Eigen::Vector3d>> uav_departure;  // per filter UAV: a_uav - a_lead
};

NominalAccelerations nominal_accelerations(const RunConfig& cfg) {
  sim::Scenario nominal = cfg;
  nominal.noise.motion = {};
  const sim::OpenLoopTruth truth(nominal);
  NominalAccelerations out;
  const std::vector<int> uavs = cfg.filter_uavs();
  out.uav_departure.resize(uavs.size());
  const int steps = cfg.num_steps();
  for (int k = 0; k <= steps; ++k) {
    const double t = k * cfg.dt();
    const Eigen::Vector3d a_lead = truth.lead(t).acceleration;
    out.lead.push_back(a_lead);
    for (std::size_t j = 0; j < uavs.size(); ++j)
      out.uav_departure[j].push_back(truth.uav(uavs[j], t).acceleration - a_lead);
  }
  return out;
}

double quadrature(double a, double b) { return std::sqrt(a * a + b * b); }

}  // namespace

void derive_process_noise(RunConfig& cfg) {
  auto& q = cfg.estimator.process_noise;
  if (!q.accel_sigma_lead.automatic && !q.accel_sigma_uav.automatic && !q.accel_sigma_common.automatic) return;
  const NominalAccelerations acc = nominal_accelerations(cfg);
  const int window = std::max(1, static_cast<int>(std::lround(eval::kAccelerationWindowS * cfg.rate)));
  const auto& m = cfg.noise.motion;

  const double lead = eval::windowed_rms_bound(acc.lead, window);
  q.accel_sigma_common.derive(
      quadrature(std::max(lead, kAccelerationFloor), m.accel_sigma_common),
      fmt::format("auto: the lead's nominal acceleration, worst {} s RMS per axis {:.3g} (floor {}){}",
                  eval::kAccelerationWindowS, lead, kAccelerationFloor,
                  m.accel_sigma_common > 0 ? fmt::format(", with noise.motion's {}", m.accel_sigma_common) : ""));
  q.accel_sigma_lead.derive(
      quadrature(kAccelerationFloor, m.accel_sigma_lead),
      fmt::format("auto: the lead flies the common acceleration; floor {}{}", kAccelerationFloor,
                  m.accel_sigma_lead > 0 ? fmt::format(", with noise.motion's {}", m.accel_sigma_lead) : ""));

  double departure = 0;
  std::string worst_uav;
  const std::vector<int> uavs = cfg.filter_uavs();
  for (std::size_t j = 0; j < uavs.size(); ++j) {
    const double d = eval::windowed_rms_bound(acc.uav_departure[j], window);
    if (d >= departure) departure = d, worst_uav = cfg.uavs[uavs[j]].name;
  }
  // Closed loop: Delta_g (eq. 58) is a velocity disturbance of two sinusoids of at most 0.5 rad/s
  // (sim/closed_loop_truth.cpp); the UAVs' accelerations answer it, RMS bound * 0.5 / sqrt(2).
  double control = 0;
  if (cfg.closed_loop()) control = cfg.control.disturbance_bound.head<3>().cwiseAbs().maxCoeff() * 0.5 / std::sqrt(2.0);
  const double own = quadrature(quadrature(std::max(departure, kAccelerationFloor), m.accel_sigma_uav), control);
  q.accel_sigma_uav.derive(
      own, fmt::format("auto: the UAVs' departure from the lead's acceleration, worst {} s RMS per axis {:.3g} "
                       "({}; floor {}){}{}",
                       eval::kAccelerationWindowS, departure, worst_uav, kAccelerationFloor,
                       m.accel_sigma_uav > 0 ? fmt::format(", with noise.motion's {}", m.accel_sigma_uav) : "",
                       control > 0 ? fmt::format(", with the closed loop's disturbance {:.3g}", control) : ""));
}

void derive_pixel_noise(RunConfig& cfg, const vision::FrontendNoiseModel& model, const std::string& model_path) {
  auto& r = cfg.estimator.measurement_noise;
  if (!r.pixel_sigma.automatic && !r.pixel_offset_sigma.automatic) return;
  if (cfg.measurements != sim::MeasurementMode::Rendered) {
    // The truth's sensor specification; a synthetic pixel error of 0 is assumed as a small one.
    r.pixel_sigma.derive(std::max(cfg.noise.pixel_sigma, 0.01), "auto: noise.pixel_sigma");
    r.pixel_offset_sigma.derive(std::sqrt(2.0) * cfg.noise.pixel_bias_sigma,
                                "auto: sqrt(2) noise.pixel_bias_sigma");
    return;
  }
  const std::string detector = vision::to_string(cfg.frontend.features.kind);
  const vision::DetectorNoise& d = model.of(cfg.frontend.features.kind);
  if (!d.calibrated())
    throw std::invalid_argument(fmt::format(
        "frontend.detector: the frontend noise model {} has no figures for detector '{}'; calibrate it "
        "(wingman calibrate-frontend DATASET --out FILE, then frontend.noise_model: FILE) or set "
        "estimator.measurement_noise.pixel_sigma and pixel_offset_sigma",
        model_path, detector));
  const std::string from = fmt::format("auto: frontend noise model {}, detector {}", model_path, detector);
  r.pixel_sigma.derive(d.pixel_sigma, from);
  r.pixel_offset_sigma.derive(d.pixel_offset_sigma, from);
}

vision::DetectorNoise track_noise(const std::vector<eval::TrackedCorrespondence>& corr) {
  std::map<std::pair<int, std::int64_t>, std::vector<Eigen::Vector2d>> tracks;
  for (const auto& c : corr)
    if (c.accepted && !c.outlier && c.true_uv.allFinite()) tracks[{c.cam, c.landmark}].push_back(c.uv - c.true_uv);
  vision::DetectorNoise d;
  double scatter2 = 0, offset2 = 0;
  std::vector<double> norms;
  for (const auto& [key, errors] : tracks) {
    if (static_cast<int>(errors.size()) < kMinTrackObservations) continue;
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& e : errors) mean += e;
    mean /= static_cast<double>(errors.size());
    for (const auto& e : errors) {
      scatter2 += (e - mean).squaredNorm();
      norms.push_back(e.norm());
    }
    offset2 += mean.squaredNorm();
    d.observations += static_cast<int>(errors.size());
    d.tracks += 1;
  }
  if (d.tracks == 0) return d;
  // Per axis: two axes per observation; the scatter loses one mean per track.
  d.pixel_sigma = std::sqrt(scatter2 / (2.0 * std::max(1, d.observations - d.tracks)));
  d.track_offset_rms = std::sqrt(offset2 / (2.0 * d.tracks));
  // The filter's offset states hold one camera's offset against the initialising camera's.
  d.pixel_offset_sigma = std::sqrt(2.0) * d.track_offset_rms;
  const eval::Stats error = eval::summarise(std::move(norms));
  d.median_error_px = error.median;
  d.p95_error_px = error.p95;
  return d;
}

vision::FrontendNoiseModel read_noise_model(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw sim::ScenarioError(fmt::format("{}: cannot read the frontend noise model", path));
  std::stringstream ss;
  ss << in.rdbuf();
  const sim::Ctx ctx(path);
  YAML::Node root;
  try {
    root = YAML::Load(ss.str());
  } catch (const YAML::Exception& e) {
    ctx.fail(e.mark, "", fmt::format("YAML syntax error: {}", e.msg));
  }
  if (!root.IsMap()) throw sim::ScenarioError(fmt::format("{}: expected a map (made_by, detectors)", path));
  vision::FrontendNoiseModel model;
  sim::KeyLocations where;
  sim::read_settings(ctx, sim::Field{root, root.Mark(), ""}, model, &where);
  // A detector that is listed carries every figure the estimator takes.
  for (vision::DetectorKind kind : vision::kDetectorKinds) {
    const std::string section = fmt::format("detectors.{}", vision::to_string(kind));
    const auto s = where.find(section);
    if (s == where.end()) continue;
    for (const char* key : {"pixel_sigma", "pixel_offset_sigma", "observations"})
      if (!where.count(section + "." + key))
        ctx.fail(s->second, fmt::format("missing '{}' (a calibrated detector has pixel_sigma, "
                                        "pixel_offset_sigma and observations)", key));
  }
  return model;
}

std::string noise_model_yaml(const vision::FrontendNoiseModel& model) {
  YAML::Emitter out;
  out << YAML::Comment(
             "Frontend noise model (docs/frontend.md, noise model): per detector, the accepted correspondences'\n"
             "white pixel sigma and the difference of two cameras' constant track offsets, px per axis.")
      << YAML::Newline;
  out << YAML::BeginMap;
  vision::FrontendNoiseModel copy = model;
  out << YAML::Key << "made_by" << YAML::Value << copy.made_by;
  out << YAML::Key << "detectors" << YAML::Value << YAML::BeginMap;
  for (vision::DetectorKind kind : vision::kDetectorKinds) {
    vision::DetectorNoise& d = copy.of(kind);
    if (!d.calibrated()) continue;
    sim::settings_detail::Emitter e(out);
    e.section(vision::to_string(kind), [&](auto& v) { d.visit(v); });
  }
  out << YAML::EndMap << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace wingman::app
