#include "app/cli/match_options.hpp"

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>

#include "app/cli/cli_options.hpp"
#include "app/cli/subcommand.hpp"
#include "eval/output/plots.hpp"
#include "io/results_dir.hpp"

namespace wingman::app {

namespace fs = std::filesystem;

void add_pair_options(CLI::App* cmd, PairCli& p, bool with_file) {
  if (with_file)
    cmd->add_option("--pairs", p.file,
                    "Pairs file (as `wingman pairs` writes it; default: the dataset's pairs with "
                    "--stride/--gap)");
  cmd->add_option("--stride", p.options.stride, "A pair starts at every N-th frame")
      ->capture_default_str()->check(CLI::Range(1, 1000000));
  cmd->add_option("--gap", p.options.gaps, "Temporal pairs: frame k with frame k + GAP (repeatable)")
      ->capture_default_str()->check(CLI::Range(1, 1000000));
  cmd->add_flag("--no-cross", p.no_cross, "No cross-UAV pairs");
  cmd->add_option("--condition", p.conditions,
                  "NAME=DIR: the same flight rendered under another condition (repeatable); pairs with frame B "
                  "from it, same-instant pairs included");
  add_step_limit(cmd, p.limit);
}

namespace {

std::vector<frontend_bench::FramePair> all_pairs(const frontend_bench::Conditions& sets, const PairCli& p) {
  const datasets::Dataset& ds = sets.reference();
  if (!p.file.empty()) return frontend_bench::read_pairs(p.file, sets);
  frontend_bench::PairOptions o = p.options;
  o.cross = !p.no_cross;
  try {
    auto pairs = frontend_bench::make_pairs(sets, o);
    if (pairs.empty()) throw io::UsageError(fmt::format("{}: no frame pairs (too few frames for the gaps?)", ds.root.string()));
    return pairs;
  } catch (const std::invalid_argument& e) {
    throw io::UsageError(e.what());
  }
}

}  // namespace

frontend_bench::Conditions load_conditions(const datasets::Dataset& reference, const PairCli& p) {
  std::vector<frontend_bench::Condition> conditions;
  for (const std::string& arg : p.conditions) {
    const auto eq = arg.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == arg.size())
      throw io::UsageError(fmt::format("--condition {}: expected NAME=DIR (e.g. low_sun=results/cond/low_sun)", arg));
    conditions.push_back({arg.substr(0, eq), datasets::read_dataset(arg.substr(eq + 1))});
  }
  try {
    return frontend_bench::Conditions(reference, std::move(conditions));
  } catch (const std::invalid_argument& e) {
    throw io::UsageError(fmt::format("--condition: {}", e.what()));
  }
}

std::vector<frontend_bench::FramePair> load_pairs(const frontend_bench::Conditions& sets, const PairCli& p,
                                                  bool quiet) {
  const datasets::Dataset& ds = sets.reference();
  std::vector<frontend_bench::FramePair> pairs = all_pairs(sets, p);
  const auto seconds = p.limit.seconds(ds.info.rate);
  if (!seconds) return pairs;
  std::int64_t t0 = std::numeric_limits<std::int64_t>::max();
  for (const auto& a : ds.agents)
    if (!a.frames.empty()) t0 = std::min(t0, a.frames.front());
  const auto t_end = t0 + static_cast<std::int64_t>(std::llround(*seconds * 1e9));
  const std::size_t all = pairs.size();
  std::erase_if(pairs, [&](const frontend_bench::FramePair& q) { return std::max(q.t_a, q.t_b) > t_end; });
  if (pairs.empty()) throw io::UsageError(fmt::format("no frame pairs within --duration/--frames (of {})", all));
  if (!quiet && pairs.size() < all)
    fmt::print(stderr, "pairs: {} of {} within --duration/--frames; the {} past it are left out\n", pairs.size(), all,
               all - pairs.size());
  return pairs;
}

void add_score_options(CLI::App* cmd, frontend_bench::ScoreOptions& o) {
  cmd->add_option("--baseline-bins", o.baseline_edges_m,
                  "Edges of the baseline bins in metres, increasing (per pair type)")
      ->delimiter(',')->capture_default_str();
}

void add_match_output_options(CLI::App* cmd, MatchOutput& o) {
  cmd->add_option("--out,-o", o.out, "Results directory: scores.json, scores.csv, curves.csv, plots/");
  add_force_flag(cmd, o.force);
  cmd->add_flag("--no-plots", o.no_plots, "Skip the PNG plot (no gnuplot needed)");
  cmd->add_flag("--quiet,-q", o.quiet, "No progress lines");
}

void open_match_output(const MatchOutput& o, std::optional<io::ResultsDir>& staged) {
  if (o.out.empty()) return;
  if (!o.no_plots && !eval::gnuplot_available())
    throw io::UsageError("gnuplot with the pngcairo terminal was not found; install it or pass --no-plots");
  stage_output(staged, o.out, "results", o.force);
}

void publish_match_report(const frontend_bench::MatchReport& report, const MatchOutput& o,
                          std::optional<io::ResultsDir>& staged) {
  if (staged) {
    frontend_bench::write_match_report(report, staged->staging(), !o.no_plots);
    staged->commit();
  }
  fmt::print("{}", frontend_bench::format_match_table(report));
  if (staged) fmt::print("results: {}\n", o.out);
}

}  // namespace wingman::app
