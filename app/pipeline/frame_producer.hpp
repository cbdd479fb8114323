// Where a run's frames come from: the off-screen renderer (every UAV camera at its true pose,
// with the lead at its true pose and the image effects) or a dataset written by `wingman
// render`. Either gives each frame with the true pose it was taken from, for the labeller.
#pragma once

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "app/frontend/labeller.hpp"
#include "app/pipeline/camera_imaging.hpp"
#include "app/config/run_config.hpp"
#include "eval/metrics/run_record.hpp"
#include "render/gl_context.hpp"
#include "sim/truth.hpp"

namespace wingman::datasets {
struct Dataset;
struct AgentData;
}  // namespace wingman::datasets

namespace wingman::render {
class Renderer;
class FrameCache;
class FrameKeyer;
struct Scene;
struct CameraView;
struct Frame;
}  // namespace wingman::render

namespace wingman::app {

class FrameProducer {
 public:
  virtual ~FrameProducer() = default;
  // Filter camera `cam`'s frame of step k at time t.
  virtual void produce(int cam, int k, double t, CameraFrame& out) = 0;
  // The same frame with only `regions`' pixels (the rest 0), where that is the same as the whole
  // frame's inside them; false (and `out` untouched): only the whole frame can be produced.
  virtual bool produce_regions(int /*cam*/, int /*k*/, double /*t*/, const std::vector<cv::Rect>& /*regions*/,
                               CameraFrame& /*out*/) {
    return false;
  }
  // A frame produce_regions() gave for `cam` (of its last two), whole: the same frame, every pixel
  // drawn.
  virtual void produce_whole(int cam, int k, double t, CameraFrame& out) { produce(cam, k, t, out); }
  // The same, with only `regions` drawn into `out`, which holds that frame's other regions.
  virtual void produce_more(int cam, int k, double t, const std::vector<cv::Rect>& /*regions*/, CameraFrame& out) {
    produce_whole(cam, k, t, out);
  }
  virtual std::string description() const = 0;
  // Whether step k+1 may be produced during step k (the renderer in open loop, whose truth is
  // known in advance).
  virtual bool renders() const = 0;
  // Adds how the frames were got (the frame cache's use) to the run's record.
  virtual void finish(eval::FrontendRecord&) const {}
};

// A frame cache for RendererFrames (render/frame_cache.hpp): its directory and size bound.
struct FrameCacheOptions {
  std::string dir;  // empty: no cache
  std::uint64_t max_bytes = 0;
};

// Renders each filter camera (UAV cam_uav[j]) with an OpenGL context of `backend`; throws
// std::invalid_argument naming the scenario for a broken world, render::GlError when no context.
// With a frame cache, a frame the cache holds is read back instead of rendered (the sensor and the
// image effects are applied either way; a frame with an exposure time or a rolling shutter is
// always rendered). The scene is uploaded to the context at the first miss or the first lead label
// (the lead drawn alone, never cached), so every run uploads it once.
class RendererFrames final : public FrameProducer {
 public:
  RendererFrames(const RunConfig& cfg, std::vector<int> cam_uav, render::GlBackend backend,
                 const sim::Truth& truth, const FrameCacheOptions& cache = {});
  ~RendererFrames() override;
  void produce(int cam, int k, double t, CameraFrame& out) override;
  // Without a frame cache, for a camera whose imaging works pixel by pixel
  // (CameraImaging::per_pixel): the renderer's regions, and the lead label's window.
  bool produce_regions(int cam, int k, double t, const std::vector<cv::Rect>& regions, CameraFrame& out) override;
  void produce_whole(int cam, int k, double t, CameraFrame& out) override;
  void produce_more(int cam, int k, double t, const std::vector<cv::Rect>& regions, CameraFrame& out) override;
  std::string description() const override;
  bool renders() const override { return true; }
  void finish(eval::FrontendRecord& rec) const override;

 private:
  render::Renderer& renderer();  // made at the first use: a run the cache holds whole uploads once
  render::Frame render(const render::CameraView& view, const render::LeadPose& lead, int row0, int rows);
  // The frame and its labels; `regions`: only those pixels are drawn.
  void take(int cam, double t, const std::vector<cv::Rect>* regions, bool again, CameraFrame& out);

  const RunConfig& cfg_;
  std::vector<int> cam_uav_;
  const sim::Truth& truth_;
  std::unique_ptr<render::Scene> scene_;  // until the renderer is made
  std::unique_ptr<render::GlContext> ctx_;
  std::unique_ptr<render::Renderer> renderer_;
  std::vector<std::unique_ptr<CameraImaging>> imaging_;
  std::unique_ptr<render::FrameKeyer> keyer_;
  std::unique_ptr<render::FrameCache> cache_;
};

// Loads each filter camera's frames from a dataset; the true poses are the scenario's truth,
// which run_replay checks against the dataset's own.
class DatasetFrames final : public FrameProducer {
 public:
  DatasetFrames(const datasets::Dataset& ds, std::vector<const datasets::AgentData*> agents,
                std::vector<int> cam_uav, const sim::Truth& truth);
  void produce(int cam, int k, double t, CameraFrame& out) override;
  std::string description() const override { return "dataset replay"; }
  bool renders() const override { return false; }

 private:
  const datasets::Dataset& ds_;
  std::vector<const datasets::AgentData*> agents_;  // per filter camera
  std::vector<int> cam_uav_;
  const sim::Truth& truth_;
};

}  // namespace wingman::app
