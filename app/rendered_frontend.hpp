// The rendered measurement source (`measurements: rendered`): each step renders every UAV camera
// at its true pose, runs the vision frontend on the frames and hands the estimator what it
// consumes (landmark candidates, lead pixels, cross-UAV pixel pairs, single-camera pixels), in
// slam's types. Ground truth (true poses, rendered depth) is used only to label what the frontend
// produced, for Table 3, the lead detector's figures and the landmarks' truth (DESIGN.md §7);
// the frontend's own decisions see only images and estimated poses. Only app/ wires render,
// vision and slam.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <unordered_map>
#include <vector>

#include <opencv2/videoio.hpp>

#include "app/run_config.hpp"
#include "eval/run_record.hpp"
#include "render/gl_context.hpp"
#include "render/renderer.hpp"
#include "sim/scenario.hpp"
#include "sim/truth.hpp"
#include "slam/estimator.hpp"
#include "vision/cross_match.hpp"
#include "vision/descriptor_store.hpp"
#include "vision/features.hpp"
#include "vision/labelling.hpp"
#include "vision/lead_detector.hpp"
#include "vision/tracking.hpp"

namespace wingman::render {
class ImageEffects;
}

namespace wingman::app {

struct StageTimes {
  double render_ms = 0;  // rendering (or loading) summed over the cameras
  double detect_ms = 0;  // detection summed over the cameras, part of it during rendering
  double wall_ms = 0;    // the whole of render_and_detect
};

// A landmark correspondence proposed by tracking, with its ground-truth label.
struct LabelledCorrespondence {
  slam::Correspondence c;
  int keypoint = -1;
  bool outlier = false;  // > 3 px from the true projection, occluded, or no truth
  double error_px = std::numeric_limits<double>::quiet_NaN();  // to the true projection
  Eigen::Vector2d true_uv = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
};

// A cross-UAV pixel pair for initialisation, with its label and what the store needs.
struct LabelledPair {
  slam::CrossMatch m;
  int keypoint_a = -1;
  bool outlier = false;
};

// Frames of filter camera `cam` at step k from somewhere other than the renderer (a dataset).
using FrameSource = std::function<render::Frame(int cam, int k)>;

// The cross matcher's settings of a run: the frontend section's, with the minimum parallax of
// the estimator's initialisation (validated).
vision::CrossMatchSettings cross_match_settings(const RunConfig& cfg);

class RenderedFrontend {
 public:
  // cam_uav: the UAV index of each filter camera (all UAVs, or the single-UAV baseline's one).
  RenderedFrontend(const RunConfig& scn, std::vector<int> cam_uav, render::GlBackend backend);
  // Replay: frames from `frames` (already with their image effects), no GL context; features
  // as `features` says (bench-frontend compares detectors), else as the scenario says.
  RenderedFrontend(const RunConfig& scn, std::vector<int> cam_uav, FrameSource frames,
                   const std::optional<vision::FeatureSettings>& features = std::nullopt);
  ~RenderedFrontend();
  RenderedFrontend(const RenderedFrontend&) = delete;
  RenderedFrontend& operator=(const RenderedFrontend&) = delete;

  std::string renderer_description() const;
  std::string detector_name() const { return vision::to_string(features_.settings().kind); }

  // Renders (or loads) every camera's frame of step k at t (true pose, gimbal error included),
  // then per camera the lead detection (searched first around the estimate's projection) and
  // features outside the lead's box; updates the lead detector's tallies in `fr`. Camera j's
  // detection overlaps camera j+1's rendering, so the two times may add up to more than the wall.
  // With prefetch on, step k's frames were rendered during step k-1, and step k+1's are rendered
  // while step k's detection runs on a second thread.
  StageTimes render_and_detect(const sim::Truth& truth, int k, double t, const slam::Estimator& est,
                               eval::FrontendRecord& fr);
  // Open loop only: the truth of step k+1 must be known at step k. Ignored on dataset replay.
  // The frames, and so every result, are the same with it on or off; only the timing changes.
  void set_prefetch(bool on) { prefetch_ = on && !frames_; }
  std::optional<Eigen::Vector2d> lead_pixel(int cam) const { return cams_[cam].lead; }

  // Tracking of the filter's predictions in camera `cam`, labelled against the truth.
  std::vector<LabelledCorrespondence> track(int cam, const std::vector<slam::LandmarkPrediction>& preds);
  // The filter accepted this correspondence: refresh the landmark's descriptor.
  void accepted(const LabelledCorrespondence& c, std::int64_t frame);

  // Cross-UAV matches of free features between two cameras (estimated poses), spread over the
  // images, at most `needed`, labelled.
  std::vector<LabelledPair> cross_match(int cam_a, int cam_b, int needed,
                                        const slam::Estimator& est);
  // Free features of one camera for single-camera initialisation, spread, at most `needed`.
  std::vector<LabelledCorrespondence> new_points(int cam, int needed);

  // A landmark was initialised from the feature `keypoint` of camera `cam` at `uv`: keep its
  // descriptor, and its truth (back-projection through the true pose and rendered depth).
  // Returns the truth, or nothing when the pixel has no rendered surface.
  std::optional<Eigen::Vector3d> added(slam::LandmarkId id, int cam, int keypoint,
                                       const Eigen::Vector2d& uv, std::int64_t frame);
  void removed(slam::LandmarkId id);

  // --video: every camera side by side (half size) per step, with tracked landmarks (green when
  // the filter accepted them, red when it rejected them), new landmarks' pixels (yellow) and the
  // lead detection (magenta). Throws std::invalid_argument naming the file if it cannot be opened.
  void open_video(const std::string& path);
  void write_video_frame(double t);

 private:
  // What both constructors set up: the cameras' models and the frontend's settings from scn_.
  void init_cameras();
  double detect_camera(int cam, const slam::Estimator& est);  // ms spent
  // Camera j's true pose and rendered frame (image effects applied) at time t.
  void render_camera(const sim::Truth& truth, int j, double t, const render::LeadPose& lead,
                     render::Frame& frame, vision::CameraPose& pose);
  render::LeadPose true_lead_pose(const sim::Truth& truth, double t) const;
  struct Cam {
    geometry::PinholeCamera model;
    render::Frame frame;
    vision::CameraPose true_pose;
    vision::Features features;
    std::vector<vision::LandmarkPrediction> preds;  // this step's, for free features and spread
    std::vector<bool> used;                         // keypoints taken by tracking
    std::optional<Eigen::Vector2d> lead;
    std::vector<Eigen::Vector2d> tracked, accepted, fresh;  // this step's, for the video
  };
  const RunConfig& scn_;
  std::vector<int> cam_uav_;
  FrameSource frames_;
  std::unique_ptr<render::GlContext> ctx_;
  std::unique_ptr<render::Renderer> renderer_;
  std::vector<std::unique_ptr<render::ImageEffects>> effects_;
  vision::FeatureExtractor features_;
  vision::LeadDetector lead_;
  vision::TrackingSettings tracking_;
  vision::CrossMatchSettings cross_;
  vision::DescriptorStore store_;
  std::unordered_map<slam::LandmarkId, std::optional<Eigen::Vector3d>> truth_;
  std::vector<Cam> cams_;
  bool colour_lead_ = false;
  std::unique_ptr<cv::VideoWriter> video_;
  std::string video_path_;
  bool prefetch_ = false;
  struct Prefetched {
    int k = -1;  // the step they belong to; -1: none
    std::vector<render::Frame> frames;
    std::vector<vision::CameraPose> poses;
  } next_;
};

}  // namespace wingman::app
