// Where a run's frames come from: the off-screen renderer (every UAV camera at its true pose,
// with the lead at its true pose and the image effects) or a dataset written by `wingman
// render`. Either gives each frame with the true pose it was taken from, for the labeller.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "app/labeller.hpp"
#include "app/run_config.hpp"
#include "render/gl_context.hpp"
#include "sim/truth.hpp"

namespace wingman::datasets {
struct Dataset;
struct AgentData;
}  // namespace wingman::datasets

namespace wingman::render {
class ImageEffects;
class Renderer;
}  // namespace wingman::render

namespace wingman::app {

class FrameProducer {
 public:
  virtual ~FrameProducer() = default;
  // Filter camera `cam`'s frame of step k at time t.
  virtual void produce(int cam, int k, double t, CameraFrame& out) = 0;
  virtual std::string description() const = 0;
  // Whether step k+1 may be produced during step k (the renderer in open loop, whose truth is
  // known in advance).
  virtual bool renders() const = 0;
};

// Renders each filter camera (UAV cam_uav[j]) with an OpenGL context of `backend`; throws
// std::invalid_argument naming the scenario for a broken world, render::GlError when no context.
class RendererFrames final : public FrameProducer {
 public:
  RendererFrames(const RunConfig& cfg, std::vector<int> cam_uav, render::GlBackend backend,
                 const sim::Truth& truth);
  ~RendererFrames() override;
  void produce(int cam, int k, double t, CameraFrame& out) override;
  std::string description() const override;
  bool renders() const override { return true; }

 private:
  const RunConfig& cfg_;
  std::vector<int> cam_uav_;
  const sim::Truth& truth_;
  std::vector<geometry::PinholeCamera> models_;
  std::unique_ptr<render::GlContext> ctx_;
  std::unique_ptr<render::Renderer> renderer_;
  std::vector<std::unique_ptr<render::ImageEffects>> effects_;
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
