// The one seam through which every measurement reaches the estimator's loop (app/pipeline/loop.cpp).
// Three sources implement it: synthetic projections of a point field (SyntheticMeasurements),
// rendered frames through the vision frontend (FrameMeasurements over RendererFrames), and a
// dataset's frames and sensor samples (FrameMeasurements over DatasetFrames). The loop never asks
// which one it has.
//
// The seam carries the estimator's input only; each observation's evaluation label (was it wrong,
// by construction or by ground truth) travels beside it, and the loop only counts it.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "eval/metrics/run_record.hpp"
#include "slam/estimator.hpp"

namespace wingman::app {

// What producing and detecting a step's frames cost.
struct StageTimes {
  double render_ms = 0;  // rendering (or loading) summed over the cameras
  double detect_ms = 0;  // detection summed over the cameras, part of it during rendering
  double wall_ms = 0;    // the whole of it
};

// What the loop counts of an observation (Table 3, the frontend's pixel errors): its ground-truth
// label, carried beside the estimator's input and never given to the filter.
struct TruthLabel {
  bool outlier = false;   // injected, or > 3 px from the true projection
  bool injected = false;  // corrupted on purpose (synthetic)
  double error_px = std::numeric_limits<double>::quiet_NaN();  // to the true projection
  Eigen::Vector2d true_uv = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
};

// Observations for the filter with each one's label beside it (labels[i] is items[i]'s).
template <typename T>
struct Labelled {
  std::vector<T> items;
  std::vector<TruthLabel> labels;
  void add(T item, const TruthLabel& label) {
    items.push_back(std::move(item));
    labels.push_back(label);
  }
  std::size_t size() const { return items.size(); }
};

// A landmark correspondence offered to the filter.
struct LandmarkObservation {
  slam::Correspondence c;
  std::int64_t handle = -1;  // what the source saw: a field point, a keypoint
};

// A pixel pair of two cameras for a cooperative landmark.
struct PairObservation {
  slam::CrossMatch m;
  std::int64_t handle = -1;  // camera a's
};

// A pixel of one camera for a single-camera (inverse-depth) landmark.
struct PointObservation {
  int cam = 0;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  std::int64_t handle = -1;
};

// The sensor samples a step asks for: the lead's GPS, and per filter camera its altimeter and its
// range to the lead (only where the phase and the UAV's kit feed them).
struct SensorRequest {
  bool gps = false;
  std::vector<bool> altimeter, range;
};

// GPS, altimeter and range samples of step k at t, by UAV index; nothing when none was taken.
class SensorSamples {
 public:
  virtual ~SensorSamples() = default;
  virtual std::optional<Eigen::Vector3d> gps(int k, double t) = 0;
  virtual std::optional<double> altimeter(int uav, int k, double t) = 0;
  virtual std::optional<double> range(int uav, int k, double t) = 0;
};

// The samples a request asks for, as the filter takes them: GPS first, then camera by camera its
// altimeter and its range (the order the samples are drawn in). cam_uav maps cameras to UAVs.
slam::SensorBatch take_samples(SensorSamples& samples, const SensorRequest& wanted,
                               const std::vector<int>& cam_uav, int k, double t);

// Cameras are the filter's (0 .. n-1); each source maps them onto its UAVs.
class MeasurementSource {
 public:
  virtual ~MeasurementSource() = default;
  // Step k at time t begins, after the filter's prediction: frames are produced and detected in
  // (the estimate places the lead's search region).
  virtual StageTimes begin_step(int k, double t, const slam::Estimator& est) = 0;
  // Correspondences for the landmarks the filter predicts in camera `cam`'s view.
  virtual Labelled<LandmarkObservation> landmarks(int cam, const std::vector<slam::LandmarkPrediction>& preds) = 0;
  virtual std::optional<Eigen::Vector2d> lead_pixel(int cam) = 0;
  // The step's GPS, altimeter and range samples that `wanted` asks for.
  virtual slam::SensorBatch sensors(const SensorRequest& wanted) = 0;
  // The filter accepted or rejected an observation of this step (with its label).
  virtual void verdict(const LandmarkObservation& o, const TruthLabel& label, bool accepted) = 0;
  // Pixel pairs between two cameras for new landmarks, at most `needed`.
  virtual Labelled<PairObservation> pairs(int cam_a, int cam_b, int needed, const slam::Estimator& est) = 0;
  // Pixels of one camera for new landmarks, at most `needed`.
  virtual std::vector<PointObservation> points(int cam, int needed) = 0;
  // A landmark was initialised from `handle` of camera `cam` at `uv`: its truth, for Table 5
  // (nothing when the source cannot tell it).
  virtual std::optional<Eigen::Vector3d> added(slam::LandmarkId id, int cam, std::int64_t handle,
                                               const Eigen::Vector2d& uv) = 0;
  virtual void removed(slam::LandmarkId id) = 0;
  virtual void end_step(double t) = 0;
  // The source's own part of the run record (the frontend's figures).
  virtual void finish(eval::RunRecord& rec) = 0;
};

}  // namespace wingman::app
