// `wingman run`: every variant of a scenario end to end into one results directory.
#include "app/cli/subcommand.hpp"
#include "app/config/variants.hpp"

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>

#include "app/cli/cli_options.hpp"
#include "app/cli/results_layout.hpp"
#include "app/pipeline/pipeline.hpp"
#include "io/progress.hpp"
#include "io/version.hpp"
#include "eval/metrics/metrics.hpp"
#include "eval/output/plots.hpp"
#include "io/results_dir.hpp"
#include "eval/output/writers.hpp"
#include "render/gl_context.hpp"
#include "sim/scenario.hpp"

namespace fs = std::filesystem;

namespace wingman::app {

namespace {

struct RunOptions {
  std::string scenario;
  std::string out;
  std::optional<std::uint64_t> seed;
  std::vector<std::string> variants;
  std::string gl = "auto";
  std::string video;
  bool no_plots = false;
  bool no_prefetch = false;
  bool whole_frames = false;
  bool correspondences = false;
  bool force = false;
  bool quiet = false;
  bool print_config = false;
  StepLimit limit;
  FrameCacheCli frame_cache;
};

int run_command(const RunOptions& o) {
  render::GlBackend gl;
  try {
    gl = render::gl_backend_from_string(o.gl);
  } catch (const std::invalid_argument& e) {
    throw io::UsageError(e.what());
  }
  auto scenarios = select_variants(load_run_configs(o.scenario), o.variants, o.scenario);
  const FrameCacheOptions cache = o.frame_cache.resolve();
  for (auto& s : scenarios) {
    if (o.seed) s.seed = *o.seed;
    apply_step_limit(o.limit, s);
  }
  if (o.print_config) {
    for (const auto& s : scenarios) fmt::print("{}", config_yaml(s));
    return 0;
  }
  if (!o.no_plots && !eval::gnuplot_available())
    throw io::UsageError("gnuplot with the pngcairo terminal was not found; install it (setup.sh does) "
                     "or pass --no-plots");

  const fs::path out = o.out.empty() ? fs::path("results") / scenarios.front().name : fs::path(o.out);
  std::optional<io::ResultsDir> staged;
  stage_output(staged, out, "results", o.force);
  io::ResultsDir& results = *staged;

  std::vector<std::string> dirs, labels;
  for (const auto& scn : scenarios) {
    const std::string label = scn.variant.empty() ? scn.name : scn.name + "/" + scn.variant;
    io::ProgressLine progress(fmt::format("[{}]", label), o.quiet);
    eval::RunRecord rec;
    try {
      std::string video = o.video;
      if (!video.empty() && scenarios.size() > 1) {  // one file per variant: FILE_<variant>.avi
        const fs::path v(video);
        video = (v.parent_path() / (v.stem().string() + "_" + scn.variant + v.extension().string())).string();
      }
      if (!video.empty() && scn.measurements != sim::MeasurementMode::Rendered)
        throw io::UsageError("--video needs a scenario with measurements: rendered");
      RenderedOptions ro(gl, video);
      ro.prefetch = !o.no_prefetch;
      ro.regions = !o.whole_frames;
      if (o.correspondences && scn.measurements != sim::MeasurementMode::Rendered)
        throw io::UsageError("--correspondences needs a scenario with measurements: rendered");
      ro.correspondences = o.correspondences;
      ro.frame_cache = cache;
      rec = run_scenario(scn, ro,
                         [&](int k, int n) { progress.update(k, n, "steps"); });
    } catch (const std::invalid_argument& e) {
      throw io::UsageError(e.what());  // a world or frontend setting the scenario got wrong
    }
    progress.finish();

    const fs::path dir = variant_dir(results, scn, scenarios.size() > 1);
    write_variant(rec, scn, dir, !o.no_plots, o.quiet);
    dirs.push_back(dir.string());
    labels.push_back(scn.variant.empty() ? scn.name : scn.variant);
  }
  if (!o.no_plots && dirs.size() > 1) {
    // The paper's Fig. 10: the variants' errors side by side, for the lead and the first UAV.
    for (const std::string agent : {"lead", "uav1"}) {
      try {
        eval::plot_comparison(dirs, labels, agent,
                              (results.staging() / ("compare_" + agent + ".png")).string());
      } catch (const std::invalid_argument&) {
        // An agent some variant does not estimate: no comparison to draw.
      }
    }
  }
  publish_results(results, scenarios.front(), out, o.quiet);
  return 0;
}

}  // namespace

Subcommand add_run(CLI::App& parent) {
  auto o = std::make_shared<RunOptions>();
  auto* cmd = parent.add_subcommand(
      "run", "Run a scenario end to end and write a results directory (metrics.json, TUM "
             "trajectories, map PLY, per-step CSV, plots)");
  cmd->add_option("scenario", o->scenario, "Scenario YAML file")->required();
  cmd->add_option("--out,-o", o->out, "Results directory (default: results/<scenario name>)");
  cmd->add_option("--seed", o->seed, "Override the scenario's seed");
  add_step_limit(cmd, o->limit);
  cmd->add_flag("--print-config", o->print_config,
                "Print each variant's resolved configuration (every key, defaults included) as "
                "YAML and exit; every results directory keeps it as config.yaml");
  add_variant_option(cmd, o->variants, "Run only this variant");
  cmd->add_option("--gl", o->gl,
                  "OpenGL backend for rendered scenarios: auto (EGL, then OSMesa), egl or osmesa")
      ->check(CLI::IsMember({"auto", "egl", "osmesa"}));
  cmd->add_option("--video", o->video,
                  "Rendered scenarios: write every camera in the filter side by side at half size, "
                  "with the tracked landmarks (red; green once the filter accepted them, so red "
                  "alone is a rejected one), new landmarks' pixels (yellow) and the lead detection "
                  "(magenta), each camera labelled with the time and the phase, a legend of the marks "
                  "underneath; MJPG AVI, one file per variant, FILE_<variant>.avi, when several run");
  cmd->add_flag("--no-plots", o->no_plots, "Skip the PNG plots (no gnuplot needed)");
  cmd->add_flag("--no-prefetch", o->no_prefetch,
                "Rendered, open loop: render each step's frames at that step, not during the "
                "previous step's detection (same results, for timing comparisons)");
  cmd->add_flag("--whole-frames", o->whole_frames,
                "Rendered, with active search: render whole frames, not only the regions the "
                "frontend reads (same results, the reference path for timing comparisons)");
  cmd->add_flag("--correspondences", o->correspondences,
                "Rendered scenarios: also write correspondences.csv per variant, every tracked "
                "correspondence offered to the filter with its true projection, label and whether "
                "the filter accepted it (about 5 MB for the 210 s paper scene; "
                "tools/track_error.py reads it)");
  add_frame_cache_options(cmd, o->frame_cache, "Off unless given.");
  add_force_flag(cmd, o->force);
  cmd->add_flag("--quiet,-q", o->quiet, "No progress line and no summary");
  return {cmd, [o] { return run_command(*o); }};
}

}  // namespace wingman::app
