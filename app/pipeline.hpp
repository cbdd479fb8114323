// The pipeline: truth -> synthetic source or rendered frames + vision frontend -> estimator, and in closed
// loop -> controller -> truth, one step at a time, with the bookkeeping evaluation needs (truth
// of every landmark the filter initialises, outliers injected and accepted, per-stage timings).
// Only app/ wires sim, slam and control.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "eval/run_record.hpp"
#include "render/gl_context.hpp"
#include "app/run_config.hpp"
#include "slam/state.hpp"
#include "vision/features.hpp"

namespace wingman::datasets {
struct Dataset;
}

namespace wingman::app {

// Called after each step with (steps done, steps in total).
using ProgressFn = std::function<void(int, int)>;

// Called after each step with the filter state, for invariant checks (tests) and inspection.
using StateObserver = std::function<void(int, const slam::FilterState&)>;

// Open loop (truth known in advance), or closed loop when the scenario has a control: section:
// then the UAVs fly the sliding-mode controller's commands computed from the estimates (section 6).
// The scenario's `measurements:` mode decides where the visual measurements come from:
// synthetic projections, or frames rendered with an OpenGL context of backend `rendered.gl`.
struct RenderedOptions {
  RenderedOptions(render::GlBackend backend = render::GlBackend::Auto, std::string video_path = {})
      : gl(backend), video(std::move(video_path)) {}
  render::GlBackend gl;
  std::string video;  // non-empty: both cameras side by side with what the frontend did, per step
  // Open loop: render step k+1 while step k's detection runs (same results, less wall time).
  bool prefetch = true;
  // Keep every tracked correspondence with its true projection (RunRecord::frontend).
  bool correspondences = false;
};
eval::RunRecord run_scenario(const RunConfig& scn, const RenderedOptions& rendered = {},
                             const ProgressFn& progress = {}, const StateObserver& observer = {});
// Replays a dataset written by `wingman render` through the same frontend and estimator: its
// frames, GPS/altimeter/range samples; its scenario (the dataset's scenario.yaml, the variant and
// seed it was rendered with) gives the truth, checked against the dataset's camera poses.
// `correspondences`: keep every tracked correspondence, as RenderedOptions::correspondences.
eval::RunRecord run_replay(const RunConfig& scn, const datasets::Dataset& ds,
                           const ProgressFn& progress = {},
                           const std::optional<vision::FeatureSettings>& features = std::nullopt,
                           bool correspondences = false);
// run_scenario with the automatic GL backend (a synthetic scenario never makes a context).
eval::RunRecord run_synthetic(const RunConfig& scn, const ProgressFn& progress = {},
                              const StateObserver& observer = {});

}  // namespace wingman::app
