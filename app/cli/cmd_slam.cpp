// `wingman slam <dataset-dir>`: replays a dataset written by `wingman render` through the same
// vision frontend and estimator as `measurements: rendered`, into a results directory with the
// same metrics. The scenario is the dataset's own scenario.yaml, with the variant and seed the
// dataset records (--variant picks another variant's estimator settings).
#include "app/cli/subcommand.hpp"

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>

#include "app/cli/cli_options.hpp"
#include "app/cli/results_layout.hpp"
#include "app/pipeline/pipeline.hpp"
#include "io/progress.hpp"
#include "app/pipeline/replay.hpp"
#include "datasets/dataset.hpp"
#include "eval/metrics/metrics.hpp"
#include "eval/output/plots.hpp"
#include "io/results_dir.hpp"
#include "eval/output/writers.hpp"
#include "sim/scenario.hpp"

namespace fs = std::filesystem;

namespace wingman::app {

namespace {

struct SlamOptions {
  std::string dataset;
  std::string out;
  std::vector<std::string> variants;
  StepLimit limit;
  bool no_plots = false;
  bool correspondences = false;
  bool force = false;
  bool quiet = false;
};

// One variant's replay into `dir`: the files of `wingman run`'s variant directory.
void replay_variant(const SlamOptions& o, const Replay& replay, const fs::path& dir) {
  const RunConfig& scn = replay.scenario;
  io::ProgressLine progress(fmt::format("[slam {}]", scn.variant.empty() ? scn.name : scn.name + "/" + scn.variant),
                            o.quiet);
  eval::RunRecord rec;
  try {
    rec = run_replay(scn, replay.dataset, [&](int k, int n) { progress.update(k, n, "steps"); }, std::nullopt,
                     o.correspondences);
  } catch (const std::invalid_argument& e) {
    throw io::UsageError(e.what());
  }
  progress.finish();
  write_variant(rec, scn, dir, !o.no_plots, o.quiet);
}

// Every variant asked for (or the dataset's own) into one results directory laid out as
// `wingman run` lays it out: OUT/<variant>/ for a scenario with variants, OUT/ otherwise.
int slam_command(const SlamOptions& o) {
  if (!o.no_plots && !eval::gnuplot_available())
    throw io::UsageError("gnuplot with the pngcairo terminal was not found; install it or pass --no-plots");
  std::vector<Replay> replays;
  for (const std::string& v : o.variants.empty() ? std::vector<std::string>{""} : o.variants) {
    replays.push_back(load_replay(o.dataset, v, o.quiet));
    apply_step_limit(o.limit, replays.back().scenario);
  }
  const RunConfig& first = replays.front().scenario;
  const fs::path out = o.out.empty() ? fs::path("results") / (first.name + "_replay") : fs::path(o.out);
  std::optional<io::ResultsDir> staged;
  stage_output(staged, out, "results", o.force);
  for (const Replay& r : replays) replay_variant(o, r, variant_dir(*staged, r.scenario, replays.size() > 1));
  publish_results(*staged, first, out, o.quiet);
  return 0;
}

}  // namespace

Subcommand add_slam(CLI::App& parent) {
  auto o = std::make_shared<SlamOptions>();
  auto* cmd = parent.add_subcommand(
      "slam", "Replay a dataset written by `wingman render` through the vision frontend and the "
              "estimator, into a results directory (the same metrics as `wingman run`)");
  cmd->add_option("dataset", o->dataset, "Dataset directory")->required();
  cmd->add_option("--out,-o", o->out, "Results directory (default: results/<scenario>_replay)");
  add_variant_option(cmd, o->variants,
                     "Estimator settings of this variant of the dataset's scenario (default: the "
                     "variant it was rendered with, else the first); each variant's results go to "
                     "OUT/<variant>, as `wingman run` writes them");
  add_step_limit(cmd, o->limit);
  cmd->add_flag("--no-plots", o->no_plots, "Skip the PNG plots (no gnuplot needed)");
  cmd->add_flag("--correspondences", o->correspondences,
                "Also write correspondences.csv: every tracked correspondence offered to the "
                "filter with its true projection, label and fate (as `wingman run`)");
  add_force_flag(cmd, o->force);
  cmd->add_flag("--quiet,-q", o->quiet, "No progress line and no summary");
  return {cmd, [o] { return slam_command(*o); }};
}

}  // namespace wingman::app
