#include "app/pipeline/pipeline.hpp"

#include <algorithm>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>

#include "app/pipeline/closed_loop.hpp"
#include "app/pipeline/frame_measurements.hpp"
#include "app/pipeline/synthetic_measurements.hpp"
#include "datasets/dataset.hpp"
#include "sim/closed_loop_truth.hpp"
#include "sim/synthetic_source.hpp"
#include "sim/truth.hpp"

namespace wingman::app {

namespace {

// The scenario's measurement source; `sensors` gives the GPS, altimeter and range either way.
std::unique_ptr<MeasurementSource> make_source(const RunConfig& cfg, const sim::Truth& truth,
                                               sim::SyntheticSource& sensors, const RenderedOptions& ro) {
  if (cfg.measurements == sim::MeasurementMode::Synthetic)
    return std::make_unique<SyntheticMeasurements>(cfg, sensors);
  // Open loop: step k+1's truth is known at step k, so its frames can render during step k.
  const bool prefetch = !cfg.closed_loop() && ro.prefetch;
  if (prefetch && !cfg.frontend.active_search.enabled) {
    // With the prefetch, whole-frame detection keeps one core busy while the frames render:
    // llvmpipe (Mesa's software rasteriser, one thread per core by default) gets the others. With
    // active search detection takes a third of the rendering's time, and llvmpipe on every core
    // is faster (docs/studies/speed.md). LP_NUM_THREADS set by the user wins; a GPU driver ignores it.
    const unsigned cores = std::max(2u, std::thread::hardware_concurrency());
    setenv("LP_NUM_THREADS", std::to_string(cores - 1).c_str(), /*overwrite=*/0);
  }
  FrameOptions fo;
  fo.prefetch = prefetch;
  fo.regions = ro.regions;
  fo.correspondences = ro.correspondences;
  fo.video = ro.video;
  return std::make_unique<FrameMeasurements>(cfg, truth,
                                             std::make_unique<RendererFrames>(cfg, cfg.filter_uavs(), ro.gl, truth, ro.frame_cache),
                                             std::make_unique<SimulatedSamples>(sensors), fo);
}

eval::RunRecord run_closed_loop(const RunConfig& cfg, const ProgressFn& progress,
                                const StateObserver& observer, const RenderedOptions& ro) {
  if (cfg.single_uav()) throw std::invalid_argument("closed loop needs the multi-UAV estimator");
  sim::ClosedLoopTruth truth(cfg);
  sim::SyntheticSource sensors(cfg, truth);
  ClosedLoopFlight flight(cfg, truth, sensors);
  const auto source = make_source(cfg, truth, sensors, ro);
  eval::RunRecord rec = run_loop(cfg, truth, *source, flight.hooks(), progress, observer);
  flight.finish(rec);
  return rec;
}

eval::RunRecord run_open_loop(const RunConfig& cfg, const ProgressFn& progress, const StateObserver& observer,
                              const RenderedOptions& ro) {
  const sim::OpenLoopTruth truth(cfg);
  sim::SyntheticSource sensors(cfg, truth);
  const auto source = make_source(cfg, truth, sensors, ro);
  return run_loop(cfg, truth, *source, {}, progress, observer);
}

// The GPS, altimeter and range samples a dataset holds; a step without one feeds nothing.
class DatasetSamples final : public SensorSamples {
 public:
  DatasetSamples(const datasets::Dataset& ds, const RunConfig& cfg, std::vector<const datasets::AgentData*> uavs)
      : lead_(ds.agent("lead")), uavs_(std::move(uavs)), rate_(cfg.rate) {}
  std::optional<Eigen::Vector3d> gps(int k, double) override { return at(lead_.gps, k); }
  std::optional<double> altimeter(int uav, int k, double) override { return at(uavs_[uav]->altimeter, k); }
  std::optional<double> range(int uav, int k, double) override { return at(uavs_[uav]->range, k); }

 private:
  template <typename Samples>
  auto at(const Samples& samples, int k) const -> std::optional<decltype(samples.front().value)> {
    const std::int64_t t_ns = datasets::step_ns(k, rate_);
    auto it = std::lower_bound(samples.begin(), samples.end(), t_ns,
                               [](const auto& s, std::int64_t v) { return s.t_ns < v; });
    if (it != samples.end() && it->t_ns == t_ns) return it->value;
    return std::nullopt;
  }
  const datasets::AgentData& lead_;
  std::vector<const datasets::AgentData*> uavs_;
  double rate_;
};

// Every UAV of the scenario in the dataset, with a frame and a camera pose per step, at the
// scenario's true positions: the frontend labels against that truth.
std::vector<const datasets::AgentData*> check_dataset(const RunConfig& cfg, const datasets::Dataset& ds,
                                                      const sim::Truth& truth) {
  std::vector<const datasets::AgentData*> agents;
  for (const auto& u : cfg.uavs) agents.push_back(&ds.agent(u.name));  // throws naming the file
  const int steps = cfg.num_steps();
  for (std::size_t u = 0; u < agents.size(); ++u) {
    const auto& a = *agents[u];
    if (static_cast<int>(a.frames.size()) < steps + 1 || static_cast<int>(a.camera_pose.size()) < steps + 1)
      throw std::invalid_argument(ds.root.string() + "/" + a.name + ": fewer frames or camera poses than the " +
                                  std::to_string(steps + 1) + " steps to replay");
    for (int k : {0, steps / 2, steps}) {
      const Eigen::Vector3d d = a.camera_pose[k].p - truth.camera(static_cast<int>(u), k * cfg.dt()).position;
      if (d.norm() > 1e-3)
        throw std::invalid_argument(ds.root.string() + "/" + a.name +
                                    ": true camera positions (cam0_pose0) differ from the truth of the "
                                    "dataset's scenario.yaml (" +
                                    std::to_string(d.norm()) + " m at step " + std::to_string(k) + ")");
    }
  }
  return agents;
}

}  // namespace

eval::RunRecord run_replay(const RunConfig& cfg, const datasets::Dataset& ds, const ProgressFn& progress,
                           const std::optional<vision::FeatureSettings>& features, bool correspondences) {
  if (cfg.closed_loop())
    throw std::invalid_argument(ds.root.string() +
                                ": a dataset holds an open-loop flight; its scenario has a control: section");
  const sim::OpenLoopTruth truth(cfg);
  const auto agents = check_dataset(cfg, ds, truth);
  const std::vector<int> cam_uav = cfg.filter_uavs();
  std::vector<const datasets::AgentData*> cams;
  for (int u : cam_uav) cams.push_back(agents[u]);
  FrameOptions fo;
  fo.correspondences = correspondences;
  fo.features = features;
  FrameMeasurements source(cfg, truth, std::make_unique<DatasetFrames>(ds, cams, cam_uav, truth),
                           std::make_unique<DatasetSamples>(ds, cfg, agents), fo);
  return run_loop(cfg, truth, source, {}, progress);
}

eval::RunRecord run_scenario(const RunConfig& cfg, const RenderedOptions& ro, const ProgressFn& progress,
                             const StateObserver& observer) {
  return cfg.closed_loop() ? run_closed_loop(cfg, progress, observer, ro)
                           : run_open_loop(cfg, progress, observer, ro);
}

eval::RunRecord run_synthetic(const RunConfig& cfg, const ProgressFn& progress, const StateObserver& observer) {
  return run_scenario(cfg, RenderedOptions{}, progress, observer);
}

}  // namespace wingman::app
