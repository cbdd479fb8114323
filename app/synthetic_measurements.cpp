#include "app/synthetic_measurements.hpp"

namespace wingman::app {

std::vector<LandmarkObservation> SyntheticMeasurements::landmarks(
    int cam, const std::vector<slam::LandmarkPrediction>& preds) {
  std::vector<std::int64_t> ids;
  for (const auto& p : preds) ids.push_back(p.id);
  std::vector<LandmarkObservation> out;
  for (const auto& o : source_.observe_landmarks(cam_uav_[cam], t_, ids)) {
    LandmarkObservation m;
    m.c = {cam, o.landmark, o.uv};
    m.handle = static_cast<std::int64_t>(o.point);
    m.outlier = m.injected = o.injected_outlier;
    m.true_uv = o.true_uv;
    m.error_px = (o.uv - o.true_uv).norm();
    out.push_back(m);
  }
  return out;
}

std::vector<PairObservation> SyntheticMeasurements::pairs(int cam_a, int cam_b, int needed,
                                                          const slam::Estimator&) {
  std::vector<PairObservation> out;
  for (const auto& m : source_.cross_matches(cam_uav_[cam_a], cam_uav_[cam_b], t_, needed)) {
    PairObservation p;
    p.m = {cam_a, cam_b, m.uv_a, m.uv_b};
    p.handle = static_cast<std::int64_t>(m.point);
    p.outlier = p.injected = m.injected_outlier;
    out.push_back(p);
  }
  return out;
}

std::vector<PointObservation> SyntheticMeasurements::points(int cam, int needed) {
  std::vector<PointObservation> out;
  for (const auto& o : source_.new_points(cam_uav_[cam], t_, needed))
    out.push_back({cam, o.uv, static_cast<std::int64_t>(o.point)});
  return out;
}

std::optional<Eigen::Vector3d> SyntheticMeasurements::added(slam::LandmarkId id, int, std::int64_t handle,
                                                            const Eigen::Vector2d&) {
  const auto point = static_cast<std::size_t>(handle);
  source_.bind(id, point);
  return source_.field()[point];
}

}  // namespace wingman::app
