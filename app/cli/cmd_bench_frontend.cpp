// `wingman bench-frontend <dataset-dir>`: the built-in feature detectors as a matching benchmark.
// By default each detector runs outside the SLAM loop on the benchmark's frame pairs (detect,
// describe, match by brute force with the ratio test and a mutual check), writes its keypoints
// and matches in the benchmark's file format, and is scored from those files by the same reader
// and scorer as `wingman score-matches` (docs/frontend.md). `--in-loop` instead replays the whole
// SLAM loop once per detector (tracking decides how many matches it asks for, so there every
// detector lands near the same count): ms per frame, tracked matches per frame and the fraction
// correct against the ground-truth labels, cooperative pairs and landmarks initialised.
#include "app/cli/cli_options.hpp"
#include "app/cli/subcommand.hpp"

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <stdlib.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/interrupt.hpp"
#include "app/cli/match_options.hpp"
#include "frontend_bench/builtin_frontend.hpp"
#include "app/pipeline/pipeline.hpp"
#include "io/progress.hpp"
#include "app/frontend/vision_frontend.hpp"
#include "app/pipeline/replay.hpp"
#include "eval/metrics/metrics.hpp"
#include "vision/features.hpp"

namespace wingman::app {

namespace fs = std::filesystem;

namespace {

struct BenchOptions {
  std::string dataset;
  std::vector<std::string> variants;
  std::vector<std::string> detectors{"orb", "gftt_orb", "akaze", "sift"};
  int max_features = 0;  // 0: the scenario's frontend.max_features
  bool in_loop = false;
  PairCli pairs;
  frontend_bench::ScoreOptions score;
  vision::DescriptorMatchSettings matching;
  bool no_mutual = false;  // --no-mutual: matching.mutual off
  MatchOutput output;
};

void check_detectors(const BenchOptions& o) {
  for (const auto& name : o.detectors) {  // a typo is a usage error, before any loading
    try {
      vision::parse_detector(name);
    } catch (const std::invalid_argument& e) {
      throw io::UsageError(e.what());
    }
  }
}

// Each detector with the rest of the scenario's frontend section (bucketing, thresholds).
std::vector<vision::FeatureSettings> detector_settings(const BenchOptions& o, const RunConfig& scn) {
  std::vector<vision::FeatureSettings> settings;
  for (const auto& name : o.detectors) {
    vision::FeatureSettings f = scn.frontend.features;
    if (o.max_features > 0) f.max_features = o.max_features;
    try {
      f.kind = vision::parse_detector(name);
      f.validate();
      settings.push_back(f);
    } catch (const std::invalid_argument& e) {
      throw io::UsageError(e.what());
    }
  }
  return settings;
}

// The whole replay once per detector.
int in_loop_command(const BenchOptions& o, const std::string& variant) {
  if (!o.output.out.empty()) throw io::UsageError("--out writes the matching benchmark; it does not go with --in-loop");
  if (!o.pairs.conditions.empty()) throw io::UsageError("--condition goes with the matching benchmark, not with --in-loop");
  Replay replay = load_replay(o.dataset, variant, o.output.quiet);
  apply_step_limit(o.pairs.limit, replay.scenario);
  const RunConfig& scn = replay.scenario;
  const std::vector<vision::FeatureSettings> settings = detector_settings(o, scn);

  struct Row {
    std::string name;
    double detect_ms_per_frame = 0;
    double matches_per_frame = 0, correct = 0;
    long coop = 0, coop_correct = 0, initialised = 0;
  };
  std::vector<Row> rows;
  for (const auto& f : settings) {
    io::ProgressLine progress(fmt::format("[bench-frontend {}]", vision::to_string(f.kind)), o.output.quiet);
    const eval::RunRecord rec =
        run_replay(scn, replay.dataset, [&](int k, int n) { progress.update(k, n, "steps"); }, f);
    progress.finish();
    const eval::Metrics m = eval::compute_metrics(rec);
    Row r;
    r.name = vision::to_string(f.kind);
    const double frames = std::max<long>(1, rec.frontend.frames);
    double detect_ms = 0;
    for (const auto& s : rec.steps) detect_ms += s.t_ms.detect;
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

// A directory for the detectors' files when no --out keeps them: removed with everything in it.
class ScratchDir {
 public:
  ScratchDir() {
    std::string tmpl = (fs::temp_directory_path() / "wingman-bench-frontend-XXXXXX").string();
    if (::mkdtemp(tmpl.data()) == nullptr) throw std::runtime_error("cannot make a temporary directory in " + fs::temp_directory_path().string());
    path_ = tmpl;
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

int benchmark_command(const BenchOptions& o, const std::string& variant) {
  try {
    o.score.validate();
    o.matching.validate();
  } catch (const std::invalid_argument& e) {
    throw io::UsageError(e.what());
  }
  std::optional<io::ResultsDir> staged;
  open_match_output(o.output, staged);
  const Replay replay = load_replay(o.dataset, variant, o.output.quiet);
  const frontend_bench::Conditions sets = load_conditions(replay.dataset, o.pairs);
  const auto pairs = load_pairs(sets, o.pairs, o.output.quiet);
  std::optional<ScratchDir> scratch;
  if (!staged) scratch.emplace();
  const fs::path root = staged ? staged->staging() / "frontends" : scratch->path();
  frontend_bench::MatchReport report = frontend_bench::make_report(o.dataset, sets, pairs, o.score);
  report.duration_s = o.pairs.limit.duration;
  report.frames = o.pairs.limit.frames;
  const std::vector<vision::FeatureSettings> detectors = detector_settings(o, replay.scenario);
  report.matcher = frontend_bench::MatcherOptions{o.matching.ratio, o.matching.mutual, detectors.front().max_features};
  for (const auto& f : detectors) {
    const std::string name = vision::to_string(f.kind);
    io::ProgressLine progress(fmt::format("[bench-frontend {}]", name), o.output.quiet);
    const frontend_bench::BuiltinFrontendRun run = frontend_bench::run_builtin_frontend(sets, pairs, {f, o.matching}, root / name, [&](int k, int n) {
      io::throw_if_interrupted();
      progress.update(k, n, "pairs matched");
    });
    // Scored from the files just written, through the reader any other frontend goes through.
    const auto counts = frontend_bench::score_directory(sets, pairs, root / name, o.score, [&](int k, int n) {
      io::throw_if_interrupted();
      progress.update(k, n, "pairs scored");
    });
    progress.finish();
    frontend_bench::MethodScores m;
    m.name = name;
    m.detect_ms_per_frame = run.frames > 0 ? run.detect_ms / run.frames : 0.0;
    m.detect_cpu_ms_per_frame = run.frames > 0 ? run.detect_cpu_ms / run.frames : 0.0;
    m.keypoints_per_frame = run.frames > 0 ? static_cast<double>(run.keypoints) / run.frames : 0.0;
    m.groups = frontend_bench::group_scores(pairs, counts, o.score);
    report.methods.push_back(std::move(m));
  }
  fmt::print("Feature frontends on {}: {}, matched by brute force (ratio {}, {})\n", o.dataset,
             frontend_bench::describe_pairs(report), o.matching.ratio, o.matching.mutual ? "mutual" : "one way");
  publish_match_report(report, o.output, staged);
  return 0;
}

int bench_command(const BenchOptions& o, const std::string& variant) {
  check_detectors(o);
  return o.in_loop ? in_loop_command(o, variant) : benchmark_command(o, variant);
}

}  // namespace

Subcommand add_bench_frontend(CLI::App& parent) {
  auto o = std::make_shared<BenchOptions>();
  auto* cmd = parent.add_subcommand(
      "bench-frontend", "Benchmark the built-in feature detectors on a rendered dataset's frame "
                        "pairs against the true correspondences (repeatability, precision, recall, "
                        "localisation, ms per frame); --in-loop: replay the SLAM loop per detector");
  cmd->add_option("dataset", o->dataset, "Dataset directory (from wingman render)")->required();
  add_variant_option(cmd, o->variants, "Estimator settings of this variant (default: the dataset's)");
  cmd->add_option("--detector", o->detectors, "Detectors to compare (repeatable; default: all four)")
      ->check(CLI::IsMember({"orb", "gftt_orb", "akaze", "sift"}));
  cmd->add_option("--max-features", o->max_features,
                  "Features per frame (default: the scenario's frontend.max_features)")
      ->check(CLI::Range(10, 100000));
  cmd->add_flag("--in-loop", o->in_loop,
                "Replay the whole SLAM loop per detector instead (tracked matches, landmarks)");
  add_pair_options(cmd, o->pairs, true);
  add_score_options(cmd, o->score);
  cmd->add_option("--ratio", o->matching.ratio, "Lowe's ratio test of the brute-force matcher")
      ->capture_default_str()->check(CLI::Range(0.01, 1.0));
  cmd->add_flag("--no-mutual", o->no_mutual, "Keep one-way matches (no cross-check)");
  add_match_output_options(cmd, o->output);
  return {cmd, [o] {
            o->matching.mutual = !o->no_mutual;
            return for_each_variant(o->variants, [&](const std::string& v) { return bench_command(*o, v); });
          }};
}

}  // namespace wingman::app
