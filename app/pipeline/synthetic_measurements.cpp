#include "app/pipeline/synthetic_measurements.hpp"

namespace wingman::app {

Labelled<LandmarkObservation> SyntheticMeasurements::landmarks(
    int cam, const std::vector<slam::LandmarkPrediction>& preds) {
  std::vector<std::int64_t> ids;
  for (const auto& p : preds) ids.push_back(p.id);
  Labelled<LandmarkObservation> out;
  for (const auto& o : source_.observe_landmarks(cam_uav_[cam], t_, ids)) {
    TruthLabel label;
    label.outlier = label.injected = o.injected_outlier;
    label.true_uv = o.true_uv;
    label.error_px = (o.uv - o.true_uv).norm();
    out.add({{cam, o.landmark, o.uv}, static_cast<std::int64_t>(o.point)}, label);
  }
  return out;
}

Labelled<PairObservation> SyntheticMeasurements::pairs(int cam_a, int cam_b, int needed,
                                                       const slam::Estimator&) {
  Labelled<PairObservation> out;
  for (const auto& m : source_.cross_matches(cam_uav_[cam_a], cam_uav_[cam_b], t_, needed)) {
    TruthLabel label;
    label.outlier = label.injected = m.injected_outlier;
    out.add({{cam_a, cam_b, m.uv_a, m.uv_b}, static_cast<std::int64_t>(m.point)}, label);
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
