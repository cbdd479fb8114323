// Measurements from frames (`measurements: rendered`, or a dataset's replay): a FrameProducer's
// frames through the vision frontend, labelled against the truth for evaluation, with the other
// sensors (GPS, altimeter, range) from SensorSamples (measurements.hpp). Rendering and detection overlap on two
// threads: camera j's detection with camera j+1's rendering, or, in open loop with prefetch, step
// k's detection with step k+1's rendering; the results are the same either way. With active
// search only the pixels detection reads are drawn (VisionFrontend::reads), with the same results.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/pipeline/frame_producer.hpp"
#include "app/frontend/labeller.hpp"
#include "app/pipeline/measurements.hpp"
#include "app/config/run_config.hpp"
#include "app/frontend/video_overlay.hpp"
#include "app/frontend/vision_frontend.hpp"
#include "sim/synthetic_source.hpp"
#include "sim/truth.hpp"

namespace wingman::app {

struct FrameOptions {
  bool prefetch = false;        // render step k+1 during step k (open loop, renderer only)
  // Render only the pixels the frontend reads (VisionFrontend::reads) where the producer can;
  // false: whole frames (the reference path). Off with --video, which shows whole frames.
  bool regions = true;
  bool correspondences = false;  // keep every tracked correspondence (RunRecord::frontend)
  std::string video;             // non-empty: VideoOverlay to this file
  std::optional<vision::FeatureSettings> features;  // overrides the frontend section's detector
};

class FrameMeasurements final : public MeasurementSource {
 public:
  FrameMeasurements(const RunConfig& cfg, const sim::Truth& truth, std::unique_ptr<FrameProducer> frames,
                    std::unique_ptr<SensorSamples> samples, const FrameOptions& options);

  StageTimes begin_step(int k, double t, const slam::Estimator& est) override;
  Labelled<LandmarkObservation> landmarks(int cam, const std::vector<slam::LandmarkPrediction>& preds) override;
  std::optional<Eigen::Vector2d> lead_pixel(int cam) override { return lead_[cam]; }
  slam::SensorBatch sensors(const SensorRequest& wanted) override {
    return take_samples(*samples_, wanted, cam_uav_, k_, t_);
  }
  void verdict(const LandmarkObservation& o, const TruthLabel& label, bool accepted) override;
  Labelled<PairObservation> pairs(int cam_a, int cam_b, int needed, const slam::Estimator& est) override;
  std::vector<PointObservation> points(int cam, int needed) override;
  std::optional<Eigen::Vector3d> added(slam::LandmarkId id, int cam, std::int64_t handle,
                                       const Eigen::Vector2d& uv) override;
  void removed(slam::LandmarkId id) override;
  void end_step(double t) override;
  void finish(eval::RunRecord& rec) override;

 private:
  StageTimes produce_and_detect(int k, double t, const slam::Estimator& est);
  void detect_all(StageTimes& st);
  void produce_and_detect_each(int k, double t, StageTimes& st);
  // Camera j's frame of step k into `out`: `regions` alone where the producer can draw them so,
  // else whole; returns whether it is regions.
  bool produce(int j, int k, double t, const std::optional<std::vector<cv::Rect>>& regions, CameraFrame& out);
  // Step k's frames, drawn during step k-1 from its predicted plan: the pixels this step's plan
  // reads and they lack drawn now.
  void take_prefetched(int k, double t, StageTimes& st);
  // Step k+1's frames, from the plan of `est` predicted one step ahead (on this thread, which
  // holds the GL context, while another detects step k).
  void prefetch(int k, const slam::Estimator& est);
  // Cameras whose regions missed the lead: their whole frame, detected again.
  void redo_whole(int k, double t, StageTimes& st);

  const RunConfig& cfg_;
  const sim::Truth& truth_;
  std::vector<int> cam_uav_;
  std::unique_ptr<FrameProducer> frames_;
  std::unique_ptr<SensorSamples> samples_;
  VisionFrontend frontend_;
  GroundTruthLabeller labeller_;
  std::unique_ptr<VideoOverlay> video_;
  bool prefetch_ = false;
  bool regions_ = false;
  std::vector<char> partial_;  // per camera: now_'s frame holds only the frontend's regions
  int k_ = 0;
  double t_ = 0;
  std::vector<CameraFrame> now_;                   // this step's frames, per filter camera
  std::vector<std::optional<Eigen::Vector2d>> lead_;  // this step's lead pixel, per camera
  struct Prefetched {
    int k = -1;  // the step they belong to; -1: none
    std::vector<CameraFrame> frames;
    std::vector<std::optional<std::vector<cv::Rect>>> drawn;  // per camera: its regions, or whole
  } next_;
  eval::FrontendRecord record_;
};

}  // namespace wingman::app
