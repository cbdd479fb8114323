#include "app/cli/commands.hpp"

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "io/interrupt.hpp"
#include "app/cli/subcommand.hpp"
#include "io/version.hpp"
#include "datasets/dataset.hpp"
#include "frontend_bench/match_files.hpp"
#include "eval/regression/metric_set.hpp"
#include "sim/scenario.hpp"
#include "sim/yaml_input.hpp"

namespace wingman::app {
namespace {

// The last word of a failed command, on stderr; never throws (stderr may be a closed pipe).
void report(const char* prefix, const char* what) noexcept {
  const std::string text = sim::printable(what);
  std::fprintf(stderr, "%s%s\n", prefix, text.c_str());
}

}  // namespace

int run_cli(int argc, char** argv) {
  CLI::App cli{"wingman: cooperative visual SLAM for UAV teams flying with a lead agent"};
  cli.set_version_flag("--version", kVersion);
  cli.require_subcommand(1);
  // Argument errors read like every other error: "error: ..." and where to look.
  cli.failure_message([](const CLI::App* app, const CLI::Error& e) {
    return fmt::format("error: {}\nsee: {} --help\n", e.what(), app->get_name().empty() ? "wingman" : app->get_name());
  });

  const std::vector<Subcommand> commands = {
      add_run(cli),
      add_montecarlo(cli),
      add_observability(cli),
      add_render(cli),
      add_slam(cli),
      add_bench_frontend(cli),
      add_bench_lead(cli),
      add_pairs(cli),
      add_score_matches(cli),
      add_baseline(cli),
      add_check(cli),
      add_export(cli),
      add_calibrate_frontend(cli),
  };

  // A first word that is neither an option nor a command: say so and list the commands.
  if (argc > 1 && argv[1][0] != '-') {
    std::vector<std::string> names;
    for (const auto& c : commands) names.push_back(c.cli->get_name());
    if (std::find(names.begin(), names.end(), argv[1]) == names.end()) {
      const std::vector<std::string_view> candidates(names.begin(), names.end());
      fmt::print(stderr, "error: unknown command '{}'{}; the commands are: {} (wingman --help)\n", argv[1],
                 sim::suggestion(argv[1], candidates), fmt::join(names, ", "));
      return 2;
    }
  }
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = cli.exit(e);
    return rc == 0 ? 0 : 2;
  }
  io::InterruptGuard interrupts;
  io::stop_with_parent();
  try {
    for (const auto& c : commands)
      if (c.cli->parsed()) return c.run();
  } catch (const io::Interrupted& e) {
    report("\n", e.what());
    return e.exit_code();
  } catch (const sim::ScenarioError& e) {
    report("error: ", e.what());
    return 2;
  } catch (const io::UsageError& e) {
    report("error: ", e.what());
    return 2;
  } catch (const eval::CheckInputError& e) {  // a baseline, a results directory that is bad input
    report("error: ", e.what());
    return 2;
  } catch (const datasets::DatasetError& e) {  // a frame or file of a dataset that is bad input
    report("error: ", e.what());
    return 2;
  } catch (const frontend_bench::MatchInputError& e) {  // a pairs, keypoints or matches file
    report("error: ", e.what());
    return 2;
  } catch (const std::exception& e) {
    report("error: ", e.what());
    return 1;
  }
  return 0;
}

}  // namespace wingman::app
