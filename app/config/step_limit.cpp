#include "app/config/step_limit.hpp"

#include <fmt/core.h>

#include "io/usage_error.hpp"

namespace wingman::app {

std::optional<double> StepLimit::seconds(double rate) const {
  if (duration) {
    if (!(*duration > 0)) throw io::UsageError(fmt::format("--duration: must be > 0, got {}", *duration));
    return *duration;
  }
  if (frames) {
    if (*frames < 2) throw io::UsageError(fmt::format("--frames: must be at least 2 (one step), got {}", *frames));
    return (*frames - 1) / rate;
  }
  return std::nullopt;
}

void apply_step_limit(const StepLimit& limit, RunConfig& cfg) {
  if (const auto s = limit.seconds(cfg.rate)) limit_duration(cfg, *s);
}

}  // namespace wingman::app
