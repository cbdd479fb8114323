#include "app/frame_producer.hpp"

#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "datasets/dataset.hpp"
#include "render/effects.hpp"
#include "render/renderer.hpp"
#include "render/scene.hpp"

namespace wingman::app {

RendererFrames::RendererFrames(const RunConfig& cfg, std::vector<int> cam_uav, render::GlBackend backend,
                               const sim::Truth& truth)
    : cfg_(cfg), cam_uav_(std::move(cam_uav)), truth_(truth) {
  render::Scene scene;
  try {
    scene = render::build_scene(sim::describe_world(cfg));
  } catch (const std::runtime_error& e) {  // a missing or broken asset: the scenario's fault
    throw std::invalid_argument(cfg.source_path + ": world: " + e.what());
  }
  ctx_ = render::create_gl_context(backend);
  renderer_ = std::make_unique<render::Renderer>(*ctx_, scene);
  for (int u : cam_uav_) {
    models_.push_back(cfg.uavs[u].camera.camera());
    effects_.push_back(std::make_unique<render::ImageEffects>(cfg.world.image, cfg.seed, cfg.uavs[u].name));
  }
}

RendererFrames::~RendererFrames() = default;

std::string RendererFrames::description() const { return ctx_->description(); }

void RendererFrames::produce(int cam, int, double t, CameraFrame& out) {
  const int u = cam_uav_[cam];
  const render::LeadPose lead = sim::lead_pose(truth_, t, cfg_.world);
  out.true_pose = {truth_.camera_R_CW(u, t), truth_.camera(u, t).position};
  out.frame = renderer_->render({models_[cam], out.true_pose}, lead);
  effects_[cam]->apply(out.frame);
}

DatasetFrames::DatasetFrames(const datasets::Dataset& ds, std::vector<const datasets::AgentData*> agents,
                             std::vector<int> cam_uav, const sim::Truth& truth)
    : ds_(ds), agents_(std::move(agents)), cam_uav_(std::move(cam_uav)), truth_(truth) {}

void DatasetFrames::produce(int cam, int k, double t, CameraFrame& out) {
  const int u = cam_uav_[cam];
  const datasets::AgentData& a = *agents_[cam];
  out.true_pose = {truth_.camera_R_CW(u, t), truth_.camera(u, t).position};
  cv::Mat img = ds_.load_image(a.name, a.frames[k]);
  if (img.channels() == 1) cv::cvtColor(img, img, cv::COLOR_GRAY2RGB);
  out.frame.rgb = img;
  out.frame.depth = ds_.load_depth(a.name, a.frames[k]);
}

}  // namespace wingman::app
