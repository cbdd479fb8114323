// `wingman pairs <dataset>`: the matching benchmark's frame pairs (pairs.csv), and
// `wingman score-matches <dataset> <dir>`: any frontend's keypoints and matches in the benchmark's
// file format scored against the dataset's true correspondences (docs/frontend.md).
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>

#include "app/cli/match_options.hpp"
#include "io/interrupt.hpp"
#include "io/progress.hpp"
#include "app/cli/subcommand.hpp"
#include "io/atomic_file.hpp"

namespace wingman::app {

namespace fs = std::filesystem;

namespace {

struct PairsOptions {
  std::string dataset, out;
  PairCli pairs;
  bool force = false;
};

int pairs_command(const PairsOptions& o) {
  if (!o.out.empty() && fs::exists(o.out) && !o.force)
    throw io::UsageError(fmt::format("{}: already exists; pass --force to replace it", o.out));
  const datasets::Dataset ds = datasets::read_dataset(o.dataset);
  const frontend_bench::Conditions sets = load_conditions(ds, o.pairs);
  const std::string csv = frontend_bench::pairs_csv(load_pairs(sets, o.pairs, false));
  if (o.out.empty()) {
    fmt::print("{}", csv);
  } else {
    io::write_file_atomic(o.out, csv);
  }
  return 0;
}

struct ScoreMatchesOptions {
  std::string dataset, dir, name;
  PairCli pairs;
  frontend_bench::ScoreOptions score;
  MatchOutput output;
};

int score_matches_command(const ScoreMatchesOptions& o) {
  try {
    o.score.validate();
  } catch (const std::invalid_argument& e) {
    throw io::UsageError(e.what());
  }
  if (!fs::is_directory(o.dir)) throw io::UsageError(fmt::format("{}: not a directory", o.dir));
  std::optional<io::ResultsDir> staged;
  open_match_output(o.output, staged);
  const datasets::Dataset ds = datasets::read_dataset(o.dataset);
  const frontend_bench::Conditions sets = load_conditions(ds, o.pairs);
  const auto pairs = load_pairs(sets, o.pairs, o.output.quiet);
  io::ProgressLine progress("[score-matches]", o.output.quiet);
  const auto counts = frontend_bench::score_directory(sets, pairs, o.dir, o.score,
                                            [&](int k, int n) {
                                              io::throw_if_interrupted();
                                              progress.update(k, n, "pairs");
                                            });
  progress.finish();
  frontend_bench::MatchReport report = frontend_bench::make_report(o.dataset, sets, pairs, o.score);
  report.duration_s = o.pairs.limit.duration;
  report.frames = o.pairs.limit.frames;
  frontend_bench::MethodScores m;
  m.name = o.name.empty() ? fs::path(o.dir).lexically_normal().filename().string() : o.name;
  if (m.name.empty() || m.name == ".") m.name = fs::absolute(o.dir).lexically_normal().parent_path().filename().string();
  long keypoints = 0;
  for (const auto& c : counts) keypoints += c.keypoints_a + c.keypoints_b;
  m.keypoints_per_frame = pairs.empty() ? 0.0 : static_cast<double>(keypoints) / (2.0 * pairs.size());
  if (const auto ms = frontend_bench::mean_frame_ms(o.dir, pairs)) m.detect_ms_per_frame = *ms;
  m.groups = frontend_bench::group_scores(pairs, counts, o.score);
  report.methods.push_back(m);
  publish_match_report(report, o.output, staged);
  return 0;
}

}  // namespace

Subcommand add_pairs(CLI::App& parent) {
  auto o = std::make_shared<PairsOptions>();
  auto* cmd = parent.add_subcommand(
      "pairs", "List the matching benchmark's frame pairs of a dataset (pair_id, agents, time "
               "stamps, temporal|cross|same-instant, baseline, condition): the pairs a frontend writes "
               "matches for");
  cmd->add_option("dataset", o->dataset, "Dataset directory (from wingman render)")->required();
  cmd->add_option("--out,-o", o->out, "Pairs file to write (default: stdout)");
  add_pair_options(cmd, o->pairs, false);
  cmd->add_flag("--force", o->force, "Replace an existing pairs file");
  return {cmd, [o] { return pairs_command(*o); }};
}

Subcommand add_score_matches(CLI::App& parent) {
  auto o = std::make_shared<ScoreMatchesOptions>();
  auto* cmd = parent.add_subcommand(
      "score-matches", "Score a feature frontend's keypoints and matches (keypoints/, matches/ "
                       "in DIR) against the dataset's true correspondences: repeatability, "
                       "precision and recall at 1/3/5 px, localisation error");
  cmd->add_option("dataset", o->dataset, "Dataset directory (from wingman render)")->required();
  cmd->add_option("dir", o->dir,
                  "Directory holding keypoints/<agent>/<t_ns>.csv (a condition's under "
                  "conditions/<condition>/keypoints/) and matches/<pair_id>.csv")
      ->required();
  cmd->add_option("--name", o->name, "The method's name in the table (default: DIR's name)");
  add_pair_options(cmd, o->pairs, true);
  add_score_options(cmd, o->score);
  add_match_output_options(cmd, o->output);
  return {cmd, [o] { return score_matches_command(*o); }};
}

}  // namespace wingman::app
