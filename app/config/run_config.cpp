#include "app/config/run_config.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <fstream>
#include <stdexcept>

#include "app/config/derived_noise.hpp"
#include "io/atomic_file.hpp"
#include "sim/assets.hpp"
#include "sim/settings_yaml.hpp"
#include "sim/yaml_input.hpp"

namespace wingman::app {

namespace {

// The controller's settings, with sim's keys of the same map (read by sim into the scenario)
// read here into a copy nobody keeps, so that every key of the section is known to one reader.
struct ControlSection {
  control::SlidingModeSettings& settings;
  sim::ControlSpec sims{};
  template <class V>
  void visit(V& v) {
    settings.visit(v);
    sims.visit(v);
  }
};

// Where each key of the module sections was last set (paths relative to the section, e.g.
// "map.max_landmarks"), and in which file.
struct Provenance {
  std::map<std::string, std::map<std::string, sim::Loc>> keys;  // section -> path -> where
  const sim::Ctx* ctx = nullptr;
  const sim::Loc* find(const std::string& section, const std::string& path) const {
    const auto s = keys.find(section);
    if (s == keys.end()) return nullptr;
    const auto k = s->second.find(path);
    return k == s->second.end() ? nullptr : &k->second;
  }
};

void read_layer(const sim::SettingsLayer& layer, RunConfig& cfg, Provenance& prov) {
  sim::KeyLocations where;
  if (layer.section == "estimator")
    sim::read_settings(layer.ctx, layer.field, cfg.estimator, &where);
  else if (layer.section == "frontend")
    sim::read_settings(layer.ctx, layer.field, cfg.frontend, &where);
  else {
    ControlSection c{cfg.controller};
    sim::read_settings(layer.ctx, layer.field, c, &where);
  }
  auto& mine = prov.keys[layer.section];
  for (const auto& [path, loc] : where) mine[path.substr(layer.field.path.size() + 1)] = loc;
  prov.ctx = &layer.ctx;
}

[[noreturn]] void fail_at(const Provenance& prov, const RunConfig& cfg, const sim::Loc* loc,
                          const std::string& what) {
  if (loc && prov.ctx) prov.ctx->fail(*loc, what);
  throw sim::ScenarioError(fmt::format("{}: {}", cfg.source_path, what));
}

// Defaults that follow from the scenario: one UAV runs the single-UAV estimator, and the
// baseline's camera is the first UAV's unless uav1 exists.
void resolve_estimator(RunConfig& cfg, const Provenance& prov) {
  auto& e = cfg.estimator;
  const sim::Loc* mode = prov.find("estimator", "mode");
  const sim::Loc* single = prov.find("estimator", "single_uav");
  if (!mode) e.mode = cfg.uavs.size() == 1 ? slam::EstimatorMode::SingleUav : slam::EstimatorMode::MultiUav;
  if (!single && cfg.uav_index(e.single_uav) < 0) e.single_uav = cfg.uavs.front().name;
  if (cfg.uav_index(e.single_uav) < 0)
    fail_at(prov, cfg, single,
            fmt::format("'{}' is not a UAV of this scenario (UAVs: {})", e.single_uav, cfg.uav_names()));
  if (e.mode == slam::EstimatorMode::MultiUav && cfg.uavs.size() < 2)
    fail_at(prov, cfg, mode, fmt::format("mode multi needs at least 2 UAVs, the scenario has {}", cfg.uavs.size()));
  if (cfg.closed_loop() && e.mode == slam::EstimatorMode::SingleUav)
    fail_at(prov, cfg, mode,
            "closed loop (the control: section) needs mode multi: the controller of every UAV takes "
            "its position from the estimator");
  if (e.map.max_landmarks == 0) {
    const int cameras = static_cast<int>(cfg.filter_uavs().size());
    e.map.max_landmarks = e.map.landmark_cap(cameras);
    // The covariance grows as (6 max_landmarks)^2 doubles: the same bound as an explicit cap's.
    if (e.map.max_landmarks > 2000)
      fail_at(prov, cfg, prov.find("estimator", "map.max_landmarks_per_camera"),
              fmt::format("{} per camera for {} cameras is {} landmarks; at most 2000 (set max_landmarks)",
                          e.map.max_landmarks_per_camera, cameras, e.map.max_landmarks));
  }
  if (e.map.target_per_camera > e.map.max_landmarks) {
    if (const auto* t = prov.find("estimator", "map.target_per_camera"))
      fail_at(prov, cfg, t, fmt::format("must not exceed max_landmarks ({}), got {}", e.map.max_landmarks,
                                        e.map.target_per_camera));
    fail_at(prov, cfg, prov.find("estimator", "map.max_landmarks"),
            fmt::format("must be at least target_per_camera ({}), got {}", e.map.target_per_camera,
                        e.map.max_landmarks));
  }
}

// The estimator's noise keys left `auto` (app/config/derived_noise.hpp). A rendered run reads the
// frontend noise model only when it needs it, and a missing or malformed one is bad input at
// frontend.noise_model.
void derive_noise(RunConfig& cfg, const Provenance& prov) {
  derive_process_noise(cfg);
  const auto& r = cfg.estimator.measurement_noise;
  vision::FrontendNoiseModel model;
  std::string path;
  if (cfg.measurements == sim::MeasurementMode::Rendered && (r.pixel_sigma.automatic || r.pixel_offset_sigma.automatic)) {
    const sim::Loc* key = prov.find("frontend", "noise_model");
    try {
      path = sim::resolve_asset(cfg.frontend.noise_model, cfg.source_path, "frontend noise model");
      model = read_noise_model(path);
    } catch (const std::runtime_error& e) {  // the model's own ScenarioError, or not found
      fail_at(prov, cfg, key, fmt::format("frontend.noise_model: {}", e.what()));
    }
  }
  try {
    derive_pixel_noise(cfg, model, path);
  } catch (const std::invalid_argument& e) {
    fail_at(prov, cfg, prov.find("frontend", "detector"), e.what());
  }
  // The lead's pixel: a marker-free detector states its own error; a marker's or a panel's stays
  // `auto`, which is pixel_sigma (MeasurementNoiseSettings::lead_sigma).
  auto& lead = cfg.estimator.measurement_noise.lead_pixel_sigma;
  using K = vision::LeadDetectorKind;
  if (cfg.measurements != sim::MeasurementMode::Rendered) return;
  if (lead_detector(cfg) == K::Learned)
    lead.derive(cfg.frontend.learned_lead.pixel_sigma, "auto: frontend.learned_lead.pixel_sigma");
  else if (lead_detector(cfg) == K::Motion)
    lead.derive(cfg.frontend.motion_lead.pixel_sigma, "auto: frontend.motion_lead.pixel_sigma");
}

// Whether some camera in the filter (or the lead, for the GPS) carries the sensor.
bool carried(const RunConfig& cfg, sim::Sensor s) {
  if (s == sim::Sensor::Landmarks) return true;
  if (s == sim::Sensor::Gps) return cfg.lead.gps;
  for (int u : cfg.filter_uavs()) {
    const auto& uav = cfg.uavs[u];
    if ((s == sim::Sensor::LeadProjection && uav.sees_lead) || (s == sim::Sensor::Altimeter && uav.altimeter) ||
        (s == sim::Sensor::Range && uav.range))
      return true;
  }
  return false;
}

std::string carrier_key(sim::Sensor s) {
  switch (s) {
    case sim::Sensor::LeadProjection: return "uavs[i].sees_lead";
    case sim::Sensor::Altimeter: return "uavs[i].altimeter";
    case sim::Sensor::Range: return "uavs[i].range";
    default: return "lead.gps";
  }
}

// A configuration of Table 1 is defined by its sensors: a phase whose configuration needs one
// that nothing in the filter carries would run as another configuration, silently. The
// integrated configuration feeds whatever is carried, so it needs nothing.
void check_phase_sensors(const RunConfig& cfg) {
  for (const auto& p : cfg.phases) {
    if (p.config == sim::Config::Integrated) continue;
    std::vector<sim::Sensor> needed = sim::sensors_of(p.config);
    needed.insert(needed.end(), p.add.begin(), p.add.end());
    for (sim::Sensor s : needed) {
      if (std::find(p.remove.begin(), p.remove.end(), s) != p.remove.end() || carried(cfg, s)) continue;
      std::string why = "no UAV carries it";
      if (s == sim::Sensor::Gps) why = "the lead does not carry it";
      else if (cfg.single_uav())
        why = fmt::format("the single-UAV estimator's UAV '{}' does not carry it", cfg.estimator.single_uav);
      throw sim::ScenarioError(fmt::format(
          "{}:{}: {}: phase '{}' (configuration {}) needs {}, but {}; switch it on ({}: true) or add "
          "'remove: [{}]' to the phase to run without it",
          cfg.source_path, p.source_line, p.source, p.name, sim::to_string(p.config), sim::to_string(s), why,
          carrier_key(s), sim::to_string(s)));
    }
  }
}

// The lead detector's own checks: a marker or panel detector needs that cue in the world; the
// learned one needs its weights, which must load as a network of the expected shape.
void resolve_lead_detector(RunConfig& cfg, const Provenance& prov) {
  using K = vision::LeadDetectorKind;
  using Cue = sim::LeadModelSpec::Cue;
  const K kind = lead_detector(cfg);
  const sim::Loc* key = prov.find("frontend", "lead_detector");
  if (kind == K::Aruco && cfg.world.lead.cue != Cue::Aruco)
    fail_at(prov, cfg, key, "aruco finds the lead's marker: it needs world.lead.cue: aruco");
  if (kind == K::Panel && cfg.world.lead.cue != Cue::Panel)
    fail_at(prov, cfg, key, "panel finds the lead's colour panel: it needs world.lead.cue: panel");
  if (kind == K::Motion) {
    try {
      cfg.frontend.motion_lead.search.validate();
    } catch (const std::invalid_argument& e) {
      const sim::Loc* at = prov.find("frontend", "motion_lead.history");
      fail_at(prov, cfg, at ? at : prov.find("frontend", "motion_lead.references"), e.what());
    }
  }
  if (kind != K::Learned || cfg.measurements != sim::MeasurementMode::Rendered) return;
  const sim::Loc* weights = prov.find("frontend", "learned_lead.weights");
  try {
    cfg.lead_weights_path = sim::resolve_asset(cfg.frontend.learned_lead.weights, cfg.source_path,
                                               "lead detector weights");
    const vision::LearnedLeadDetector check(cfg.lead_weights_path, cfg.frontend.learned_lead.search);
  } catch (const std::runtime_error& e) {  // not found, or vision::LeadModelError
    fail_at(prov, cfg, weights, e.what());
  }
}

}  // namespace

vision::LeadDetectorKind lead_detector(const RunConfig& cfg) {
  using K = vision::LeadDetectorKind;
  if (cfg.frontend.lead_detector != K::Auto) return cfg.frontend.lead_detector;
  switch (cfg.world.lead.cue) {
    case sim::LeadModelSpec::Cue::Aruco: return K::Aruco;
    case sim::LeadModelSpec::Cue::Panel: return K::Panel;
    case sim::LeadModelSpec::Cue::None: return K::Learned;
  }
  return K::Aruco;
}

std::vector<int> RunConfig::filter_uavs() const {
  if (single_uav()) return {uav_index(estimator.single_uav)};
  std::vector<int> all(uavs.size());
  for (std::size_t j = 0; j < uavs.size(); ++j) all[j] = static_cast<int>(j);
  return all;
}

RunConfig compose(const sim::Scenario& scenario) {
  RunConfig cfg;
  static_cast<sim::Scenario&>(cfg) = scenario;
  Provenance prov;
  for (const auto& layer : scenario.settings_layers) read_layer(*layer, cfg, prov);
  resolve_estimator(cfg, prov);
  check_phase_sensors(cfg);
  derive_noise(cfg, prov);
  resolve_lead_detector(cfg, prov);
  return cfg;
}

std::vector<RunConfig> parse_run_configs(const std::string& yaml_text, const std::string& origin) {
  std::vector<RunConfig> out;
  for (const auto& s : sim::parse_scenarios(yaml_text, origin)) out.push_back(compose(s));
  return out;
}

std::vector<RunConfig> load_run_configs(const std::string& path) {
  std::vector<RunConfig> out;
  for (const auto& s : sim::load_scenarios(path)) out.push_back(compose(s));
  return out;
}

namespace {

void emit_phases(YAML::Emitter& out, const RunConfig& cfg) {
  sim::settings_detail::Emitter e(out);
  e.list("phases", cfg.phases, sim::kPhaseList);
  e.list("outages", cfg.outages, sim::kOutageList);
}

// The control: section: sim's keys, then the controller's.
struct ControlOut {
  sim::ControlSpec spec;
  control::SlidingModeSettings controller;
  template <class V>
  void visit(V& v) {
    spec.visit(v);
    controller.visit(v);
  }
};

void emit_control(YAML::Emitter& out, const RunConfig& cfg) {
  if (cfg.closed_loop()) sim::emit_settings(out, "control", ControlOut{cfg.control, cfg.controller});
}

}  // namespace

std::string config_yaml(const RunConfig& cfg) {
  YAML::Emitter out;
  out << YAML::Comment(fmt::format("Resolved configuration of {}{}: every key, defaults included; runs as a "
                                   "scenario of its own.",
                                   cfg.source_path, cfg.variant.empty() ? "" : ", variant " + cfg.variant))
      << YAML::Newline;
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << cfg.name;
  out << YAML::Key << "duration" << YAML::Value << sim::number_text(cfg.duration);
  out << YAML::Key << "rate" << YAML::Value << sim::number_text(cfg.rate);
  out << YAML::Key << "seed" << YAML::Value << cfg.seed;
  out << YAML::Key << "measurements" << YAML::Value << sim::to_string(cfg.measurements);
  sim::emit_settings(out, "lead", cfg.lead);
  out << YAML::Key << "uavs" << YAML::Value << YAML::BeginSeq;
  for (const auto& u : cfg.uavs) {
    sim::UavSpec copy = u;
    sim::settings_detail::Emitter e(out);
    out << YAML::BeginMap;
    copy.visit(e);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  sim::emit_settings(out, "noise", cfg.noise);
  sim::emit_settings(out, "landmarks", cfg.field);
  emit_phases(out, cfg);
  sim::emit_settings(out, "estimator", cfg.estimator);
  sim::emit_settings(out, "frontend", cfg.frontend);
  emit_control(out, cfg);
  sim::emit_settings(out, "world", cfg.world);
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

void write_config(const RunConfig& cfg, const std::filesystem::path& path) {
  io::write_file_atomic(path, config_yaml(cfg));
}

void limit_duration(RunConfig& cfg, double duration) {
  if (duration >= cfg.duration) return;
  cfg.duration = duration;
  auto cut = [&](auto& windows) {
    windows.erase(std::remove_if(windows.begin(), windows.end(),
                                 [&](const auto& w) { return w.t_start >= duration; }),
                  windows.end());
    for (auto& w : windows) w.t_end = std::min(w.t_end, duration);
  };
  cut(cfg.phases);
  cut(cfg.outages);
}

void copy_scenario(const sim::Scenario& scn, const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  fs::copy_file(scn.source_path, dir / "scenario.yaml");
  const auto& tr = scn.lead.trajectory;
  if (tr.type != "file") return;
  // The loader made the path absolute; the scenario file names it relative to its folder.
  const fs::path file(tr.file.value);
  const fs::path rel = file.lexically_relative(fs::absolute(scn.source_path).parent_path());
  if (rel.empty() || *rel.begin() == "..") return;
  fs::create_directories((dir / rel).parent_path());
  fs::copy_file(file, dir / rel);
}

}  // namespace wingman::app
