// `wingman calibrate-frontend <dataset> --out model.yaml`: the frontend noise model
// (vision/noise_model.hpp) measured on a rendered dataset. Each detector replays the dataset
// through the frontend and the estimator (as `wingman slam`), and the correspondences the filter
// accepted are compared with their true projections (labels the replay keeps beside the
// estimator's input): per track of a camera and a landmark, the mean error is the track's constant
// offset and the scatter about it the white noise.
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "app/cli/cli_options.hpp"
#include "app/config/derived_noise.hpp"
#include "app/pipeline/pipeline.hpp"
#include "io/progress.hpp"
#include "app/pipeline/replay.hpp"
#include "app/cli/subcommand.hpp"
#include "io/atomic_file.hpp"

namespace wingman::app {

namespace fs = std::filesystem;

namespace {

// px: what the replay's filter assumes where the scenario would take its pixel noise from a model.
constexpr double kCalibrationPixelSigma = 1.0, kCalibrationPixelOffsetSigma = 0.75;

struct CalibrateOptions {
  std::string dataset, out, variant;
  std::vector<std::string> detectors{"orb", "gftt_orb"};
  StepLimit limit;
  bool force = false, quiet = false;
};

int calibrate_command(const CalibrateOptions& o) {
  if (!o.force && fs::exists(o.out))
    throw io::UsageError(fmt::format("{}: already exists; pass --force to replace it", o.out));
  std::vector<vision::DetectorKind> kinds;
  for (const auto& name : o.detectors) {
    try {
      kinds.push_back(vision::parse_detector(name));
    } catch (const std::invalid_argument& e) {
      throw io::UsageError(fmt::format("--detectors: {}", e.what()));
    }
  }
  Replay replay = load_replay(o.dataset, o.variant, o.quiet);
  apply_step_limit(o.limit, replay.scenario);
  // The replay's gate must not depend on the model being measured: where the scenario takes its
  // pixel noise from a model, the replay assumes a generous fixed one instead.
  auto& r = replay.scenario.estimator.measurement_noise;
  if (r.pixel_sigma.automatic) r.pixel_sigma = kCalibrationPixelSigma;
  if (r.pixel_offset_sigma.automatic) r.pixel_offset_sigma = kCalibrationPixelOffsetSigma;
  vision::FrontendNoiseModel model;
  model.made_by = fmt::format(
      "wingman calibrate-frontend DATASET --detectors {}{}; DATASET: wingman render of {} (seed {}, {} s); "
      "the replay's filter assumed pixel_sigma {} px, pixel_offset_sigma {} px",
      fmt::join(o.detectors, ","),
      o.limit.duration ? fmt::format(" --duration {}", *o.limit.duration)
      : o.limit.frames ? fmt::format(" --frames {}", *o.limit.frames)
                       : std::string(),
      replay.scenario.name, replay.scenario.seed, replay.scenario.duration, double(r.pixel_sigma),
      double(r.pixel_offset_sigma));
  for (vision::DetectorKind kind : kinds) {
    vision::FeatureSettings features = replay.scenario.frontend.features;
    features.kind = kind;
    io::ProgressLine progress(fmt::format("[calibrate {}]", vision::to_string(kind)), o.quiet);
    const eval::RunRecord rec = run_replay(replay.scenario, replay.dataset,
                                           [&](int k, int n) { progress.update(k, n, "steps"); }, features, true);
    progress.finish();
    vision::DetectorNoise d = track_noise(rec.frontend.correspondences);
    if (d.tracks == 0)
      throw io::UsageError(fmt::format("{}: detector {} kept no track of {} or more accepted correspondences; "
                                   "calibrate on a longer dataset",
                                   o.dataset, vision::to_string(kind), kMinTrackObservations));
    if (!o.quiet)
      fmt::print("{}: {} tracks, {} observations: white {:.3f} px, track offset {:.3f} px per axis "
                 "(median error {:.3f} px, p95 {:.3f} px)\n",
                 vision::to_string(kind), d.tracks, d.observations, d.pixel_sigma, d.track_offset_rms,
                 d.median_error_px, d.p95_error_px);
    model.of(kind) = d;
  }
  io::write_file_atomic(o.out, noise_model_yaml(model));
  if (!o.quiet) fmt::print("frontend noise model: {}\n", o.out);
  return 0;
}

}  // namespace

Subcommand add_calibrate_frontend(CLI::App& parent) {
  auto o = std::make_shared<CalibrateOptions>();
  auto* cmd = parent.add_subcommand(
      "calibrate-frontend",
      "Measure the frontend noise model (per detector: white pixel sigma and track offset) on a "
      "rendered dataset, against its true correspondences (docs/frontend.md, noise model)");
  cmd->add_option("dataset", o->dataset, "Dataset directory (wingman render)")->required();
  cmd->add_option("--out,-o", o->out, "The model file to write (YAML)")->required();
  cmd->add_option("--detectors", o->detectors, "Detectors to calibrate (orb, gftt_orb, akaze, sift)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--variant", o->variant, "Estimator settings of this variant of the dataset's scenario");
  add_step_limit(cmd, o->limit);
  add_force_flag(cmd, o->force);
  cmd->add_flag("--quiet,-q", o->quiet, "No progress line and no summary");
  return {cmd, [o] { return calibrate_command(*o); }};
}

}  // namespace wingman::app
