#include "app/replay.hpp"

#include <fmt/core.h>

#include <algorithm>

#include "app/subcommand.hpp"
#include "app/variants.hpp"

namespace wingman::app {

Replay load_replay(const std::string& dir, const std::string& variant) {
  Replay r;
  try {
    r.dataset = datasets::read_dataset(dir);
  } catch (const std::runtime_error& e) {  // DatasetError names the file
    throw UsageError(e.what());
  }
  r.scenario_path = std::filesystem::path(dir) / "scenario.yaml";
  if (!std::filesystem::exists(r.scenario_path))
    throw UsageError(r.scenario_path.string() + ": missing (wingman render writes it)");
  auto scenarios = load_run_configs(r.scenario_path.string());
  const std::string want = variant.empty() ? r.dataset.info.variant : variant;
  r.scenario = select_variant(std::move(scenarios), want, r.scenario_path.string());
  RunConfig& scn = r.scenario;
  scn.seed = r.dataset.info.seed;
  scn.measurements = sim::MeasurementMode::Rendered;
  // A shortened dataset (render --frames/--duration) replays what it has.
  const auto& first = r.dataset.agent(scn.uavs.front().name);
  const int frames = static_cast<int>(first.frames.size());
  if (frames < 2) throw UsageError(fmt::format("{}: fewer than 2 frames to replay", dir));
  scn.duration = std::min(scn.duration, (frames - 1) / scn.rate);
  return r;
}

}  // namespace wingman::app
