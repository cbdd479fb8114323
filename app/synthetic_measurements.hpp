// Synthetic measurements (`measurements: synthetic`, the paper's section 7.1): projections of
// sim's point field with the paper's noise and injected outliers, and the simulated sensors, for
// the filter's cameras (every UAV's, or the single-UAV baseline's).
#pragma once

#include <vector>

#include "app/measurements.hpp"
#include "app/run_config.hpp"
#include "sim/synthetic_source.hpp"

namespace wingman::app {

class SyntheticMeasurements final : public MeasurementSource {
 public:
  SyntheticMeasurements(const RunConfig& cfg, sim::SyntheticSource& source)
      : source_(source), cam_uav_(cfg.filter_uavs()) {}

  StageTimes begin_step(int, double t, const slam::Estimator&) override {
    t_ = t;
    return {};
  }
  std::vector<LandmarkObservation> landmarks(int cam, const std::vector<slam::LandmarkPrediction>& preds) override;
  std::optional<Eigen::Vector2d> lead_pixel(int cam) override { return source_.lead_pixel(cam_uav_[cam], t_); }
  std::optional<Eigen::Vector3d> gps() override { return source_.gps(t_); }
  std::optional<double> altimeter(int cam) override { return source_.altimeter(cam_uav_[cam], t_); }
  std::optional<double> range(int cam) override { return source_.range(cam_uav_[cam], t_); }
  void verdict(const LandmarkObservation&, bool) override {}
  std::vector<PairObservation> pairs(int cam_a, int cam_b, int needed, const slam::Estimator& est) override;
  std::vector<PointObservation> points(int cam, int needed) override;
  // The landmark is bound to the field point it came from: association by identity from now on.
  std::optional<Eigen::Vector3d> added(slam::LandmarkId id, int cam, std::int64_t handle,
                                       const Eigen::Vector2d& uv) override;
  void removed(slam::LandmarkId id) override { source_.unbind(id); }
  void end_step(double) override {}
  void finish(eval::RunRecord&) override {}

 private:
  sim::SyntheticSource& source_;
  std::vector<int> cam_uav_;
  double t_ = 0;
};

}  // namespace wingman::app
