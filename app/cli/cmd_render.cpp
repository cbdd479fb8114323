// `wingman render`: renders every UAV camera at every step of the open-loop truth and writes an
// image dataset with depth, an IMU, sensor samples and ground truth (datasets/dataset.hpp). The dataset
// is staged next to --out and renamed into place only when complete, so a failed or interrupted
// run (Ctrl-C and SIGTERM included, io/interrupt.hpp) never leaves a directory that looks finished.
#include "app/cli/cli_options.hpp"
#include "app/cli/subcommand.hpp"
#include "app/config/variants.hpp"

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <random>

#include "io/interrupt.hpp"
#include "io/progress.hpp"
#include "io/version.hpp"
#include "datasets/dataset.hpp"
#include "io/results_dir.hpp"
#include "geometry/rotation.hpp"
#include "app/pipeline/camera_imaging.hpp"
#include "app/pipeline/lead_label.hpp"
#include "render/gl_context.hpp"
#include "render/renderer.hpp"
#include "render/scene.hpp"
#include "sim/assets.hpp"
#include "sim/rng.hpp"
#include "sim/imu.hpp"
#include "sim/scenario.hpp"
#include "sim/synthetic_source.hpp"
#include "sim/truth.hpp"

namespace fs = std::filesystem;

namespace wingman::app {

namespace {

struct RenderOptions {
  std::string scenario;
  std::string out;
  std::string gl = "auto";
  std::optional<std::uint64_t> seed;
  std::vector<std::string> variants;
  StepLimit limit;
  bool gray = false, rgb = false;
  bool force = false;
  bool quiet = false;
};

RunConfig pick(const RenderOptions& o, const std::string& variant) {
  RunConfig scn = select_variant(load_run_configs(o.scenario), variant, o.scenario);
  // A scenario of synthetic measurements is checked on loading without its world's files.
  sim::check_world_files(scn);
  if (o.seed) scn.seed = *o.seed;
  return scn;
}

// Steps to render (after t = 0): the whole run, or what --frames / --duration keep. The world
// is always built for the whole run, so a short preview shows exactly the full run's first frames.
int steps_to_render(const RenderOptions& o, const RunConfig& scn) {
  int n = scn.num_steps();
  if (o.limit.frames) {
    if (*o.limit.frames < 1) throw io::UsageError("--frames must be at least 1");
    n = std::min(n, *o.limit.frames - 1);
  }
  if (o.limit.duration) {
    if (!(*o.limit.duration >= 0)) throw io::UsageError("--duration must be >= 0");
    n = std::min(n, static_cast<int>(std::floor(*o.limit.duration * scn.rate + 1e-9)));
  }
  return n;
}

datasets::PoseSample pose(std::int64_t t, const Eigen::Vector3d& p, const Eigen::Matrix3d& R,
                          const Eigen::Vector3d& v = Eigen::Vector3d::Zero()) {
  return {t, p, geometry::quaternion_xyzw(R), v};
}

// Grey frames (EuRoC's mono8, what visual(-inertial) loaders read) unless asked otherwise or the
// scenario's lead cue is found by its colour (a panel): then RGB, so that `wingman slam` replays it.
int frame_channels(const RenderOptions& o, const RunConfig& scn) {
  if (o.gray && o.rgb) throw io::UsageError("--gray and --rgb exclude each other");
  if (o.gray) return 1;
  if (o.rgb) return 3;
  return scn.world.lead.cue == sim::LeadModelSpec::Cue::Panel ? 3 : 1;
}

// UAV j's IMU (imu0) and its ground truth at the IMU's rate, with the biases in effect, over
// [0, t_end]: both from the truth's analytic derivatives.
void write_inertial(datasets::DatasetWriter& writer, const sim::Truth& truth, const RunConfig& scn, int j,
                    double t_end) {
  const auto& spec = scn.noise.imu;
  const std::string& name = scn.uavs[j].name;
  writer.imu_info(name, {spec.rate, spec.gyroscope_noise_density, spec.gyroscope_random_walk,
                         spec.accelerometer_noise_density, spec.accelerometer_random_walk});
  sim::ImuSimulator imu(spec, scn.seed, name);
  const int m = static_cast<int>(std::floor(t_end * spec.rate + 1e-9));
  for (int i = 0; i <= m; ++i) {
    const double t = i / spec.rate;
    const std::int64_t t_ns = datasets::step_ns(i, spec.rate);
    const sim::BodyMotion body = sim::uav_body_motion(truth, j, t);
    const sim::ImuReading r = imu.measure(body);
    writer.imu(name, {t_ns, r.w_S, r.a_S});
    const sim::KinematicState q = truth.uav(j, t);
    datasets::PoseSample gt = pose(t_ns, q.position, body.R_WB, q.velocity);
    gt.b_w = r.b_w;
    gt.b_a = r.b_a;
    writer.ground_truth(name, gt);
  }
}

// One variant's dataset into `out` (or, with several variants, out/<variant>).
int render_command(const RenderOptions& o, const std::string& variant) {
  render::GlBackend backend;
  try {
    backend = render::gl_backend_from_string(o.gl);
  } catch (const std::invalid_argument& e) {
    throw io::UsageError(e.what());
  }
  const RunConfig scn = pick(o, variant);
  const int n = steps_to_render(o, scn);
  const int channels = frame_channels(o, scn);
  fs::path out = o.out.empty() ? fs::path("results") / "datasets" / scn.name : fs::path(o.out);
  if (o.variants.size() > 1) out /= scn.variant;

  render::Scene scene;
  try {
    scene = render::build_scene(sim::describe_world(scn));
  } catch (const std::runtime_error& e) {
    throw io::UsageError(fmt::format("{}: world: {}", o.scenario, e.what()));
  }
  std::optional<io::ResultsDir> staged;
  stage_output(staged, out, "dataset", o.force);
  const auto ctx = render::create_gl_context(backend);
  render::Renderer renderer(*ctx, scene);
  scene = {};  // uploaded; free the CPU copy

  const sim::OpenLoopTruth truth(scn);
  sim::SyntheticSource sensors(scn, truth);  // same noise streams as a synthetic run
  auto ahrs_rng = sim::make_stream(scn.seed, "ahrs");
  std::normal_distribution<double> ahrs_noise(0.0, scn.noise.ahrs_yaw_sigma);

  datasets::DatasetInfo info;
  info.scenario = scn.name;
  info.variant = scn.variant;
  info.seed = scn.seed;
  info.software_version = kVersion;
  info.rate = scn.rate;
  info.renderer = ctx->description();
  info.agents.push_back("lead");
  for (const auto& u : scn.uavs) info.agents.push_back(u.name);
  datasets::DatasetWriter writer(staged->staging(), info);
  writer.add_agent("lead", std::nullopt);
  std::vector<app::CameraImaging> imaging;
  for (const auto& u : scn.uavs) {
    datasets::CameraInfo c;
    c.camera = u.camera.camera();
    c.R_CW = truth.commanded_R_CW();
    c.offset = u.camera.offset;
    c.rate = scn.rate;
    c.channels = channels;
    describe_shutter(u.camera, c);
    writer.add_agent(u.name, c);
    imaging.emplace_back(scn, static_cast<int>(imaging.size()));
  }

  const int cams = static_cast<int>(scn.uavs.size());
  io::ProgressLine progress(fmt::format("[render {}]", scn.name), o.quiet);
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k <= n; ++k) {
    io::throw_if_interrupted();  // unwinds through the staging directory: nothing half-written
    const double t = k * scn.dt();
    const std::int64_t t_ns = datasets::step_ns(k, scn.rate);
    const render::LeadPose lead = sim::lead_pose(truth, t, scn.world);
    const sim::KinematicState lk = truth.lead(t);
    // Ground truth heading: the path's, without the model's yaw_offset.
    const double heading = lead.yaw - scn.world.lead.yaw_offset;
    writer.ground_truth("lead", pose(t_ns, lk.position, geometry::rot_z(heading), lk.velocity));
    if (scn.lead.gps) writer.gps("lead", {t_ns, sensors.gps(t)});
    for (int j = 0; j < cams; ++j) {
      const auto& u = scn.uavs[j];
      app::TakenFrame f = imaging[j].take(truth, t, [&](const render::CameraView& view, const render::LeadPose& l,
                                                        int row0, int rows) {
        return renderer.render_rows(view, l, row0, rows);
      });
      const geometry::CameraPose& centre = f.poses.centre();
      writer.write_frame(u.name, t_ns, f.frame.rgb, f.frame.depth);
      writer.camera_pose(u.name, pose(t_ns, centre.position, centre.R_CW));
      const auto silhouette = renderer.lead_silhouette({imaging[j].model(), centre}, lead);
      writer.lead_label(u.name, {t_ns, app::lead_label(lk.position, imaging[j].model(), f.poses, f.frame.depth, silhouette)});
      writer.exposure(u.name, {t_ns, f.exposure.exposure_s, f.exposure.gain});
      if (u.altimeter) writer.altimeter(u.name, {t_ns, sensors.altimeter(j, t)});
      if (u.range) writer.range(u.name, {t_ns, sensors.range(j, t)});
      writer.ahrs(u.name, {t_ns, ahrs_noise(ahrs_rng)});
    }
    const double secs =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    progress.update(k + 1, n + 1,
                    fmt::format("steps, {:.1f} frames/s", secs > 0 ? (k + 1) * cams / secs : 0.0));
  }
  progress.finish();
  for (int j = 0; j < cams; ++j) write_inertial(writer, truth, scn, j, n * scn.dt());
  writer.finish();
  copy_scenario(scn, staged->staging());
  staged->commit();
  if (!o.quiet)
    fmt::print("dataset: {} ({} steps x {} cameras, {})\n", out.string(), n + 1, cams,
               ctx->description());
  return 0;
}

}  // namespace

Subcommand add_render(CLI::App& parent) {
  auto o = std::make_shared<RenderOptions>();
  auto* cmd = parent.add_subcommand(
      "render", "Render every UAV camera along the open-loop truth into an image dataset with "
                "depth, an IMU, sensor samples and ground truth (EuRoC/ASL layout, docs/datasets.md)");
  cmd->add_option("scenario", o->scenario, "Scenario YAML file")->required();
  cmd->add_option("--out,-o", o->out, "Dataset directory (default: results/datasets/<scenario name>)");
  cmd->add_option("--gl", o->gl, "OpenGL backend: auto (EGL, then OSMesa), egl or osmesa")
      ->check(CLI::IsMember({"auto", "egl", "osmesa"}));
  cmd->add_option("--seed", o->seed, "Override the scenario's seed");
  add_variant_option(cmd, o->variants,
                     "Which variant's settings to use (default: the first; with several, one dataset "
                     "each, OUT/<variant>)");
  add_step_limit(cmd, o->limit);
  cmd->add_flag("--gray", o->gray, "Write 8-bit grey frames (the default unless the lead's cue is a colour panel)");
  cmd->add_flag("--rgb", o->rgb, "Write 8-bit RGB frames (the default when the lead's cue is a colour panel)");
  add_force_flag(cmd, o->force);
  cmd->add_flag("--quiet,-q", o->quiet, "No progress line and no summary");
  return {cmd, [o] {
            return for_each_variant(o->variants, [&](const std::string& v) { return render_command(*o, v); });
          }};
}

}  // namespace wingman::app
