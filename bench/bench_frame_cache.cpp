// What the frame cache (render/frame_cache.hpp) costs against rendering: one 1000 x 1000 frame of
// the rendered paper scene (scenes/paper_rendered_fast.yaml, Quad 1 at t = 20 s with the lead in
// view), stored and read back per codec (raw, zstd), with the entry's size; the key's cost per
// frame; and, beside them, rendering the same frame (EGL). Reads here come from the page cache,
// as a study's do while its cache fits in memory. Skipped with the reason when no EGL context can
// be made.
#include <benchmark/benchmark.h>

#include <unistd.h>

#include <filesystem>
#include <memory>
#include <optional>

#include "render/frame_cache.hpp"
#include "bench/process_cpu.hpp"
#include "render/gl_context.hpp"
#include "render/renderer.hpp"
#include "render/scene.hpp"
#include "sim/scenario.hpp"
#include "sim/truth.hpp"

#ifndef WINGMAN_SOURCE_DIR
#define WINGMAN_SOURCE_DIR "."
#endif

namespace {

using namespace wingman;
namespace fs = std::filesystem;

using bench::process_cpu_seconds;

// The paper scene's world, one camera's view of it, and a context that renders it.
struct PaperFrame {
  std::unique_ptr<render::GlContext> ctx;
  std::unique_ptr<render::Renderer> renderer;
  std::unique_ptr<render::FrameKeyer> keyer;
  render::CameraView view;
  render::LeadPose lead;
  render::Frame frame;
};

// Built once for every benchmark; nullptr (and the reason) when no EGL context can be made.
PaperFrame* paper_frame(std::string& why) {
  static std::unique_ptr<PaperFrame> p;
  static std::string error;
  if (p || !error.empty()) return why = error, p.get();
  try {
    const sim::Scenario scn = sim::load_scenarios(WINGMAN_SOURCE_DIR "/scenes/paper_rendered_fast.yaml").front();
    auto f = std::make_unique<PaperFrame>();
    f->ctx = render::create_gl_context(render::GlBackend::Egl);
    const render::Scene scene = render::build_scene(sim::describe_world(scn));
    f->renderer = std::make_unique<render::Renderer>(*f->ctx, scene);
    f->keyer = std::make_unique<render::FrameKeyer>(scene, f->ctx->description());
    const sim::OpenLoopTruth truth(scn);
    const double t = 20.0;
    f->view = {scn.uavs[0].camera.camera(), {truth.camera_R_CW(0, t), truth.camera(0, t).position}};
    f->lead = sim::lead_pose(truth, t, scn.world);
    f->frame = f->renderer->render(f->view, f->lead);
    p = std::move(f);
  } catch (const std::exception& e) {
    error = e.what();
  }
  return why = error, p.get();
}

PaperFrame* frame_or_skip(benchmark::State& state) {
  std::string why;
  PaperFrame* f = paper_frame(why);
  if (!f) {
    state.SkipWithError(why.c_str());
    for (auto _ : state) {
    }
  }
  return f;
}

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("wingman-bench-frame-cache-" + std::to_string(::getpid()));
  ~TempDir() { fs::remove_all(path); }
};

void report(benchmark::State& state, double cpu0) {
  state.counters["cpu_ms"] = 1e3 * (process_cpu_seconds() - cpu0) / static_cast<double>(state.iterations());
}

// Argument: the codec (0 raw, 1 zstd).
void BM_FrameCacheStore(benchmark::State& state) {
  PaperFrame* f = frame_or_skip(state);
  if (!f) return;
  TempDir dir;
  render::FrameCache cache(dir.path, 1ull << 40, static_cast<render::FrameCodec>(state.range(0)));
  const render::FrameKey key = f->keyer->key(f->view, f->lead);
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) cache.store(key, f->frame);
  report(state, cpu0);
  state.counters["entry_MB"] = static_cast<double>(fs::file_size(cache.entry_path(key))) / 1e6;
}

void BM_FrameCacheLoad(benchmark::State& state) {
  PaperFrame* f = frame_or_skip(state);
  if (!f) return;
  TempDir dir;
  render::FrameCache cache(dir.path, 1ull << 40, static_cast<render::FrameCodec>(state.range(0)));
  const render::FrameKey key = f->keyer->key(f->view, f->lead);
  cache.store(key, f->frame);
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) {
    std::optional<render::Frame> got = cache.load(key);
    if (!got) state.SkipWithError("the stored frame did not load");
    benchmark::DoNotOptimize(got);
  }
  report(state, cpu0);
}

void BM_FrameCacheKey(benchmark::State& state) {
  PaperFrame* f = frame_or_skip(state);
  if (!f) return;
  for (auto _ : state) benchmark::DoNotOptimize(f->keyer->key(f->view, f->lead));
}

// The same frame rendered, for the ratio.
void BM_FrameCacheRenderInstead(benchmark::State& state) {
  PaperFrame* f = frame_or_skip(state);
  if (!f) return;
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) {
    render::Frame fr = f->renderer->render(f->view, f->lead);
    benchmark::DoNotOptimize(fr.rgb.data);
  }
  report(state, cpu0);
}

BENCHMARK(BM_FrameCacheStore)->Arg(0)->Arg(1)->ArgName("zstd")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FrameCacheLoad)->Arg(0)->Arg(1)->ArgName("zstd")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FrameCacheKey)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FrameCacheRenderInstead)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
