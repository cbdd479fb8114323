// One run's configuration: sim's scenario (truth, sensors, noise, world) composed with the
// settings of the modules that run it, each defined once by its module (slam::EstimatorSettings,
// vision::FrontendSettings, control::SlidingModeSettings) and read straight from the scenario
// file's sections of the same names.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "control/sliding_mode.hpp"
#include "sim/scenario.hpp"
#include "slam/settings.hpp"
#include "vision/settings.hpp"

namespace wingman::app {

struct RunConfig : sim::Scenario {
  slam::EstimatorSettings estimator{};
  vision::FrontendSettings frontend{};
  control::SlidingModeSettings controller{};  // closed loop: the control: section's gains and limits
  // frontend.learned_lead.weights as found (next to the scenario or in assets/), when the lead
  // detector is the learned one; checked to load when the configuration is read.
  std::string lead_weights_path;

  bool single_uav() const { return estimator.mode == slam::EstimatorMode::SingleUav; }
  // UAV index of each camera in the filter: every UAV (multi) or the baseline's (single).
  std::vector<int> filter_uavs() const;
};

// The lead detector a rendered run uses: frontend.lead_detector, or for auto the one the world's
// cue calls for (aruco, panel; learned for cue: none).
vision::LeadDetectorKind lead_detector(const RunConfig& cfg);

// Loads a scenario file: one configuration per variant (or one), validated as a whole; errors
// are sim::ScenarioError naming file:line:col and the key.
std::vector<RunConfig> load_run_configs(const std::string& path);
// Same, from YAML text; `origin` stands for the file name in messages.
std::vector<RunConfig> parse_run_configs(const std::string& yaml_text, const std::string& origin);
// A scenario's module sections read into their settings, with the checks that involve both.
RunConfig compose(const sim::Scenario& scenario);

// The fully resolved configuration as YAML (every key, defaults included): what
// `wingman run --print-config` shows and every results directory keeps as config.yaml.
std::string config_yaml(const RunConfig& cfg);
// Writes config_yaml(cfg) to `path`; throws std::runtime_error naming it when it cannot.
void write_config(const RunConfig& cfg, const std::filesystem::path& path);
// Copies the scenario file a run came from into dir as scenario.yaml, with the trajectory file its
// lead follows when the scenario names it by a path inside its own directory, so that the copy
// loads the same (a replay of a dataset reads its scenario.yaml).
void copy_scenario(const sim::Scenario& scn, const std::filesystem::path& dir);

// Cuts a run to its first `duration` seconds: phases and outages that start later are dropped,
// the others end there at the latest.
void limit_duration(RunConfig& cfg, double duration);

}  // namespace wingman::app
