// Synthetic measurements the way the paper emulates them (section 7.1): a static field of 3D
// points over the ground; their projections in every camera with sigma-px noise; 5 % of the
// correspondences per camera, and of the cross-UAV matches, replaced by outliers whose error norm
// is uniform in [0, 15] px; the lead's projection, GPS, altimeter and range with the paper's
// noise. Association is by identity (a filter landmark is bound to the point it came from), but
// an outlier leaves here as an ordinary pixel: only the bookkeeping fields say what it is.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <random>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "sim/scenario.hpp"
#include "sim/truth.hpp"

namespace wingman::sim {

// Points scattered over the ground below the flight, reproducible from the seed.
std::vector<Eigen::Vector3d> make_landmark_field(const Scenario& scn, const Truth& truth);

struct PixelObservation {
  std::int64_t landmark = -1;  // the filter's id, or -1 for a new point
  std::size_t point = 0;       // index into the field (truth, for evaluation only)
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  // Evaluation only, never given to the estimator:
  Eigen::Vector2d true_uv = Eigen::Vector2d::Zero();
  bool injected_outlier = false;
};

struct PointPair {
  std::size_t point = 0;
  Eigen::Vector2d uv_a = Eigen::Vector2d::Zero(), uv_b = Eigen::Vector2d::Zero();
  bool injected_outlier = false;  // evaluation only
};

class SyntheticSource {
 public:
  SyntheticSource(const Scenario& scn, const Truth& truth);

  const std::vector<Eigen::Vector3d>& field() const { return field_; }
  void bind(std::int64_t landmark, std::size_t point);
  void unbind(std::int64_t landmark);
  std::optional<std::size_t> point_of(std::int64_t landmark) const;

  // The true pixel of a field point in a UAV camera at t, if inside the image.
  std::optional<Eigen::Vector2d> true_pixel(int uav, double t, const Eigen::Vector3d& p) const;

  // Correspondences for the landmarks the estimator predicts in view (by id).
  std::vector<PixelObservation> observe_landmarks(int uav, double t,
                                                  const std::vector<std::int64_t>& predicted);
  // Unmapped points seen by both UAVs now, spread over the image of `uav_a`.
  std::vector<PointPair> cross_matches(int uav_a, int uav_b, double t, int count);
  // Unmapped points seen by one UAV (single-UAV initialisation).
  std::vector<PixelObservation> new_points(int uav, double t, int count);

  std::optional<Eigen::Vector2d> lead_pixel(int uav, double t);
  // Camera uav's constant pixel offset for field point `point` (noise.pixel_bias_sigma; zero
  // when that is 0): the same on every call.
  Eigen::Vector2d pixel_bias(int uav, std::size_t point) const;
  Eigen::Vector3d gps(double t);
  double altimeter(int uav, double t);
  double range(int uav, double t);
  double ahrs_yaw(int uav, double t);  // truth yaw plus N(0, ahrs_yaw_sigma), wrapped

  long injected_outliers(int uav) const { return injected_[uav]; }

 private:
  Eigen::Vector2d noisy(const Eigen::Vector2d& uv);  // white pixel noise only (the lead)
  // Landmark pixels: white noise plus the camera's constant offset for that point.
  Eigen::Vector2d noisy(const Eigen::Vector2d& uv, int uav, std::size_t point);
  Eigen::Vector2d outlier(const Eigen::Vector2d& uv);
  std::vector<std::size_t> unmapped_in_view(int uav, double t) const;
  std::vector<std::size_t> spread(int uav, double t, std::vector<std::size_t> candidates, int count);

  const Scenario& scn_;
  const Truth& truth_;
  std::vector<Eigen::Vector3d> field_;
  std::unordered_map<std::int64_t, std::size_t> bound_;
  std::unordered_set<std::size_t> bound_points_;
  std::mt19937_64 pixel_rng_, outlier_rng_, select_rng_, gps_rng_, alt_rng_, range_rng_, ahrs_rng_;
  std::vector<long> injected_;
};

}  // namespace wingman::sim
