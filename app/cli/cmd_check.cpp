// `wingman check`: a results or Monte Carlo directory against a baseline (metric regressions,
// eval/regression/check.hpp), or against another results directory (determinism, eval/regression/same_results.hpp).
// Exit 0 when nothing fails, 1 when something regressed or differs, 2 for bad input; reports
// are written only once everything was judged, each atomically.
#include "app/cli/subcommand.hpp"

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <filesystem>
#include <memory>
#include <string>

#include "io/atomic_file.hpp"
#include "eval/regression/check.hpp"
#include "eval/regression/same_results.hpp"

namespace fs = std::filesystem;

namespace wingman::app {
namespace {

struct CheckCommand {
  std::string dir, baseline, against, junit, markdown, json;
  double tolerance = 0;  // relative, for --against; 0: bit for bit
  bool quiet = false, verbose = false;
};

std::string same_words(const CheckCommand& o) {
  return o.tolerance > 0 ? fmt::format("the same within {:g}, timings aside", o.tolerance)
                         : "identical, timings aside";
}

// The determinism check as a report: one row per data file.
eval::CheckReport against_report(const eval::TreeComparison& c, const CheckCommand& o) {
  eval::CheckReport r;
  r.results = o.dir;
  r.baseline = o.against;
  for (const auto& f : c.files) {
    eval::CheckRow row;
    row.metric = f.path;
    row.rule = o.tolerance > 0 ? fmt::format("identical within {:g}", o.tolerance) : "identical";
    row.detail = f.difference.empty() ? same_words(o) : f.difference;
    row.verdict = f.difference.empty() ? eval::Verdict::kPass : eval::Verdict::kFail;
    r.failed += !f.difference.empty();
    r.rows.push_back(row);
  }
  return r;
}

void print_against(const eval::TreeComparison& c, const CheckCommand& o) {
  for (const auto& f : c.files)
    if (!f.difference.empty()) fmt::print("{}: {}\n", f.path, f.difference);
  if (c.identical()) fmt::print("{} and {}: {} ({} data files)\n", o.dir, o.against, same_words(o), c.files.size());
  else fmt::print("{} and {}: {} of {} data files differ\n", o.dir, o.against, c.differing(), c.files.size());
}

void write_report(const std::string& path, const std::string& text) {
  if (path.empty()) return;
  if (fs::path(path).has_parent_path()) fs::create_directories(fs::path(path).parent_path());
  io::write_file_atomic(path, text);
}

int check_command(const CheckCommand& o) {
  if (o.baseline.empty() == o.against.empty())
    throw io::UsageError("give one of --baseline FILE (metric regressions) or --against DIR (determinism)");
  if (o.tolerance != 0 && o.against.empty()) throw io::UsageError("--tolerance goes with --against DIR");
  eval::CheckReport r;
  if (o.against.empty()) {
    r = eval::check_against_baseline(eval::read_metric_set(o.dir), eval::read_baseline(o.baseline));
  } else {
    const eval::TreeComparison c = eval::compare_results_trees(o.dir, o.against, o.tolerance);
    r = against_report(c, o);
    if (!o.quiet || !c.identical()) print_against(c, o);
  }
  write_report(o.junit, eval::check_junit(r));
  write_report(o.markdown, eval::check_markdown(r));
  write_report(o.json, eval::check_json(r));
  if (o.against.empty() && (!o.quiet || r.failed > 0)) fmt::print("{}", eval::format_check(r, o.verbose));
  return r.failed > 0 ? 1 : 0;
}

}  // namespace

Subcommand add_check(CLI::App& parent) {
  auto o = std::make_shared<CheckCommand>();
  auto* cmd = parent.add_subcommand(
      "check", "Judge a results or Monte Carlo directory against a baseline (exit 1 when a metric regressed), or "
               "against another results directory of the same scenario and seed (identical, timings aside)");
  cmd->add_option("results", o->dir, "Results directory (wingman run) or Monte Carlo directory")->required();
  cmd->add_option("--baseline,-b", o->baseline, "Baseline file (wingman baseline)");
  cmd->add_option("--against", o->against, "Another results directory that must hold the same results");
  cmd->add_option("--tolerance", o->tolerance,
                  "With --against: numbers may differ by this much, relative above 1 and absolute below (1e-9: "
                  "the rounding of another order of the same arithmetic); 0, the default, asks for identical files")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--junit", o->junit, "Also write JUnit XML (one testcase per metric) to this file");
  cmd->add_option("--markdown", o->markdown, "Also write a Markdown report (a pull-request comment) to this file");
  cmd->add_option("--json", o->json, "Also write the verdicts as JSON to this file");
  cmd->add_flag("--quiet,-q", o->quiet, "Print the table only when something failed");
  cmd->add_flag("--verbose,-v", o->verbose, "Print the numbers behind every verdict, passes included");
  return {cmd, [o] { return check_command(*o); }};
}

}  // namespace wingman::app
