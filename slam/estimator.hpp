// The estimator's face to a frontend (synthetic now, image-based later). Per step:
//   predict(dt) -> landmarks_in_view(cam) for every camera -> update_visual(correspondences, lead)
//   -> update_sensors(...) -> initialise_* for new points -> end_step() (map management).
// It owns the filter state and composes the small pieces of slam/: motion model, measurement
// models, gated and 1-point RANSAC updates, landmark initialisation. It never sees an image.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <random>
#include <unordered_map>
#include <vector>

#include "slam/landmark_init.hpp"
#include "slam/measurement_models.hpp"
#include "slam/settings.hpp"
#include "slam/state.hpp"
#include "slam/visual_update.hpp"

namespace wingman::slam {

struct AgentInit {
  Eigen::Vector3d position = Eigen::Vector3d::Zero(), velocity = Eigen::Vector3d::Zero();
};

// A landmark predicted in a camera's image: pixel and innovation covariance H P H^T + R, so a
// frontend can search inside its 3-sigma ellipse.
struct LandmarkPrediction {
  LandmarkId id = -1;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  Eigen::Matrix2d S = Eigen::Matrix2d::Identity();
};

// A point seen by two cameras at the same instant, for cooperative initialisation.
struct CrossMatch {
  int cam_a = 0, cam_b = 1;
  Eigen::Vector2d uv_a = Eigen::Vector2d::Zero(), uv_b = Eigen::Vector2d::Zero();
};

// Non-landmark measurements of one instant; cameras by index.
struct SensorBatch {
  std::optional<Eigen::Vector3d> gps;
  std::vector<std::pair<int, double>> altimeter;
  std::vector<std::pair<int, double>> range;
};
struct SensorUpdateResult {
  int offered = 0, accepted = 0;
};

class Estimator {
 public:
  // `seed` seeds RANSAC's draws.
  Estimator(std::vector<CameraRig> cameras, const AgentInit& lead,
            const std::vector<AgentInit>& camera_init, const EstimatorSettings& settings,
            std::uint64_t seed = 1);

  int num_cameras() const { return static_cast<int>(cams_.size()); }
  const FilterState& state() const { return s_; }
  const CameraRig& camera(int j) const { return cams_[j]; }
  // The gimbal's commanded orientation, a known input (docs/design.md, frames and conventions).
  void set_camera_rotation(int cam, const Eigen::Matrix3d& R_CW) { cams_[cam].R_CW = R_CW; }

  void predict(double dt);  // eq. 41-42
  // Landmarks predicted inside camera `cam`'s image (with the margin); records them as expected
  // to be matched this step, for map management.
  std::vector<LandmarkPrediction> landmarks_in_view(int cam);
  // The same predictions without recording anything: what the frontend's active search plans
  // its regions from before the step's measurements are taken.
  std::vector<LandmarkPrediction> predictions_in_view(int cam) const;
  // Landmark correspondences (1-point RANSAC and gating) together with the lead's projections
  // (eq. 5-6) of the same frames, which share the gimbal noise with them.
  VisualUpdateResult update_visual(const std::vector<Correspondence>& candidates,
                                   const std::vector<std::pair<int, Eigen::Vector2d>>& lead_pixels = {});
  SensorUpdateResult update_sensors(const SensorBatch& batch);
  // Cooperative initialisation of each match (eq. 47-52); one outcome per match.
  std::vector<InitOutcome> initialise_from_matches(const std::vector<CrossMatch>& matches);
  // Single-camera undelayed inverse-depth initialisation.
  InitOutcome initialise_from_pixel(int cam, const Eigen::Vector2d& uv);
  // Map management: drops landmarks that kept failing to match where predicted visible, converts
  // linear inverse-depth landmarks to XYZ. Returns every id removed during this step (dropped
  // here, or evicted earlier to make room for a new one).
  std::vector<LandmarkId> end_step();

  Eigen::Vector3d lead_position() const { return s_.x.segment<3>(FilterState::lead_pos()); }
  Eigen::Vector3d lead_velocity() const { return s_.x.segment<3>(FilterState::lead_vel()); }
  Eigen::Vector3d camera_position(int j) const { return s_.x.segment<3>(FilterState::cam_pos(j)); }
  Eigen::Vector3d camera_velocity(int j) const { return s_.x.segment<3>(FilterState::cam_vel(j)); }
  std::optional<Eigen::Vector3d> landmark_position(LandmarkId id) const;
  int num_landmarks() const { return static_cast<int>(s_.landmarks().size()); }

 private:
  struct Track {
    int misses = 0;
    bool expected = false;  // predicted in view this step
    bool matched = false;   // accepted this step
  };
  bool make_room();  // evicts one landmark out of view when the map is full
  void forget(LandmarkId id);

  std::vector<CameraRig> cams_;
  EstimatorSettings cfg_;
  FilterState s_;
  std::unordered_map<LandmarkId, Track> tracks_;
  std::vector<LandmarkId> evicted_;  // removed since the last end_step()
  std::mt19937_64 rng_;
};

}  // namespace wingman::slam
