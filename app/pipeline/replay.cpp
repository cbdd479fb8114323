#include "app/pipeline/replay.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "io/interrupt.hpp"
#include "io/progress.hpp"
#include "io/usage_error.hpp"
#include "app/config/variants.hpp"
#include "sim/yaml_input.hpp"

namespace wingman::app {
namespace {

bool same(double a, double b) { return std::abs(a - b) <= 1e-9 * std::max({1.0, std::abs(a), std::abs(b)}); }

// One camera of the dataset against the scenario's UAV it belongs to.
void check_camera(const datasets::AgentData& a, const RunConfig& scn, const sim::UavSpec& u,
                  const datasets::Dataset& ds, const std::filesystem::path& scn_path) {
  const double scn_rate = scn.rate;
  const auto file = (ds.layout.sensor(ds.root, a.name, "cam0") / "sensor.yaml").string();
  if (!a.camera) throw io::UsageError(fmt::format("{}: missing: the scenario's UAV '{}' has a camera", file, u.name));
  const geometry::PinholeCamera& d = a.camera->camera;
  const geometry::PinholeCamera s = u.camera.camera();
  const auto& dd = d.distortion();
  const auto& sd = s.distortion();
  const bool ok = d.width() == s.width() && d.height() == s.height() && same(d.fx(), s.fx()) &&
                  same(d.fy(), s.fy()) && same(d.cx(), s.cx()) && same(d.cy(), s.cy()) && same(dd.k1, sd.k1) &&
                  same(dd.k2, sd.k2) && same(dd.p1, sd.p1) && same(dd.p2, sd.p2) && same(dd.k3, sd.k3);
  if (!(std::abs(a.camera->rate - scn_rate) <= 1e-9 * scn_rate))
    throw io::UsageError(fmt::format("{}: rate_hz {} differs from the scenario's {} Hz", file, a.camera->rate, scn_rate));
  if (!ok)
    throw io::UsageError(fmt::format(
        "{}: the camera ({}x{}, fx {} fy {} cx {} cy {}) is not the one {} gives uav '{}' ({}x{}, fx {} fy {} cx {} "
        "cy {}, or its distortion differs): the frames would be read with the wrong model",
        file, d.width(), d.height(), d.fx(), d.fy(), d.cx(), d.cy(), scn_path.string(), u.name, s.width(), s.height(),
        s.fx(), s.fy(), s.cx(), s.cy()));
  // A colour panel is found by its hue: grey frames cannot show it.
  if (scn.world.lead.cue == sim::LeadModelSpec::Cue::Panel && a.camera->channels == 1)
    throw io::UsageError(fmt::format("{}: grey frames (encoding mono8), but the lead's cue in {} is a colour panel: "
                                 "render the dataset with --rgb",
                                 file, scn_path.string()));
  for (std::size_t k = 0; k < a.frames.size(); ++k)
    if (a.frames[k] != datasets::step_ns(static_cast<int>(k), a.camera->rate))
      throw io::UsageError(fmt::format("{}: frame {} has time stamp {} ns; at {} Hz it would be {} ns",
                                   (ds.layout.sensor(ds.root, a.name, "cam0") / "data.csv").string(), k + 1, a.frames[k],
                                   a.camera->rate, datasets::step_ns(static_cast<int>(k), a.camera->rate)));
}

// The dataset and its scenario describe the same run: the same rate, an agent with the same
// camera for every UAV, the lead's ground truth. A dataset that contradicts its scenario would
// change the results without a word.
void check_against_scenario(const datasets::Dataset& ds, const RunConfig& scn, const std::filesystem::path& scn_path) {
  const auto yf = (ds.root / "dataset.yaml").string();
  if (!(std::abs(ds.info.rate - scn.rate) <= 1e-9 * scn.rate))
    throw io::UsageError(fmt::format("{}: rate_hz {} differs from the rate {} Hz of {}", yf, ds.info.rate, scn.rate,
                                 scn_path.string()));
  auto find = [&](const std::string& name) -> const datasets::AgentData* {
    for (const auto& a : ds.agents)
      if (a.name == name) return &a;
    return nullptr;
  };
  if (ds.info.scenario != scn.name)
    throw io::UsageError(fmt::format("{}: scenario '{}', but {} is '{}'", yf, sim::printable(ds.info.scenario),
                                 scn_path.string(), scn.name));
  const datasets::AgentData* lead = find("lead");
  if (!lead) throw io::UsageError(fmt::format("{}: agents: no 'lead' (its ground truth is needed)", yf));
  const datasets::AgentData* first = find(scn.uavs.front().name);
  const std::size_t frames = first ? first->frames.size() : 0;
  // Every sensor the scenario carries has a sample for every frame.
  auto samples = [&](const datasets::AgentData& a, const char* folder, std::size_t n) {
    if (n < frames)
      throw io::UsageError(fmt::format("{}: {} samples for {} frames (the scenario's {} carries it)",
                                   (ds.layout.sensor(ds.root, a.name, folder) / "data.csv").string(), n, frames,
                                   a.name));
  };
  if (scn.lead.gps) samples(*lead, "gps0", lead->gps.size());
  for (const auto& u : scn.uavs) {
    const datasets::AgentData* a = find(u.name);
    if (!a)
      throw io::UsageError(fmt::format("{}: agents: no '{}', a UAV of {} ({})", yf, u.name, scn_path.string(),
                                   scn.uav_names()));
    check_camera(*a, scn, u, ds, scn_path);
    if (a->frames.size() != frames)
      throw io::UsageError(fmt::format("{}: {} has {} frames, {} has {}", yf, a->name, a->frames.size(),
                                   scn.uavs.front().name, frames));
    if (u.altimeter) samples(*a, "altimeter0", a->altimeter.size());
    if (u.range) samples(*a, "range0", a->range.size());
    if (a->groundtruth.size() < a->frames.size())
      throw io::UsageError(fmt::format("{}: {} poses for {} frames",
                                   ds.layout.groundtruth_csv(ds.root, a->name).string(), a->groundtruth.size(),
                                   a->frames.size()));
  }
}

}  // namespace

Replay load_replay(const std::string& dir, const std::string& variant, bool quiet) {
  Replay r;
  try {
    r.dataset = datasets::read_dataset(dir);
  } catch (const std::runtime_error& e) {  // DatasetError names the file
    throw io::UsageError(e.what());
  }
  r.scenario_path = std::filesystem::path(dir) / "scenario.yaml";
  if (!std::filesystem::exists(r.scenario_path))
    throw io::UsageError(r.scenario_path.string() + ": missing (wingman render writes it)");
  auto scenarios = load_run_configs(r.scenario_path.string());
  const std::string want = variant.empty() ? r.dataset.info.variant : variant;
  r.scenario = select_variant(std::move(scenarios), want, r.scenario_path.string());
  RunConfig& scn = r.scenario;
  scn.seed = r.dataset.info.seed;
  scn.measurements = sim::MeasurementMode::Rendered;
  check_against_scenario(r.dataset, scn, r.scenario_path);
  // A shortened dataset (render --frames/--duration) replays what it has.
  const int frames = static_cast<int>(r.dataset.agent(scn.uavs.front().name).frames.size());
  if (frames < 2) throw io::UsageError(fmt::format("{}: fewer than 2 frames to replay", dir));
  scn.duration = std::min(scn.duration, (frames - 1) / scn.rate);
  // Every frame is checked before the first step, so a damaged one is bad input now, not an
  // error an hour into the replay.
  io::ProgressLine progress(fmt::format("[verify {}]", dir), quiet);
  try {
    datasets::verify_frames(r.dataset, [&](int k, int n) {
      io::throw_if_interrupted();
      progress.update(k, n, "frames");
    });
  } catch (const datasets::DatasetError& e) {
    throw io::UsageError(e.what());
  }
  progress.finish();
  return r;
}

}  // namespace wingman::app
