// One `wingman` subcommand. Each lives in its own app/cli/cmd_<name>.cpp, exposes one add_<name>()
// that declares its options on the parent CLI::App, and is listed once in app/cli/commands.cpp;
// adding a subcommand never touches the others.
#pragma once

#include <functional>

#include "io/usage_error.hpp"

namespace CLI {
class App;
}

namespace wingman::app {

struct Subcommand {
  CLI::App* cli = nullptr;     // the parsed subcommand
  std::function<int()> run;    // runs it after parsing; returns the exit code
};

Subcommand add_run(CLI::App& parent);            // app/cli/cmd_run.cpp
Subcommand add_montecarlo(CLI::App& parent);     // app/cli/cmd_montecarlo.cpp
Subcommand add_observability(CLI::App& parent);  // app/cli/cmd_observability.cpp
Subcommand add_render(CLI::App& parent);         // app/cli/cmd_render.cpp
Subcommand add_slam(CLI::App& parent);           // app/cli/cmd_slam.cpp
Subcommand add_bench_frontend(CLI::App& parent); // app/cli/cmd_bench_frontend.cpp
Subcommand add_bench_lead(CLI::App& parent);     // app/cli/cmd_bench_lead.cpp
Subcommand add_pairs(CLI::App& parent);          // app/cli/cmd_score_matches.cpp
Subcommand add_score_matches(CLI::App& parent);  // app/cli/cmd_score_matches.cpp
Subcommand add_baseline(CLI::App& parent);       // app/cli/cmd_baseline.cpp
Subcommand add_check(CLI::App& parent);          // app/cli/cmd_check.cpp
Subcommand add_export(CLI::App& parent);         // app/cli/cmd_export.cpp
Subcommand add_calibrate_frontend(CLI::App& parent);  // app/cli/cmd_calibrate_frontend.cpp
// Further subcommands declare their add_<name>() here.

}  // namespace wingman::app
