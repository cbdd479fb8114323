// What makes the runs of a Monte Carlo directory one study: every variant's resolved
// configuration (seed aside) and the options that change what a run computes. The directory
// keeps them in montecarlo_settings.yaml, and --resume refuses a scenario or options that resolve
// differently, so runs made with other settings are never aggregated into one montecarlo.json.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "app/config/step_limit.hpp"
#include "app/config/run_config.hpp"

namespace wingman::app {

inline constexpr const char* kStudySettingsFile = "montecarlo_settings.yaml";

// The settings text: the options, then each variant's config_yaml without comments or seed.
std::string study_settings(const std::vector<RunConfig>& variants, const StepLimit& limit);
// Writes `settings` into dir when it holds no record (a new study, or one from a version that
// kept none), else compares: a difference is a io::UsageError naming the first differing key with
// both values.
void record_or_check_study(const std::filesystem::path& dir, const std::string& settings);
// FNV-1a 64 of a file's bytes, 16 hex digits: the scenario file as montecarlo.json records it.
std::string file_fnv1a64(const std::filesystem::path& path);

}  // namespace wingman::app
