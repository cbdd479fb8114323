// A run cut to its first S seconds or first N frames (t = 0, dt, ...): what --duration and
// --frames mean on every command that takes them (app/cli/cli_options.hpp); phases and outages
// are cut there.
#pragma once

#include <optional>

#include "app/config/run_config.hpp"

namespace wingman::app {

struct StepLimit {
  std::optional<double> duration;
  std::optional<int> frames;
  bool any() const { return duration || frames; }
  // The seconds it keeps of a run at `rate`; throws io::UsageError for a limit that keeps no step.
  std::optional<double> seconds(double rate) const;
};
// Cuts the run to the limit (limit_duration).
void apply_step_limit(const StepLimit& limit, RunConfig& cfg);

}  // namespace wingman::app
