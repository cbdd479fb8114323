// Synthetic measurements (`measurements: synthetic`, the paper's section 7.1): projections of
// sim's point field with the paper's noise and injected outliers, and the simulated sensors, for
// the filter's cameras (every UAV's, or the single-UAV baseline's).
#pragma once

#include <vector>

#include "app/pipeline/measurements.hpp"
#include "app/config/run_config.hpp"
#include "sim/synthetic_source.hpp"

namespace wingman::app {

// The simulated sensors of sim::SyntheticSource (synthetic and rendered runs).
class SimulatedSamples final : public SensorSamples {
 public:
  explicit SimulatedSamples(sim::SyntheticSource& source) : source_(source) {}
  std::optional<Eigen::Vector3d> gps(int, double t) override { return source_.gps(t); }
  std::optional<double> altimeter(int uav, int, double t) override { return source_.altimeter(uav, t); }
  std::optional<double> range(int uav, int, double t) override { return source_.range(uav, t); }

 private:
  sim::SyntheticSource& source_;
};

class SyntheticMeasurements final : public MeasurementSource {
 public:
  SyntheticMeasurements(const RunConfig& cfg, sim::SyntheticSource& source)
      : source_(source), samples_(source), cam_uav_(cfg.filter_uavs()) {}

  StageTimes begin_step(int, double t, const slam::Estimator&) override {
    t_ = t;
    return {};
  }
  Labelled<LandmarkObservation> landmarks(int cam, const std::vector<slam::LandmarkPrediction>& preds) override;
  std::optional<Eigen::Vector2d> lead_pixel(int cam) override { return source_.lead_pixel(cam_uav_[cam], t_); }
  slam::SensorBatch sensors(const SensorRequest& wanted) override {
    return take_samples(samples_, wanted, cam_uav_, 0, t_);
  }
  void verdict(const LandmarkObservation&, const TruthLabel&, bool) override {}
  Labelled<PairObservation> pairs(int cam_a, int cam_b, int needed, const slam::Estimator& est) override;
  std::vector<PointObservation> points(int cam, int needed) override;
  // The landmark is bound to the field point it came from: association by identity from now on.
  std::optional<Eigen::Vector3d> added(slam::LandmarkId id, int cam, std::int64_t handle,
                                       const Eigen::Vector2d& uv) override;
  void removed(slam::LandmarkId id) override { source_.unbind(id); }
  void end_step(double) override {}
  void finish(eval::RunRecord&) override {}

 private:
  sim::SyntheticSource& source_;
  SimulatedSamples samples_;
  std::vector<int> cam_uav_;
  double t_ = 0;
};

}  // namespace wingman::app
