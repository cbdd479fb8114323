// `wingman bench-frontend <dataset-dir>`: the whole replay (frontend and estimator) once per
// feature detector, and one table: ms per frame of detection + description, tracked matches per
// frame, the fraction of them correct against the ground-truth labels, cooperative pairs and
// landmarks initialised. The estimator is in the loop because what it predicts is what tracking
// searches for; the lead detector and everything else stay as in `wingman slam`.
#include "app/cli_options.hpp"
#include "app/subcommand.hpp"

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/pipeline.hpp"
#include "app/progress.hpp"
#include "app/vision_frontend.hpp"
#include "app/replay.hpp"
#include "eval/metrics.hpp"
#include "vision/features.hpp"

namespace wingman::app {

namespace {

struct BenchOptions {
  std::string dataset;
  std::vector<std::string> variants;
  StepLimit limit;
  std::vector<std::string> detectors{"orb", "gftt_orb", "akaze", "sift"};
  int max_features = 0;  // 0: the scenario's frontend.max_features
  bool quiet = false;
};

int bench_command(const BenchOptions& o, const std::string& variant) {
  for (const auto& name : o.detectors) {  // a typo is a usage error, before any loading
    try {
      vision::parse_detector(name);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
  }
  Replay replay = load_replay(o.dataset, variant, o.quiet);
  apply_step_limit(o.limit, replay.scenario);
  const RunConfig& scn = replay.scenario;
  // Each detector with the rest of the scenario's frontend section (bucketing, thresholds).
  std::vector<vision::FeatureSettings> settings;
  for (const auto& name : o.detectors) {
    vision::FeatureSettings f = scn.frontend.features;
    if (o.max_features > 0) f.max_features = o.max_features;
    try {
      f.kind = vision::parse_detector(name);
      f.validate();
      settings.push_back(f);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
  }

  struct Row {
    std::string name;
    double detect_ms_per_frame = 0;
    double matches_per_frame = 0, correct = 0;
    long coop = 0, coop_correct = 0, initialised = 0;
  };
  std::vector<Row> rows;
  for (const auto& f : settings) {
    ProgressLine progress(fmt::format("[bench-frontend {}]", vision::to_string(f.kind)), o.quiet);
    const eval::RunRecord rec =
        run_replay(scn, replay.dataset, [&](int k, int n) { progress.update(k, n, "steps"); }, f);
    progress.finish();
    const eval::Metrics m = eval::compute_metrics(rec);
    Row r;
    r.name = vision::to_string(f.kind);
    const double frames = std::max<long>(1, rec.frontend.frames);
    double detect_ms = 0;
    for (const auto& s : rec.steps) detect_ms += s.t_detect_ms;
    // t_detect also holds the lead detector (the same for every row).
    r.detect_ms_per_frame = detect_ms / frames;
    long corr = 0, out = 0;
    for (const auto& row : m.table3) {
      if (row.counts.channel == "cooperative") {
        r.coop = row.counts.correspondences;
        r.coop_correct = row.counts.correspondences - row.counts.outliers;
      } else {
        corr += row.counts.correspondences;
        out += row.counts.outliers;
      }
    }
    r.matches_per_frame = corr / frames;
    r.correct = corr > 0 ? 1.0 - static_cast<double>(out) / corr : 0.0;
    r.initialised = m.landmarks.initialised;
    rows.push_back(r);
  }
  fmt::print("Frontend on {} ({} steps, {} variant, {} frames per detector)\n",
             o.dataset, scn.num_steps() + 1, scn.variant.empty() ? "-" : scn.variant,
             scn.num_steps() * static_cast<int>(scn.uavs.size()));
  fmt::print("{:<10} {:>12} {:>14} {:>9} {:>14} {:>12}\n", "detector", "ms/frame", "matches/frame",
             "correct", "coop correct", "landmarks");
  for (const auto& r : rows)
    fmt::print("{:<10} {:>12.1f} {:>14.1f} {:>8.1f}% {:>14} {:>12}\n", r.name, r.detect_ms_per_frame,
               r.matches_per_frame, 100 * r.correct, fmt::format("{}/{}", r.coop_correct, r.coop),
               r.initialised);
  fmt::print("ms/frame: lead detector + detection + description; matches: tracked landmark "
             "correspondences; correct: within 3 px of the true projection and not occluded\n");
  return 0;
}

}  // namespace

Subcommand add_bench_frontend(CLI::App& parent) {
  auto o = std::make_shared<BenchOptions>();
  auto* cmd = parent.add_subcommand(
      "bench-frontend", "Replay a rendered dataset once per feature detector and compare them: ms "
                        "per frame, matches per frame, fraction correct, landmarks initialised");
  cmd->add_option("dataset", o->dataset, "Dataset directory (from wingman render)")->required();
  add_variant_option(cmd, o->variants, "Estimator settings of this variant (default: the dataset's)");
  add_step_limit(cmd, o->limit);
  cmd->add_option("--detector", o->detectors, "Detectors to compare (repeatable; default: all four)")
      ->check(CLI::IsMember({"orb", "gftt_orb", "akaze", "sift"}));
  cmd->add_option("--max-features", o->max_features,
                  "Features per frame (default: the scenario's frontend.max_features)")
      ->check(CLI::Range(10, 100000));
  cmd->add_flag("--quiet,-q", o->quiet, "No progress lines");
  return {cmd, [o] {
            return for_each_variant(o->variants, [&](const std::string& v) { return bench_command(*o, v); });
          }};
}

}  // namespace wingman::app
