// A run end to end: the truth (open loop, or closed loop when the scenario has a control:
// section), the measurement source its `measurements:` mode names (synthetic projections, or
// frames rendered with an OpenGL context of backend `gl` through the vision frontend), and the
// estimator's loop (app/pipeline/loop.hpp) with the bookkeeping evaluation needs. Only app/ wires sim,
// render, vision, slam and control.
#pragma once

#include <optional>
#include <string>

#include "app/pipeline/frame_producer.hpp"
#include "app/pipeline/loop.hpp"
#include "app/config/run_config.hpp"
#include "eval/metrics/run_record.hpp"
#include "render/gl_context.hpp"
#include "vision/features.hpp"

namespace wingman::datasets {
struct Dataset;
}

namespace wingman::app {

struct RenderedOptions {
  RenderedOptions(render::GlBackend backend = render::GlBackend::Auto, std::string video_path = {})
      : gl(backend), video(std::move(video_path)) {}
  render::GlBackend gl;
  // Non-empty: every filter camera side by side with what the frontend did, per step (VideoOverlay).
  std::string video;
  // Open loop: render step k+1 while step k's detection runs (same results, less wall time).
  bool prefetch = true;
  // With active search: draw only the regions the frontend reads (same results, less rendering);
  // false: whole frames, the reference path.
  bool regions = true;
  // Keep every tracked correspondence with its true projection (RunRecord::frontend).
  bool correspondences = false;
  // Read frames the cache holds instead of rendering them (RendererFrames).
  FrameCacheOptions frame_cache;
};
eval::RunRecord run_scenario(const RunConfig& cfg, const RenderedOptions& rendered = {},
                             const ProgressFn& progress = {}, const StateObserver& observer = {});
// Replays a dataset written by `wingman render` through the same frontend and estimator: its
// frames, GPS/altimeter/range samples; its scenario (the dataset's scenario.yaml, the variant and
// seed it was rendered with) gives the truth, checked against the dataset's camera poses.
// `correspondences`: keep every tracked correspondence, as RenderedOptions::correspondences.
eval::RunRecord run_replay(const RunConfig& cfg, const datasets::Dataset& ds, const ProgressFn& progress = {},
                           const std::optional<vision::FeatureSettings>& features = std::nullopt,
                           bool correspondences = false);
// run_scenario with the automatic GL backend (a synthetic scenario never makes a context).
eval::RunRecord run_synthetic(const RunConfig& cfg, const ProgressFn& progress = {},
                              const StateObserver& observer = {});

}  // namespace wingman::app
