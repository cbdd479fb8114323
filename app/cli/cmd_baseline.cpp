// `wingman baseline`: the reference values and rules `wingman check` judges later results by,
// written as YAML a person edits and commits (eval/regression/baseline.hpp, docs/check.md).
#include "app/cli/subcommand.hpp"

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "io/atomic_file.hpp"
#include "eval/regression/baseline.hpp"

namespace fs = std::filesystem;

namespace wingman::app {
namespace {

struct BaselineCommand {
  std::string dir, out;
  eval::BaselineOptions options;
  bool force = false, quiet = false;
};

int baseline_command(const BaselineCommand& o) {
  if (fs::is_directory(o.out)) throw io::UsageError(fmt::format("{}: is a directory; --out names the baseline file", o.out));
  if (fs::exists(o.out) && !o.force)
    throw io::UsageError(fmt::format("{}: already exists; pass --force to replace it", o.out));
  const eval::MetricSet set = eval::read_metric_set(o.dir);
  const eval::Baseline b = eval::make_baseline(set, o.options);
  for (const auto& m : b.left_out) fmt::print(stderr, "note: {} has no value (null) in at least one run; left out\n", m);
  if (b.entries.empty())
    throw io::UsageError(fmt::format("{}: none of the chosen metrics has a value; choose others with --metrics", o.dir));
  if (fs::path(o.out).has_parent_path()) fs::create_directories(fs::path(o.out).parent_path());
  io::write_file_atomic(o.out, eval::baseline_yaml(b));
  if (!o.quiet)
    fmt::print("baseline of {} metrics of {} ({} seed{}) written to {}\ncheck later results with: wingman check "
               "<results> --baseline {}\n", b.entries.size(), o.dir, b.seeds.size(), b.seeds.size() == 1 ? "" : "s",
               o.out, o.out);
  return 0;
}

}  // namespace

Subcommand add_baseline(CLI::App& parent) {
  auto o = std::make_shared<BaselineCommand>();
  auto* cmd = parent.add_subcommand(
      "baseline", "Write a baseline of a results or Monte Carlo directory: each metric's value and the rule "
                  "`wingman check` holds later results to (docs/check.md)");
  cmd->add_option("results", o->dir, "Results directory (wingman run) or Monte Carlo directory")->required();
  cmd->add_option("--out,-o", o->out, "Baseline file to write (YAML)")->required();
  cmd->add_option("--metrics", o->options.metrics,
                  "Metric paths or shell globs to hold (repeatable; default: Table 4 and 5 totals, accepted-outlier "
                  "fractions, NEES mean, lead detection, wall time and stage timings)")
      ->allow_extra_args(false);
  cmd->add_option("--rel", o->options.rel, "Tolerance of the relative rules (rel, mean, paired), a fraction")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--abs", o->options.abs, "Tolerance of the absolute rules (fractions and rates)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--rule", o->options.rule,
                  "Rule of the errors, the NEES and counts: rel, or for a Monte Carlo directory mean (other seeds, "
                  "single runs) or paired (the same seeds; the default there)")
      ->check(CLI::IsMember({"rel", "mean", "paired"}));
  cmd->add_flag("--force", o->force, "Replace an existing baseline file");
  cmd->add_flag("--quiet,-q", o->quiet, "Print nothing but errors");
  return {cmd, [o] { return baseline_command(*o); }};
}

}  // namespace wingman::app
