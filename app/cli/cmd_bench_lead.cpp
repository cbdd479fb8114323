// `wingman bench-lead <dataset>...`: the benchmark of lead detectors. Each frame of each UAV is
// searched by a built-in detector (or the detections of anyone's, from a file) and scored against
// the lead's ground truth in that frame (cam0_lead0): detection rate over the frames that show the
// lead, false detections per frame, x_h's pixel error and the detector's CPU time, over all frames
// and per lead, ground image, distance and visible share (docs/frontend.md, lead detectors).
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <time.h>

#include <filesystem>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>
#include <string>

#include "app/cli/cli_options.hpp"
#include "app/cli/subcommand.hpp"
#include "app/config/run_config.hpp"
#include "app/frontend/vision_frontend.hpp"
#include "datasets/dataset.hpp"
#include "frontend_bench/lead_scores.hpp"
#include "io/atomic_file.hpp"
#include "io/interrupt.hpp"
#include "io/progress.hpp"
#include "io/results_dir.hpp"
#include "sim/assets.hpp"
#include "vision/learned_lead_detector.hpp"

namespace wingman::app {

namespace fs = std::filesystem;

namespace {

struct BenchLeadOptions {
  std::vector<std::string> datasets;
  std::string detector = "auto", weights, detections, write_detections, out;
  double threshold = 0;  // 0: the scenario's frontend.learned_lead.threshold
  double prediction_sigma = 0;
  frontend_bench::LeadScoreOptions score;
  bool force = false, quiet = false;
};

// The process's CPU time: OpenCV runs a network's layers on its own threads, and they count.
double process_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

std::string stem(const std::string& path) { return path.empty() ? "none" : fs::path(path).stem().string(); }

// The scenario a dataset was rendered from: its variant's configuration.
RunConfig dataset_scenario(const datasets::Dataset& ds) {
  const fs::path yaml = ds.root / "scenario.yaml";
  for (RunConfig& c : load_run_configs(yaml.string()))
    if (c.variant == ds.info.variant) return c;
  throw io::UsageError(fmt::format("{}: has no variant '{}', the dataset's", yaml.string(), ds.info.variant));
}

// The detector --detector names (auto: the dataset's scenario's), with --weights and --threshold.
std::unique_ptr<vision::LeadFinder> make_detector(const BenchLeadOptions& o, const RunConfig& cfg, std::string& name) {
  using K = vision::LeadDetectorKind;
  const K kind = o.detector == "aruco"     ? K::Aruco
                 : o.detector == "panel"   ? K::Panel
                 : o.detector == "learned" ? K::Learned
                 : o.detector == "motion"  ? K::Motion
                                           : lead_detector(cfg);
  vision::LearnedLeadSettings learned = cfg.frontend.learned_lead.search;
  if (o.threshold > 0) learned.threshold = o.threshold;
  std::string weights;
  try {
    if (kind == K::Learned) {
      weights = o.weights.empty() ? sim::resolve_asset(cfg.frontend.learned_lead.weights, cfg.source_path,
                                                       "lead detector weights")
                                  : o.weights;
    }
    name = kind == K::Learned  ? "learned (" + weights + ")"
           : kind == K::Motion ? "motion"
           : kind == K::Panel  ? "panel"
                               : "aruco";
    return make_lead_finder(cfg, kind, weights, learned);
  } catch (const std::runtime_error& e) {  // not found, or vision::LeadModelError
    throw io::UsageError(fmt::format("--weights: {}", e.what()));
  }
}

// Every camera frame of a dataset with its truth; detected by `detector` unless it is null.
void bench_dataset(const BenchLeadOptions& o, const fs::path& dir, std::vector<frontend_bench::LeadFrame>& frames,
                   std::string& detector_name, io::ProgressLine& progress) {
  const datasets::Dataset ds = datasets::read_dataset(dir);
  const RunConfig cfg = dataset_scenario(ds);
  const bool colour = cfg.world.lead.cue == sim::LeadModelSpec::Cue::Panel && (o.detector == "auto" || o.detector == "panel");
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, o.prediction_sigma);
  const std::string name = o.datasets.size() > 1 ? dir.filename().string() : "";
  int total = 0, done = 0;
  for (const auto& a : ds.agents) total += a.camera ? static_cast<int>(a.frames.size()) : 0;
  for (const auto& a : ds.agents) {
    if (!a.camera) continue;
    // Each camera's own detector, given its frames in order (the motion detector keeps them).
    std::unique_ptr<vision::LeadFinder> detector;
    if (o.detections.empty()) detector = make_detector(o, cfg, detector_name);
    if (a.lead_labels.empty())
      throw io::UsageError(fmt::format("{}: agent {} has no cam0_lead0 (the lead's labels): render the dataset "
                                       "again with this wingman", dir.string(), a.name));
    for (std::size_t k = 0; k < a.frames.size(); ++k) {
      io::throw_if_interrupted();
      frontend_bench::LeadFrame f;
      f.dataset = name, f.agent = a.name, f.t_ns = a.frames[k];
      f.lead = stem(cfg.world.lead.model), f.ground = stem(cfg.world.texture.image);
      f.width = a.camera->camera.width(), f.height = a.camera->camera.height();
      f.truth = a.lead_labels[k].lead;
      if (detector) {
        cv::Mat img = ds.load_image(a.name, a.frames[k]);
        if (img.channels() == 3) cv::cvtColor(img, img, colour ? cv::COLOR_RGB2BGR : cv::COLOR_RGB2GRAY);
        std::optional<Eigen::Vector2d> predicted;
        if (o.prediction_sigma > 0 && f.truth.uv.allFinite())
          predicted = f.truth.uv + Eigen::Vector2d(noise(rng), noise(rng));
        const double t0 = process_cpu_ms();
        const auto d = detector->detect(img, predicted);
        f.cpu_ms = process_cpu_ms() - t0;
        if (d) f.detected = d->uv;
      }
      frames.push_back(f);
      progress.update(++done, total, dir.filename().string());
    }
  }
}

int bench_lead_command(const BenchLeadOptions& o) {
  try {
    o.score.validate();
  } catch (const std::invalid_argument& e) {
    throw io::UsageError(e.what());
  }
  if (o.prediction_sigma < 0) throw io::UsageError("--prediction-sigma must be >= 0");
  std::optional<io::ResultsDir> staged;
  if (!o.out.empty()) stage_output(staged, o.out, "results", o.force);
  std::vector<frontend_bench::LeadFrame> frames;
  std::string detector = o.detections.empty() ? o.detector : "detections (" + o.detections + ")";
  {
    io::ProgressLine progress("[bench-lead]", o.quiet);
    for (const auto& d : o.datasets) bench_dataset(o, d, frames, detector, progress);
    progress.finish();
  }
  if (!o.detections.empty())
    frontend_bench::attach_detections(frames, frontend_bench::read_lead_detections(o.detections), o.detections);
  const auto scores = frontend_bench::score_leads(frames, o.score);
  if (!o.write_detections.empty()) {
    std::vector<frontend_bench::LeadDetectionRow> rows;
    for (const auto& f : frames)
      if (f.detected) rows.push_back({f.dataset, f.agent, f.t_ns, *f.detected, 1.0});
    io::write_file_atomic(o.write_detections, frontend_bench::lead_detections_csv(rows));
  }
  fmt::print("{}", frontend_bench::lead_scores_table(scores, detector));
  if (staged) {
    io::write_file_atomic(staged->staging() / "lead_scores.json",
                          frontend_bench::lead_scores_json(scores, detector, o.score));
    staged->commit();
  }
  return 0;
}

}  // namespace

Subcommand add_bench_lead(CLI::App& parent) {
  auto o = std::make_shared<BenchLeadOptions>();
  auto* cmd = parent.add_subcommand(
      "bench-lead",
      "Score a lead detector on datasets with the lead's labels (cam0_lead0): detection rate, false detections, "
      "pixel error of x_h and CPU time, per lead, ground, distance and visible share");
  cmd->add_option("datasets", o->datasets, "Datasets written by `wingman render`")->required()->check(CLI::ExistingDirectory);
  cmd->add_option("--detector", o->detector, "auto (the scenario's: aruco, panel, or learned for cue: none), aruco, "
                                             "panel, learned or motion")
      ->check(CLI::IsMember({"auto", "aruco", "panel", "learned", "motion"}));
  cmd->add_option("--weights", o->weights, "The learned detector's ONNX file (default: the scenario's)");
  cmd->add_option("--threshold", o->threshold, "The learned detector's peak threshold (default: the scenario's)")
      ->check(CLI::Range(0.01, 0.99));
  cmd->add_option("--detections", o->detections,
                  "Score these detections instead of running a detector (#dataset,agent,timestamp [ns],u [px],v [px],score)");
  cmd->add_option("--prediction-sigma", o->prediction_sigma,
                  "Search around the truth moved by this much Gaussian noise (px), as a filter's prediction; 0: "
                  "the whole frame");
  cmd->add_option("--min-visible", o->score.min_visible, "A frame shows the lead from this visible share on");
  cmd->add_option("--match-px", o->score.match_px, "A detection within this many pixels of x_h is the lead");
  cmd->add_option("--write-detections", o->write_detections, "Write the detections in the detections file format");
  cmd->add_option("--out", o->out, "Write lead_scores.json into this new directory");
  cmd->add_flag("--force", o->force, "Replace --out if it is a results directory");
  cmd->add_flag("--quiet", o->quiet, "No progress line");
  return {cmd, [o] { return bench_lead_command(*o); }};
}

}  // namespace wingman::app
