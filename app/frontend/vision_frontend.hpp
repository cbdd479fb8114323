// The vision frontend of a run: per camera, the lead detector and features outside the lead's
// box; tracking of the filter's predictions inside their innovation ellipses; cross-UAV matching
// between estimated poses; free features for single-camera landmarks; the descriptor store of the
// map. It sees images and estimates only, never the truth (labels are GroundTruthLabeller's).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/config/run_config.hpp"
#include "render/renderer.hpp"
#include "slam/estimator.hpp"
#include "vision/active_search.hpp"
#include "vision/cross_match.hpp"
#include "vision/descriptor_store.hpp"
#include "vision/features.hpp"
#include "vision/lead_detector.hpp"
#include "vision/motion_lead_detector.hpp"
#include "vision/tracking.hpp"

namespace wingman::app {

// The cross matcher's settings of a run: the frontend section's, with the minimum parallax of
// the estimator's initialisation (validated).
vision::CrossMatchSettings cross_match_settings(const RunConfig& cfg);

// The lead detector of `kind` (auto: lead_detector(cfg)) with the scenario's marker id, the
// learned one from `weights` with `learned`'s search, or the motion detector with the scenario's
// frontend.motion_lead; throws vision::LeadModelError for weights that do not load. One per camera.
std::unique_ptr<vision::LeadFinder> make_lead_finder(const RunConfig& cfg, vision::LeadDetectorKind kind,
                                                     const std::string& weights,
                                                     const vision::LearnedLeadSettings& learned);

class VisionFrontend {
 public:
  // A keypoint the frontend proposes: for a landmark (id >= 0) or a new one (id -1).
  struct Feature {
    slam::LandmarkId id = -1;
    Eigen::Vector2d uv = Eigen::Vector2d::Zero();
    int keypoint = -1;
  };
  struct Pair {
    Feature a, b;
  };
  // What a camera's image showed this step, for the video overlay.
  struct Marks {
    std::vector<Eigen::Vector2d> tracked, accepted, fresh;
  };

  // cam_uav: the UAV of each filter camera. `features` overrides the frontend section's detector
  // settings (bench-frontend compares detectors).
  VisionFrontend(const RunConfig& cfg, const std::vector<int>& cam_uav,
                 const std::optional<vision::FeatureSettings>& features = std::nullopt);

  std::string detector_name() const { return vision::to_string(features_.settings().kind); }
  const geometry::PinholeCamera& model(int cam) const { return cams_[cam].model; }
  int num_cameras() const { return static_cast<int>(cams_.size()); }

  // Once a step, before its detection: where the predicted state puts the lead in every camera,
  // and what active search needs (every camera's predictions and gates, the blocks for new
  // landmarks).
  void plan_step(const slam::Estimator& est);
  // The pixels of camera `cam`'s frame that detect() reads this step when the lead is found in
  // its finder's window: the planned crops with the detector's margin, and that window. Nothing:
  // the whole frame (no active search or a whole-frame plan, no prediction of the lead, or a
  // finder that reads the whole image).
  std::optional<std::vector<cv::Rect>> reads(int cam) const { return reads(cam, cams_[cam].plan); }
  // What reads() would give every camera for a step planned from `est` (a state predicted ahead,
  // to draw a step's frames before its plan exists). Touches no camera's state: it may run while
  // another thread detects.
  std::vector<std::optional<std::vector<cv::Rect>>> reads_for(const slam::Estimator& est) const;
  // The lead, searched first around where the estimate projects it, then features outside its
  // box; returns the milliseconds spent. Cameras may detect on different threads, one at a time.
  // `partial`: the frame holds only reads(cam)'s pixels; a lead not found in the finder's window
  // then leaves needs_whole_frame(cam) set and nothing detected.
  double detect(int cam, const render::Frame& frame, bool partial = false);
  bool needs_whole_frame(int cam) const { return cams_[cam].needs_whole_frame; }
  std::optional<Eigen::Vector2d> lead(int cam) const { return cams_[cam].lead; }

  // Keypoints for the filter's predictions in camera `cam`, by descriptor inside each ellipse.
  std::vector<Feature> track(int cam, const std::vector<slam::LandmarkPrediction>& preds);
  // The filter accepted a tracked feature: its descriptor becomes the landmark's latest.
  void accepted(int cam, const Feature& f, std::int64_t frame);
  // Free features matched between two cameras (estimated poses), spread, at most `needed`.
  std::vector<Pair> cross_match(int cam_a, int cam_b, int needed, const slam::Estimator& est);
  // Free features of one camera, strongest first and spread, at most `needed`.
  std::vector<Feature> new_points(int cam, int needed);
  // A landmark was made from camera `cam`'s keypoint: its descriptor joins the store.
  void added(slam::LandmarkId id, int cam, int keypoint, std::int64_t frame);
  void removed(slam::LandmarkId id) { store_.remove(id); }

  const Marks& marks(int cam) const { return cams_[cam].marks; }
  // The last detection's share of the frame's pixels that the detector processed (active search).
  double searched_fraction(int cam) const { return cams_[cam].searched; }

 private:
  // What a step's detection in one camera is planned to be.
  struct CameraPlan {
    std::vector<vision::LandmarkPrediction> in_view;  // for active search
    std::vector<cv::Rect> blocks;                      // where new landmarks are searched
    std::optional<vision::SearchPlan> search;          // the crops; nothing: no active search
    std::optional<Eigen::Vector2d> lead;               // the lead's pixel by the estimate
    double lead_depth = 0;                             // and its depth along the optical axis
  };
  struct Cam {
    geometry::PinholeCamera model;
    vision::Features features;
    std::vector<vision::LandmarkPrediction> preds;  // this step's, for free features and spread
    std::vector<bool> used;                         // keypoints taken by tracking or matching
    std::unique_ptr<vision::LeadFinder> lead_finder;  // its own: a finder may keep earlier frames
    std::optional<Eigen::Vector2d> lead;
    Marks marks;
    double searched = 1.0;
    CameraPlan plan;  // plan_step's
    bool needs_whole_frame = false;
  };
  std::vector<CameraPlan> make_plans(const slam::Estimator& est) const;
  std::optional<std::vector<cv::Rect>> reads(int cam, const CameraPlan& plan) const;
  vision::Features detect_features(int cam, const cv::Mat& grey, const std::vector<vision::ExclusionBox>& exclude);
  std::vector<cv::Rect> carry_blocks(const std::vector<cv::Rect>& blocks, int from, int to, double ground_z,
                                     const slam::Estimator& est) const;
  const RunConfig& cfg_;
  vision::FeatureExtractor features_;
  vision::TrackingSettings tracking_;
  vision::CrossMatchSettings cross_;
  vision::DescriptorStore store_;
  std::vector<Cam> cams_;
  bool colour_lead_ = false;
};

}  // namespace wingman::app
