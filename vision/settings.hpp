// The vision frontend's settings: the `frontend:` section of a scenario (rendered measurements),
// defined once by the structs of the stages that use them.
#pragma once

#include "vision/active_search.hpp"
#include "vision/cross_match.hpp"
#include "vision/features.hpp"
#include "vision/learned_lead_detector.hpp"
#include "vision/motion_lead_detector.hpp"
#include "vision/tracking.hpp"

namespace wingman::vision {

// Which detector finds the lead in each frame. auto: the world's cue decides (aruco: the marker,
// panel: the colour panel, none: the learned detector); motion: what does not follow the ground.
enum class LeadDetectorKind { Auto, Aruco, Panel, Learned, Motion };

// frontend.learned_lead: the learned detector's network and search.
struct LearnedLeadConfig {
  // The ONNX file (tools/train_lead_detector.py): next to the scenario, then in assets/.
  std::string weights = "lead/lead_detector.onnx";
  LearnedLeadSettings search{};
  // The error of x_h the filter assumes for it (px per axis, estimator.measurement_noise.
  // lead_pixel_sigma: auto): about its p95 on held-out frames (0.75-1.42 px), since its error stays
  // from frame to frame while the lead's look does, and a filter that takes it for white noise
  // trusts it too much.
  double pixel_sigma = 1.5;

  template <class V>
  void visit(V& v) {
    v("weights", weights);
    v("pixel_sigma", pixel_sigma, geometry::in(0.01, 1000.0));
    v("threshold", search.threshold, geometry::in(0.01, 0.99));
    v("window_half_px", search.window_half_px, geometry::in(16, 4096));
  }
};

// frontend.motion_lead: the motion detector's background and blobs (vision/motion_lead_detector.hpp).
struct MotionLeadConfig {
  MotionLeadSettings search{};
  // The error the filter assumes (px per axis): the silhouette's centroid lies about 10 px from
  // a person's x_h.
  double pixel_sigma = 10;

  template <class V>
  void visit(V& v) {
    v("pixel_sigma", pixel_sigma, geometry::in(0.01, 1000.0));
    v("downscale", search.downscale, geometry::in(1, 8));
    v("step_px", search.step_px, geometry::in(1.0, 500.0));
    v("references", search.references, geometry::in(3, 15));
    v("history", search.history, geometry::in(3, 1000));
    v("threshold", search.threshold, geometry::in(1.0, 254.0));
    v("min_area_px", search.min_area_px, geometry::in(1.0, 1e6));
    v("window_half_px", search.window_half_px, geometry::in(8, 4096));
  }
};

struct FrontendSettings {
  FeatureSettings features{};
  TrackingSettings tracking{};
  CrossMatchSettings cross_matching{};
  ActiveSearchSettings active_search{};
  // Diagnostic ablation, never for reported figures: every correspondence the frontend got right
  // (ground-truth label inlier; a detected lead within the match radius) reaches the estimator at
  // its exact true projection instead of its measured pixel. Data association, wrong matches and
  // what is found stay the frontend's, so a run separates the estimator's error from the pixel
  // noise of detection (docs/pipeline_rendered.md).
  bool oracle_pixels = false;
  // The frontend noise model (vision/noise_model.hpp) a rendered run takes the estimator's pixel
  // noise from when it leaves it `auto`: next to the scenario, then in assets/.
  std::string noise_model = "frontend/noise_model.yaml";
  LeadDetectorKind lead_detector = LeadDetectorKind::Auto;
  LearnedLeadConfig learned_lead{};
  MotionLeadConfig motion_lead{};

  template <class V>
  void visit(V& v) {
    features.visit(v);
    v("noise_model", noise_model);
    v.choice("lead_detector", lead_detector,
             {{"auto", LeadDetectorKind::Auto}, {"aruco", LeadDetectorKind::Aruco}, {"panel", LeadDetectorKind::Panel},
              {"learned", LeadDetectorKind::Learned}, {"motion", LeadDetectorKind::Motion}});
    v.section("learned_lead", [&](auto& l) { learned_lead.visit(l); });
    v.section("motion_lead", [&](auto& m) { motion_lead.visit(m); });
    v.section("tracking", [&](auto& t) { tracking.visit(t); });
    v.section("cross_matching", [&](auto& c) { cross_matching.visit(c); });
    v.section("active_search", [&](auto& a) { active_search.visit(a); });
    v("oracle_pixels", oracle_pixels);
  }
};

}  // namespace wingman::vision
