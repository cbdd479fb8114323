#include "app/pipeline/frame_producer.hpp"

#include <fmt/core.h>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "datasets/dataset.hpp"
#include "app/pipeline/lead_label.hpp"
#include "render/effects.hpp"
#include "render/frame_cache.hpp"
#include "render/renderer.hpp"
#include "render/scene.hpp"

namespace wingman::app {

RendererFrames::RendererFrames(const RunConfig& cfg, std::vector<int> cam_uav, render::GlBackend backend,
                               const sim::Truth& truth, const FrameCacheOptions& cache)
    : cfg_(cfg), cam_uav_(std::move(cam_uav)), truth_(truth) {
  scene_ = std::make_unique<render::Scene>();
  try {
    *scene_ = render::build_scene(sim::describe_world(cfg));
  } catch (const std::runtime_error& e) {  // a missing or broken asset: the scenario's fault
    throw std::invalid_argument(cfg.source_path + ": world: " + e.what());
  }
  ctx_ = render::create_gl_context(backend);
  if (!cache.dir.empty()) {
    // The context's description (driver and its version) keys the frames: another GL stack may
    // draw other pixels.
    keyer_ = std::make_unique<render::FrameKeyer>(*scene_, ctx_->description());
    cache_ = std::make_unique<render::FrameCache>(cache.dir, cache.max_bytes);
    cache_->on_warning([](const std::string& w) { fmt::print(stderr, "warning: {}\n", w); });
  } else {
    renderer_ = std::make_unique<render::Renderer>(*ctx_, *scene_);
    scene_.reset();
  }
  for (int u : cam_uav_) imaging_.push_back(std::make_unique<CameraImaging>(cfg, u));
}

RendererFrames::~RendererFrames() = default;

std::string RendererFrames::description() const { return ctx_->description(); }

render::Renderer& RendererFrames::renderer() {
  if (!renderer_) {  // the first frame the cache did not hold, or the first lead label
    renderer_ = std::make_unique<render::Renderer>(*ctx_, *scene_);
    scene_.reset();
  }
  return *renderer_;
}

render::Frame RendererFrames::render(const render::CameraView& view, const render::LeadPose& lead, int row0,
                                     int rows) {
  return renderer().render_rows(view, lead, row0, rows);
}

void RendererFrames::produce(int cam, int, double t, CameraFrame& out) { take(cam, t, nullptr, false, out); }

void RendererFrames::produce_whole(int cam, int, double t, CameraFrame& out) { take(cam, t, nullptr, true, out); }

bool RendererFrames::produce_regions(int cam, int, double t, const std::vector<cv::Rect>& regions,
                                     CameraFrame& out) {
  if (cache_ || !imaging_[cam]->per_pixel()) return false;
  take(cam, t, &regions, false, out);
  return true;
}

void RendererFrames::produce_more(int cam, int, double t, const std::vector<cv::Rect>& regions, CameraFrame& out) {
  const TakenFrame f = imaging_[cam]->retake(
      truth_, t, [&](const render::CameraView& view, const render::LeadPose& at, int, int) {
        return renderer().render_regions(view, at, regions);
      });
  const cv::Rect image(0, 0, f.frame.rgb.cols, f.frame.rgb.rows);
  for (const cv::Rect& r : regions) {
    const cv::Rect c = r & image;
    if (c.empty()) continue;
    f.frame.rgb(c).copyTo(out.frame.rgb(c));
    f.frame.depth(c).copyTo(out.frame.depth(c));
  }
}

void RendererFrames::take(int cam, double t, const std::vector<cv::Rect>* regions, bool again, CameraFrame& out) {
  CameraImaging& imaging = *imaging_[cam];
  // The lead's label: its silhouette drawn alone at the frame's time (a small window, never cached).
  const render::LeadPose lead = sim::lead_pose(truth_, t, cfg_.world);
  const auto silhouette =
      renderer().lead_silhouette({imaging.model(), true_centre_pose(truth_, cam_uav_[cam], t)}, lead);
  std::vector<cv::Rect> drawn;
  if (regions) {
    drawn = *regions;
    // The label compares the silhouette with the frame's depth in its window: the label's pixels,
    // drawn beside the frontend's (which reads only its own).
    if (silhouette) drawn.push_back(silhouette->window);
  }
  // The cache holds instants: an exposure or a rolling shutter renders every time.
  const bool cached = cache_ && imaging.instant();
  const auto draw = [&](const render::CameraView& view, const render::LeadPose& at, int row0, int rows) {
    if (regions) return renderer().render_regions(view, at, drawn);
    if (!cached) return render(view, at, row0, rows);
    const render::FrameKey key = keyer_->key(view, at);
    if (auto hit = cache_->load(key)) return std::move(*hit);
    render::Frame frame = render(view, at, row0, rows);
    cache_->store(key, frame);
    return frame;
  };
  TakenFrame f = again ? imaging.retake(truth_, t, draw) : imaging.take(truth_, t, draw);
  out.frame = std::move(f.frame);
  out.true_pose = std::move(f.poses);
  out.lead_truth = lead_label(truth_.lead(t).position, imaging.model(), out.true_pose, out.frame.depth, silhouette);
}

void RendererFrames::finish(eval::FrontendRecord& rec) const {
  if (!cache_) return;
  const render::FrameCacheStats& s = cache_->stats();
  rec.frame_cache = {true, cache_->dir().string(), s.hits, s.misses, s.corrupt, s.stores, s.evicted,
                     s.read_ms, s.write_ms, static_cast<double>(s.bytes_read), static_cast<double>(s.bytes_written)};
}

DatasetFrames::DatasetFrames(const datasets::Dataset& ds, std::vector<const datasets::AgentData*> agents,
                             std::vector<int> cam_uav, const sim::Truth& truth)
    : ds_(ds), agents_(std::move(agents)), cam_uav_(std::move(cam_uav)), truth_(truth) {}

void DatasetFrames::produce(int cam, int k, double t, CameraFrame& out) {
  const int u = cam_uav_[cam];
  const datasets::AgentData& a = *agents_[cam];
  out.true_pose = true_poses(truth_.scenario(), truth_, u, t);
  cv::Mat img = ds_.load_image(a.name, a.frames[k]);
  if (img.channels() == 1) cv::cvtColor(img, img, cv::COLOR_GRAY2RGB);
  out.frame.rgb = img;
  out.frame.depth = ds_.load_depth(a.name, a.frames[k]);
  out.lead_truth.reset();  // datasets rendered before labels were written have none
  if (!a.lead_labels.empty()) out.lead_truth = a.lead_labels[k].lead;
}

}  // namespace wingman::app
