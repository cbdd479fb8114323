// The vision frontend's settings: the `frontend:` section of a scenario (rendered measurements),
// defined once by the structs of the stages that use them.
#pragma once

#include "vision/active_search.hpp"
#include "vision/cross_match.hpp"
#include "vision/features.hpp"
#include "vision/learned_lead_detector.hpp"
#include "vision/tracking.hpp"

namespace wingman::vision {

// Which detector finds the lead in each frame. auto: the world's cue decides (aruco: the marker,
// panel: the colour panel, none: the learned detector).
enum class LeadDetectorKind { Auto, Aruco, Panel, Learned };

// frontend.learned_lead: the learned detector's network and search.
struct LearnedLeadConfig {
  // The ONNX file (tools/train_lead_detector.py): next to the scenario, then in assets/.
  std::string weights = "lead/lead_detector.onnx";
  LearnedLeadSettings search{};

  template <class V>
  void visit(V& v) {
    v("weights", weights);
    v("threshold", search.threshold, geometry::in(0.01, 0.99));
    v("window_half_px", search.window_half_px, geometry::in(16, 4096));
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

  template <class V>
  void visit(V& v) {
    features.visit(v);
    v("noise_model", noise_model);
    v.choice("lead_detector", lead_detector,
             {{"auto", LeadDetectorKind::Auto}, {"aruco", LeadDetectorKind::Aruco}, {"panel", LeadDetectorKind::Panel},
              {"learned", LeadDetectorKind::Learned}});
    v.section("learned_lead", [&](auto& l) { learned_lead.visit(l); });
    v.section("tracking", [&](auto& t) { tracking.visit(t); });
    v.section("cross_matching", [&](auto& c) { cross_matching.visit(c); });
    v.section("active_search", [&](auto& a) { active_search.visit(a); });
    v("oracle_pixels", oracle_pixels);
  }
};

}  // namespace wingman::vision
