// Frames per second of one 1000 x 1000 camera of the paper's scene (scenes/paper_synthetic.yaml:
// the default world; Quad 1 at t = 20 s with the lead in view), colour and depth read back, per GL
// backend, for a few MSAA, anisotropy and mipmap-filter settings. A backend that cannot make a
// context here is reported as skipped with the reason.
// Beside them the floor (BM_FloorEgl, BM_FloorOsMesa): one textured quad filling the same
// 1000 x 1000 frame, drawn and read back as colour + metric depth through the same Renderer, so
// that a scene's time over the floor's is the renderer's cost over what the machine and its GL
// allow, one ratio that holds on any machine. Stages beside them: region rendering (BM_RegionsEgl)
// and the readback alone per format (BM_ReadbackEgl).
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <random>
#include <vector>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "app/pipeline/camera_imaging.hpp"
#include "bench/process_cpu.hpp"
#include "render/gl_context.hpp"
#include "render/gl_functions.hpp"
#include "render/ground_bake.hpp"
#include "render/renderer.hpp"
#include "render/sensor.hpp"
#include "render/scene.hpp"
#include "sim/scenario.hpp"
#include "sim/truth.hpp"

#ifndef WINGMAN_SOURCE_DIR
#define WINGMAN_SOURCE_DIR "."
#endif

namespace {

using namespace wingman;

using bench::process_cpu_seconds;

// A context of the backend, or nullptr with the benchmark skipped and the reason given.
std::unique_ptr<render::GlContext> context_or_skip(benchmark::State& state, render::GlBackend backend) {
  try {
    return render::create_gl_context(backend);
  } catch (const render::GlContextError& e) {
    state.SkipWithError(e.what());
    for (auto _ : state) {
    }
    return nullptr;
  }
}

// Renders the view over and over (after one warm-up frame: framebuffers, shader compilation),
// reporting frames per second and the process's CPU per frame.
// regions: null for the whole frame, else render_regions() over them.
void time_frames(benchmark::State& state, render::Renderer& renderer, const render::CameraView& view,
                 const std::optional<render::LeadPose>& lead, const std::vector<cv::Rect>* regions = nullptr) {
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) {
    render::Frame f = regions ? renderer.render_regions(view, lead, *regions) : renderer.render(view, lead);
    benchmark::DoNotOptimize(f.rgb.data);
    benchmark::DoNotOptimize(f.depth.data);
  }
  state.counters["fps"] = benchmark::Counter(static_cast<double>(state.iterations()),
                                             benchmark::Counter::kIsRate);
  state.counters["cpu_ms"] = 1e3 * (process_cpu_seconds() - cpu0) / static_cast<double>(state.iterations());
  state.SetLabel(renderer.context().description());
}

// The benchmark's arguments: MSAA samples, max anisotropy, trilinear (1) or bilinear (0).
void apply_quality(const benchmark::State& state, sim::Scenario& scn) {
  scn.world.image.msaa = static_cast<int>(state.range(0));
  scn.world.texture.anisotropy = static_cast<double>(state.range(1));
  scn.world.texture.filter =
      state.range(2) ? sim::TextureSpec::Filter::Trilinear : sim::TextureSpec::Filter::Bilinear;
}

// Quad 1's camera at t = 20 s in the paper's scene, and the lead then.
struct PaperShot {
  render::CameraView view;
  render::LeadPose lead;
};
PaperShot paper_shot(const sim::Scenario& scn) {
  const sim::OpenLoopTruth truth(scn);
  const double t = 20.0;
  const render::CameraView view{scn.uavs[0].camera.camera(), truth.camera_R_CW(0, t),
                                truth.camera(0, t).position};
  return {view, sim::lead_pose(truth, t, scn.world)};
}

void render_paper_camera(benchmark::State& state, render::GlBackend backend) {
  sim::Scenario scn = sim::load_scenarios(WINGMAN_SOURCE_DIR "/scenes/paper_synthetic.yaml").front();
  apply_quality(state, scn);
  const auto ctx = context_or_skip(state, backend);
  if (!ctx) return;
  render::Renderer renderer(*ctx, render::build_scene(sim::describe_world(scn)));
  const auto [view, lead] = paper_shot(scn);
  renderer.render(view, lead);  // warm-up
  time_frames(state, renderer, view, lead);
}

// Region rendering (Renderer::render_regions) of the same camera at the default quality: `gates`
// squares of 48 px (a landmark's search box with the detector's context) scattered over the frame
// and 3 blocks of 125 px where the map wants new landmarks, about what active search reads; the
// counter `fraction` is the share of the frame's pixels they cover.
void render_paper_regions(benchmark::State& state) {
  sim::Scenario scn = sim::load_scenarios(WINGMAN_SOURCE_DIR "/scenes/paper_synthetic.yaml").front();
  const auto ctx = context_or_skip(state, render::GlBackend::Egl);
  if (!ctx) return;
  render::Renderer renderer(*ctx, render::build_scene(sim::describe_world(scn)));
  const auto [view, lead] = paper_shot(scn);
  const int w = view.camera.width(), h = view.camera.height();
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> x(0, w - 48), y(0, h - 48);
  std::vector<cv::Rect> regions;
  for (int i = 0; i < state.range(0); ++i) regions.emplace_back(x(rng), y(rng), 48, 48);
  for (int i = 0; i < 3; ++i) regions.emplace_back(w / 2 - 187 + 125 * i, h / 2 - 62, 125, 125);
  cv::Mat covered = cv::Mat::zeros(h, w, CV_8U);
  for (const auto& r : regions) covered(r & cv::Rect(0, 0, w, h)).setTo(1);
  renderer.render_regions(view, lead, regions);  // warm-up
  time_frames(state, renderer, view, lead, &regions);
  state.counters["fraction"] = static_cast<double>(cv::countNonZero(covered)) / (w * h);
}

// The floor's scene: a 200 m square of the paper world's ground texture under a camera at 15 m
// looking straight down, which it fills (the footprint is 75 m); no MSAA, no anisotropy, bilinear.
render::Scene floor_scene() {
  const sim::Scenario scn = sim::load_scenarios(WINGMAN_SOURCE_DIR "/scenes/paper_synthetic.yaml").front();
  render::Scene world = render::build_scene(sim::describe_world(scn));
  render::Scene s;
  s.msaa = 1;
  render::Material ground = world.materials.at(static_cast<std::size_t>(world.static_meshes.front().material));
  ground.anisotropy = 1;
  ground.trilinear = false;
  // The tiling drawn live, as the floor has always drawn it: floor-frames stay comparable across
  // versions however the scenes' ground is drawn (baked by default).
  ground.bake = false;
  s.materials = {ground};
  render::Mesh quad;
  const Eigen::Vector3d up(0, 0, 1), white(1, 1, 1);
  quad.add({-100, -100, 0}, up, {0, 0}, white);
  quad.add({100, -100, 0}, up, {8, 0}, white);
  quad.add({100, 100, 0}, up, {8, 8}, white);
  quad.add({-100, 100, 0}, up, {0, 8}, white);
  quad.indices = {0, 1, 2, 0, 2, 3};
  quad.material = 0;
  s.static_meshes = {quad};
  return s;
}

void render_floor(benchmark::State& state, render::GlBackend backend) {
  const auto ctx = context_or_skip(state, backend);
  if (!ctx) return;
  render::Renderer renderer(*ctx, floor_scene());
  geometry::CameraPose pose;
  pose.R_CW = Eigen::Vector3d(1, -1, -1).asDiagonal();  // optical axis down, image x along world x
  pose.position = {0, 0, 15};
  const render::CameraView view{geometry::PinholeCamera(200.1, 200.1, 500, 500, 1000, 1000), pose};
  const render::Frame first = renderer.render(view);  // warm-up, and the floor's own check
  if (cv::countNonZero(first.depth) != first.depth.rows * first.depth.cols) {
    state.SkipWithError("the floor's quad does not fill the frame");
    for (auto _ : state) {
    }
    return;
  }
  time_frames(state, renderer, view, std::nullopt);
}

void BM_FloorEgl(benchmark::State& s) { render_floor(s, render::GlBackend::Egl); }
void BM_FloorOsMesa(benchmark::State& s) { render_floor(s, render::GlBackend::OsMesa); }
BENCHMARK(BM_FloorEgl)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FloorOsMesa)->Unit(benchmark::kMillisecond)->UseRealTime();

// The readback stage alone: a 1000 x 1000 framebuffer cleared and read into memory, per format,
// to price what a lighter frame would save against the floor. Argument: 0 the renderer's colour
// (an RGBA8 buffer read as GL_RGBA, then RGBA to RGB and RGB to grey on the CPU, what a run
// does), 1 the same buffer read as GL_RED (the format mismatches the buffer's), 2 an R8 buffer
// read as GL_RED (a grey target), 3 the 32-bit float depth buffer read as GL_FLOAT, 4 path 0
// through a pixel buffer object (read into the buffer, mapped, converted from the mapping).
void readback(benchmark::State& state) {
  const auto ctx = context_or_skip(state, render::GlBackend::Egl);
  if (!ctx) return;
  ctx->make_current();
  render::GlFunctions gl;
  gl.load(*ctx);
  const int w = 1000, h = 1000, path = static_cast<int>(state.range(0));
  GLuint fbo = 0, rb = 0;
  gl.GenFramebuffers(1, &fbo);
  gl.BindFramebuffer(GL_FRAMEBUFFER, fbo);
  gl.GenRenderbuffers(1, &rb);
  gl.BindRenderbuffer(GL_RENDERBUFFER, rb);
  const bool depth = path == 3, pbo = path == 4;
  gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, 0, depth ? GL_DEPTH_COMPONENT32F : path == 2 ? GL_R8 : GL_RGBA8,
                                    w, h);
  gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, depth ? GL_DEPTH_ATTACHMENT : GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb);
  if (depth) {
    const GLenum none = GL_NONE;
    gl.DrawBuffers(1, &none);
    gl.ReadBuffer(GL_NONE);
  } else {
    gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
  }
  gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
  const auto map = reinterpret_cast<PFNGLMAPBUFFERRANGEPROC>(ctx->proc_address("glMapBufferRange"));
  const auto unmap = reinterpret_cast<PFNGLUNMAPBUFFERPROC>(ctx->proc_address("glUnmapBuffer"));
  GLuint buffer = 0;
  if (pbo) {
    gl.GenBuffers(1, &buffer);
    gl.BindBuffer(GL_PIXEL_PACK_BUFFER, buffer);
    gl.BufferData(GL_PIXEL_PACK_BUFFER, 4 * w * h, nullptr, GL_STREAM_READ);
  }
  cv::Mat out(h, w, path == 0 || pbo ? CV_8UC4 : depth ? CV_32F : CV_8U), rgb, grey;
  const float clear[4] = {0.25f, 0.5f, 0.75f, 1.f}, one = 0.5f;
  const GLenum format = path == 0 || pbo ? GL_RGBA : depth ? GL_DEPTH_COMPONENT : GL_RED;
  const GLenum type = depth ? GL_FLOAT : GL_UNSIGNED_BYTE;
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) {
    if (depth) gl.ClearBufferfv(GL_DEPTH, 0, &one);
    else gl.ClearBufferfv(GL_COLOR, 0, clear);
    gl.ReadPixels(0, 0, w, h, format, type, pbo ? nullptr : out.data);
    if (pbo) {
      const cv::Mat mapped(h, w, CV_8UC4, map(GL_PIXEL_PACK_BUFFER, 0, 4 * w * h, GL_MAP_READ_BIT));
      cv::cvtColor(mapped, rgb, cv::COLOR_RGBA2RGB);
      unmap(GL_PIXEL_PACK_BUFFER);
      cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
    } else if (path == 0) {
      cv::cvtColor(out, rgb, cv::COLOR_RGBA2RGB);
      cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
    }
    benchmark::DoNotOptimize(out.data);
  }
  state.counters["cpu_ms"] = 1e3 * (process_cpu_seconds() - cpu0) / static_cast<double>(state.iterations());
  if (gl.GetError() != GL_NO_ERROR) state.SkipWithError("OpenGL error while reading back");
  if (pbo) gl.DeleteBuffers(1, &buffer);
  gl.DeleteFramebuffers(1, &fbo);
  gl.DeleteRenderbuffers(1, &rb);
  state.SetLabel(ctx->description());
}
void BM_ReadbackEgl(benchmark::State& s) { readback(s); }
BENCHMARK(BM_ReadbackEgl)->DenseRange(0, 4)->ArgName("path")->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_RenderEgl(benchmark::State& s) { render_paper_camera(s, render::GlBackend::Egl); }
void BM_RegionsEgl(benchmark::State& s) { render_paper_regions(s); }
BENCHMARK(BM_RegionsEgl)->Arg(20)->Arg(60)->Arg(120)->ArgName("gates")->Unit(benchmark::kMillisecond)->UseRealTime();
void BM_RenderOsMesa(benchmark::State& s) { render_paper_camera(s, render::GlBackend::OsMesa); }

// Arguments: MSAA samples, max anisotropy, trilinear (1) or bilinear (0) between mipmap levels
// (world.texture.filter). {4, 4, 1} is the world section's default, {1, 1, 0} the fastest.
BENCHMARK(BM_RenderEgl)->Args({1, 1, 1})->Args({1, 1, 0})->Args({1, 4, 1})->Args({4, 1, 1})->Args({4, 4, 1})->ArgNames({"msaa", "aniso", "trilinear"})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RenderOsMesa)->Args({1, 1, 1})->Args({1, 1, 0})->Args({4, 4, 1})->ArgNames({"msaa", "aniso", "trilinear"})->Unit(benchmark::kMillisecond)->UseRealTime();

// The image-quality sweep: a 640 x 480 camera (f = 420 px, 75 deg across) at 24 poses over a
// world dense with every kind of object (boulders, trees, buildings, the truck), 8-30 m above an
// object and tilted up to 25 deg, each pose rendered once per iteration. Per setting it reports
// the median and the worst frame time (wall, ms): a stall shows in the worst frame, not in the
// mean of a benchmark that repeats one view.
struct SweepWorld {
  sim::Scenario scn;
  std::vector<render::CameraView> views;
  render::LeadPose lead;
};

const SweepWorld& sweep_world() {
  static const SweepWorld w = [] {
    SweepWorld out;
    out.scn = sim::load_scenarios(WINGMAN_SOURCE_DIR "/scenes/paper_synthetic.yaml").front();
    out.scn.world.objects.boulders = 80;
    out.scn.world.objects.trees = 50;
    out.scn.world.objects.buildings = 6;
    const sim::WorldDescription desc = sim::describe_world(out.scn);
    const sim::OpenLoopTruth truth(out.scn);
    out.lead = sim::lead_pose(truth, 20.0, out.scn.world);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0, 1);
    const geometry::PinholeCamera cam(420, 420, 319.5, 239.5, 640, 480);
    const std::size_t n = 24;
    for (std::size_t k = 0; k < n; ++k) {
      // Every third pose over the lead; the others over objects spread through the list.
      const Eigen::Vector3d target = k % 3 == 0 || desc.objects.empty()
                                         ? out.lead.position
                                         : desc.objects[(k * 7919) % desc.objects.size()].position;
      const double height = 8 + 22 * u(rng), tilt = 25 * M_PI / 180 * u(rng), yaw = 2 * M_PI * u(rng);
      const Eigen::Matrix3d nadir = Eigen::Vector3d(1, -1, -1).asDiagonal();
      const Eigen::Matrix3d R_WC = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                                   Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitX()).toRotationMatrix() *
                                   nadir.transpose();
      geometry::CameraPose pose;
      pose.R_CW = R_WC.transpose();
      pose.position = target + Eigen::Vector3d(0, 0, height);
      out.views.push_back({cam, pose});
    }
    return out;
  }();
  return w;
}

void quality_sweep(benchmark::State& state, render::GlBackend backend) {
  sim::Scenario scn = sweep_world().scn;
  apply_quality(state, scn);
  const auto ctx = context_or_skip(state, backend);
  if (!ctx) return;
  render::Renderer renderer(*ctx, render::build_scene(sim::describe_world(scn)));
  const auto& views = sweep_world().views;
  renderer.render(views.front(), sweep_world().lead);  // warm-up
  std::vector<double> ms;
  for (auto _ : state) {
    for (const auto& v : views) {
      const auto t0 = std::chrono::steady_clock::now();
      render::Frame f = renderer.render(v, sweep_world().lead);
      benchmark::DoNotOptimize(f.rgb.data);
      ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
  }
  std::sort(ms.begin(), ms.end());
  state.counters["median_ms"] = ms[ms.size() / 2];
  state.counters["worst_ms"] = ms.back();
  state.counters["worst_over_median"] = ms.back() / ms[ms.size() / 2];
  state.SetLabel(renderer.context().description());
}

// The camera effects (sim/camera_sensor.hpp) on one 1000 x 1000 camera of
// scenes/paper_rendered_fast.yaml (MSAA 1, anisotropy 1) at t = 20 s, through the imaging chain
// the runs use (app/pipeline/camera_imaging.hpp). Argument: 0 ideal; 1 a 10 ms exposure (as many
// images as the image motion needs, at most 9); 2 rolling shutter, every row drawn alone (the
// reference); 3 rolling shutter in bands of 10 rows; 4 physical sensor with auto-exposure; 5 all of
// them at their defaults (rolling shutter in one pass, the exposure's images by the image motion,
// physical sensor); 6 the sun's shadows (a 2048 px shadow map each frame); 7 the ground by repeat
// tiling (one lookup where the default stochastic tiling takes three); 8 the clear-sky light
// model; 9 all of them with the sun's shadows; 10 rolling shutter in one pass; 11 a 10 ms exposure
// of 9 images always (the reference). With shadows (6, 9) each frame is 0.1 s after the last (over
// a second, then again), so the lead moves and the map is drawn every frame.
void set_camera_effect(sim::CameraSpec& c, int effect) {
  using S = sim::ShutterSpec;
  if (effect == 1 || effect == 5 || effect == 9 || effect == 11) c.shutter.exposure = 0.01, c.shutter.subframes = 9;
  if (effect == 11) c.shutter.subframe_motion_px = 0;
  if (effect == 2 || effect == 3 || effect == 5 || effect == 9 || effect == 10) {
    c.shutter.type = S::Type::Rolling;
    c.shutter.line_delay = 3e-5;
    c.shutter.rows_per_band = effect == 2 ? 1 : effect == 3 ? 10 : 0;
  }
  if (effect == 4 || effect == 5 || effect == 9) {
    c.sensor.model = sim::SensorSpec::Model::Physical;
    c.sensor.auto_exposure.enabled = true;
    c.sensor.vignetting = 0.5;
    if (effect == 4) c.shutter.subframes = 1;  // the sensor alone: no blur
  }
}

void camera_effect(benchmark::State& state, render::GlBackend backend) {
  sim::Scenario scn = sim::load_scenarios(WINGMAN_SOURCE_DIR "/scenes/paper_rendered_fast.yaml").front();
  const int effect = static_cast<int>(state.range(0));
  set_camera_effect(scn.uavs[0].camera, effect);
  scn.world.light.shadows = effect == 6 || effect == 9;
  if (effect == 7) scn.world.texture.tiling = sim::TextureSpec::Tiling::Repeat;
  if (effect == 8) scn.world.light.skylight.model = sim::SkylightSpec::Model::ClearSky;
  const auto ctx = context_or_skip(state, backend);
  if (!ctx) return;
  render::Renderer renderer(*ctx, render::build_scene(sim::describe_world(scn)));
  const sim::OpenLoopTruth truth(scn);
  app::CameraImaging imaging(scn, 0);
  auto draw = [&](const render::CameraView& v, const render::LeadPose& l, int row0, int rows) {
    return renderer.render_rows(v, l, row0, rows);
  };
  imaging.take(truth, 20.0, draw);  // warm-up
  // With shadows the frames step through a second of flight: the lead moves, and the shadow map
  // is drawn again each frame, as in a run.
  const bool moving = scn.world.light.shadows;
  const double cpu0 = process_cpu_seconds();
  int k = 0;
  for (auto _ : state) {
    app::TakenFrame f = imaging.take(truth, moving ? 20.0 + 0.1 * (++k % 10) : 20.0, draw);
    benchmark::DoNotOptimize(f.frame.rgb.data);
  }
  state.counters["cpu_ms"] = 1e3 * (process_cpu_seconds() - cpu0) / static_cast<double>(state.iterations());
  state.SetLabel(renderer.context().description());
}

void BM_CameraEffectEgl(benchmark::State& s) { camera_effect(s, render::GlBackend::Egl); }

// The physical sensor alone (render/sensor.hpp, as effect 4 sets it up) on a 1000 x 1000 frame
// of the paper camera, an image with every grey level: its cost beside a frame's.
void BM_SensorModel(benchmark::State& state) {
  sim::CameraSpec c = sim::load_scenarios(WINGMAN_SOURCE_DIR "/scenes/paper_rendered_fast.yaml").front().uavs[0].camera;
  set_camera_effect(c, 4);
  render::SensorModel sensor(c.sensor, c.shutter.exposure, c.camera(), 1, "uav1");
  render::Frame image;
  image.rgb.create(c.height, c.width, CV_8UC3);
  for (int r = 0; r < image.rgb.rows; ++r)
    for (int col = 0; col < image.rgb.cols; ++col)
      image.rgb.at<cv::Vec3b>(r, col) = cv::Vec3b(static_cast<uchar>(col % 256), static_cast<uchar>(r % 256), 128);
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) {
    render::Frame f;
    f.rgb = image.rgb.clone();
    sensor.apply(f);
    benchmark::DoNotOptimize(f.rgb.data);
  }
  state.counters["cpu_ms"] = 1e3 * (process_cpu_seconds() - cpu0) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_SensorModel)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_CameraEffectEgl)->DenseRange(0, 11)->ArgName("effect")->Unit(benchmark::kMillisecond)->UseRealTime();

// What the stochastic ground's bake costs once per world (render/ground_bake.hpp): a renderer made
// for scenes/paper_rendered_fast.yaml's world with the bake (argument 1) and without (0), the
// process's CPU per renderer; `texels`: the bake's size (its plan, over the ground's coordinates).
void BM_GroundBakeEgl(benchmark::State& state) {
  sim::Scenario scn = sim::load_scenarios(WINGMAN_SOURCE_DIR "/scenes/paper_rendered_fast.yaml").front();
  scn.world.texture.bake = state.range(0) == 1;
  const render::Scene scene = render::build_scene(sim::describe_world(scn));
  const auto ctx = context_or_skip(state, render::GlBackend::Egl);
  if (!ctx) return;
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) {
    render::Renderer renderer(*ctx, scene);
    benchmark::DoNotOptimize(&renderer);
  }
  state.counters["cpu_ms"] = 1e3 * (process_cpu_seconds() - cpu0) / static_cast<double>(state.iterations());
  const int ground = scene.static_meshes.front().material;
  const cv::Mat& tex = scene.materials[static_cast<std::size_t>(ground)].texture;
  if (const auto plan = render::plan_ground_bake(render::uv_box(scene.static_meshes, ground), tex.cols, tex.rows, 16384)) {
    state.counters["width"] = plan->width;
    state.counters["height"] = plan->height;
  }
}
BENCHMARK(BM_GroundBakeEgl)->Arg(0)->Arg(1)->ArgName("bake")->Iterations(3)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_QualitySweepEgl(benchmark::State& s) { quality_sweep(s, render::GlBackend::Egl); }
// Arguments as BM_RenderEgl's. One iteration: 24 frames per setting.
BENCHMARK(BM_QualitySweepEgl)
    ->ArgsProduct({{1, 2, 4}, {1, 4, 16}, {0, 1}})
    ->ArgNames({"msaa", "aniso", "trilinear"})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
